//! twinray-vk: the Vulkan half of twinray. It draws one fullscreen triangle whose
//! fragment shader is the ray tracer, into an offscreen float image, and times it.
//!
//! The modules are listed in the order a reader meets the setup; `app.rs` ties
//! them together and is the best place to start for the big picture.

pub mod app;
pub mod commands;
pub mod compute;
pub mod descriptors;
pub mod device;
pub mod instance;
pub mod memory;
pub mod pipeline;
pub mod target;
pub mod timestamps;
