//! twinray-common: everything both apps share so that they differ only where
//! Vulkan and OpenGL differ. Its modules form layers: a file imports only from
//! its own layer or the ones above it, and no two files import each other. The
//! map of those layers, and what each module owns, is in
//! docs/architecture.md#the-modules-of-common (one map, kept there only).

pub mod cli;
pub mod error;
pub mod explain;
pub mod gpu;
pub mod lab;
pub mod limits;
pub mod plan;
pub mod rays;
pub mod reference;
pub mod report;
pub mod scene;
pub mod shader;
pub mod stats;
pub mod value_name;
#[cfg(feature = "window")]
pub mod window;

pub use error::{Failure, FailureKind};
