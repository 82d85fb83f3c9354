//! twinray-vk: the Vulkan half of twinray. It draws one fullscreen triangle whose
//! fragment shader is the ray tracer, into an offscreen float image (headless)
//! or a window's swapchain, and times it.
//!
//! The modules are listed in reading order, the same as vk/README.md and
//! docs/vulkan-walkthrough.md: the headless fragment path first (`app.rs` ties
//! it together), then what a window adds (`window.rs`), then the compute path.
//! rustfmt.toml keeps rustfmt from sorting them.

// Part 1, the headless fragment path: from the loader to a PNG.
pub mod instance;
pub mod device;
pub mod memory;
pub mod barrier;
pub mod pipeline_barrier;
pub mod descriptors;
pub mod pipeline;
pub mod scene;
pub mod target;
pub mod timestamps;
pub mod commands;
pub mod app;
// Part 2, the window: what presenting adds.
pub mod surface;
pub mod swapchain;
pub mod frames;
pub mod hooks;
pub mod window;
// Part 3, the compute path, what the driver made of the shaders, and the
// untimed frame that counts rays.
pub mod compute;
pub mod statistics;
pub mod rays;
