//! twinray-gl: the OpenGL twin of twinray-vk. Modules in the order a reader
//! meets the setup: context, debug output, program, buffers, target, timer,
//! the compute path (compute.rs) and its warp probe (probe.rs), the headless run that strings them together,
//! and the windowed run.

pub mod app;
pub mod buffers;
pub mod compute;
pub mod context;
pub mod debug;
pub mod probe;
pub mod program;
pub mod rays;
pub mod target;
pub mod timer;
pub mod window;

pub use app::run;
