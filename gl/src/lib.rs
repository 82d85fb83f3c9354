//! twinray-gl: the OpenGL twin of twinray-vk. Modules in the order a reader
//! meets the setup: context, debug output, program, buffers, target, timer,
//! the compute path (compute.rs) and the run that strings them together.

pub mod app;
pub mod buffers;
pub mod compute;
pub mod context;
pub mod debug;
pub mod program;
pub mod target;
pub mod timer;

pub use app::run;
