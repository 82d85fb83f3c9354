//! twinray-common: everything both apps share so that they differ only where
//! Vulkan and OpenGL differ — scene loading, camera, GPU buffer layouts, the
//! naga shader build, the f64 CPU reference, image metrics, CLI and statistics.

pub mod bvh;
pub mod camera;
pub mod cli;
pub mod error;
pub mod explain;
pub mod gpu;
pub mod hard;
pub mod image_io;
pub mod interactive;
pub mod limits;
pub mod metrics;
pub mod numerics;
pub mod random_scene;
pub mod reference;
pub mod report;
pub mod scene;
pub mod shader;
pub mod stats;
pub mod teapot;

pub use error::{Failure, FailureKind};
