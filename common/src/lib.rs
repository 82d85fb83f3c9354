//! twinray-common: everything both apps share so that they differ only where
//! Vulkan and OpenGL differ. Its map, lowest layer first (a module imports only
//! from the layers above it in this list, never from one below):
//!
//! | module | owns |
//! |---|---|
//! | `error`, `explain`, `stats` | exit codes and clear errors; `--explain`'s log; frame statistics |
//! | `gpu::layout` | the `#[repr(C)]` mirror of every shader struct, binding numbers, the flattened BVH |
//! | `limits` | one limit per user-controlled quantity |
//! | `scene/` | the scene model; loading (`load`, `format`, `overrides`, `resolve`, `check`, `mesh`, `teapot`); `camera`, `numerics`, `accel` (`--accel`, the BVH builder); `random` and `hard` scenes |
//! | `gpu::upload` | a scene as the bytes both apps upload |
//! | `reference/` | the f64 CPU tracer (`intersect` beside it), `image_io` (float images, PNG files), `metrics` (image differences) |
//! | `cli` | the options both apps take (one clap struct) |
//! | `shader/` | `variant` (the one decider of a run's shader variant), `build` (naga to SPIR-V and GLSL), `post` (passes over naga's output) |
//! | `report` | the `--json` run report |
//! | `window/` | the windowed event loop both apps share (cargo feature `window`, which only the apps enable) |

pub mod cli;
pub mod error;
pub mod explain;
pub mod gpu;
pub mod limits;
pub mod reference;
pub mod report;
pub mod scene;
pub mod shader;
pub mod stats;
#[cfg(feature = "window")]
pub mod window;

pub use error::{Failure, FailureKind};
