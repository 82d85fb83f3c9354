//! twinray-vk: the Vulkan half of twinray. It draws one fullscreen triangle whose
//! fragment shader is the ray tracer, into an offscreen float image (headless)
//! or a window's swapchain, and times it.
//!
//! The modules are listed in the order a reader meets the setup; `app.rs` ties
//! them together for the headless run and `window.rs` for the windowed one.

pub mod app;
pub mod commands;
pub mod compute;
pub mod descriptors;
pub mod device;
pub mod frames;
pub mod instance;
pub mod memory;
pub mod pipeline;
pub mod scene;
pub mod statistics;
pub mod surface;
pub mod swapchain;
pub mod target;
pub mod timestamps;
pub mod window;
