//! twinray-common: everything both apps share so that they differ only where
//! Vulkan and OpenGL differ. Its map, lowest layer first: a file imports only
//! from its own row or the rows above it, never from a row below, and no two
//! files import each other.
//!
//! | module | owns |
//! |---|---|
//! | `error`, `explain`, `stats`, `value_name` | exit codes and clear errors; `--explain`'s log; frame statistics; the one spelling of every enum value |
//! | `gpu::layout` | the `#[repr(C)]` mirror of every shader struct, binding numbers, the flattened BVH |
//! | `limits`, `rays` | one limit per user-controlled quantity; rays counted by kind (the counting frame's and the reference's), `--json`'s `rays`, Grays/s |
//! | `reference::image_io`, `reference::metrics` | float images and PNG files; how far one image is from another |
//! | `scene/` | the scene model; loading (`load`, `format`, `overrides`, `resolve`, `check`, `mesh`, `teapot`); `camera`, `numerics`, `accel` (`--accel` and the BVH builder); the `random` and `hard` scenes |
//! | `gpu::upload` | a scene as the bytes both apps upload |
//! | `reference/` | the f64 CPU tracer (`mod.rs`: shading and the ray loop; `intersect`: hits and the BVH walk) |
//! | `cli`, `fragment_pass` | the options both apps take (one clap struct); what the fragment path's experiments change outside the shader (vertices, clear, target format), and which runs refuse an experiment |
//! | `shader/` | `variant` (the one place a run's shader variant is decided), `build` (naga to SPIR-V and GLSL), `post` (passes over naga's output) |
//! | `report` | the `--json` run report |
//! | `window/` | the windowed event loop both apps share; cargo feature `window` (only the apps enable it, so the comparison and the tests build without winit), and `test-hooks` for the end-to-end tests' hooks |

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
