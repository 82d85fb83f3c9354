//! The windowed apps' shared behaviour: the winit event loop, what every key
//! and mouse gesture does, the window title, the camera, scene, depth and
//! path (fragment / compute) switches, screenshots and `--frames`. Both apps hand this module a
//! [`Renderer`] (their API-specific half) and nothing else, so the two windows
//! cannot behave differently: only the drawing differs.
//!
//! Here: the `Renderer` contract, the shaders of a path, the window's attributes
//! and the run's report; `session` runs the event loop; `keys` maps input to
//! actions; `title` formats the title; `hooks` holds the end-to-end tests' hooks
//! (cargo feature `test-hooks`).

pub mod hooks;
pub mod keys;
pub mod session;
pub mod title;

use crate::cli::{RenderArgs, RenderPath, Workgroup};
use crate::error::{no_device, without_source_location};
use crate::gpu::layout::GpuFrame;
use crate::gpu::upload::GpuScene;
use crate::limits::StorageLimit;
use crate::plan::CountingRun;
use crate::rays::RayKinds;
use crate::reference::image_io::FloatImage;
use crate::report::{DeviceInfo, FrameTime, RunReport};
use crate::scene::Scene;
use crate::shader::build::PathShaders;
use crate::shader::variant::Variant;
use crate::window::title::window_title;
use winit::dpi::PhysicalSize;
use winit::event_loop::EventLoop;
use winit::window::{Window, WindowAttributes};

/// What an API's windowed app must provide. Sizes are physical pixels.
pub trait Renderer {
    /// "Vulkan" or "OpenGL", for the title.
    fn api(&self) -> &'static str;
    fn window(&self) -> &Window;
    /// The largest storage buffer the device binds: every plan a window
    /// prepares (its start and each scene switch) is checked against it.
    fn storage_limit(&self) -> StorageLimit;
    /// The window's drawable area changed; 0 in either dimension means minimized.
    fn resize(&mut self, width: u32, height: u32) -> anyhow::Result<()>;
    /// Draws and presents one frame with this uniform block. `Ok(None)` when no
    /// frame could be drawn (e.g. a swapchain that must first be rebuilt);
    /// otherwise the GPU time of the most recent frame whose timing is known.
    fn draw(&mut self, frame: &GpuFrame) -> anyhow::Result<Option<Drawn>>;
    /// A new scene, shader variant or path: rebuild buffers, descriptors and
    /// program (or pipeline) for the path `shaders` belongs to, and draw with
    /// that path from now on.
    fn load_scene(&mut self, scene: &GpuScene<'_>, shaders: &PathShaders) -> anyhow::Result<()>;
    /// Renders `frame` at `width`×`height` (the window's size) with the current
    /// path into the RGBA32F image the headless path uses and reads it back, top
    /// row first, so that a screenshot is quantised by `image_io` exactly like
    /// `--headless --out`.
    fn capture(&mut self, frame: &GpuFrame, width: u32, height: u32) -> anyhow::Result<FloatImage>;
    /// `--count-rays`: renders `run`'s counting frame, untimed, and returns its
    /// rays; afterwards the window draws with `shaders` as before (OpenGL
    /// rebinds what the counting frame bound in its place).
    fn count_rays(&mut self, run: &CountingRun, shaders: &PathShaders) -> anyhow::Result<RayKinds>;
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drawn {
    pub gpu_ms: Option<f64>,
}

/// The event loop, or a clear exit-3 error where there is no display.
pub fn event_loop() -> anyhow::Result<EventLoop<()>> {
    EventLoop::new().map_err(|e| {
        no_device(format!(
            "cannot open a window ({}): no X display (is DISPLAY set?); run under xvfb-run, or use --headless",
            without_source_location(&e.to_string())
        ))
    })
}

/// The window both apps open: `--size` as the drawable size, a fixed title until
/// the first FPS figure.
pub fn window_attributes(args: &RenderArgs, scene: &str, api: &str) -> WindowAttributes {
    Window::default_attributes()
        .with_title(window_title(scene, api, args.path, None, None))
        .with_inner_size(PhysicalSize::new(args.size.width, args.size.height))
}

/// What the run did, for `--json`.
pub struct WindowedRun {
    pub frames: Vec<FrameTime>,
    pub scene: Scene,
    pub variant: Variant,
    /// The path drawing at exit (`C` may have switched it).
    pub path: RenderPath,
    pub workgroup: Workgroup,
    pub width: u32,
    pub height: u32,
    /// Milliseconds from `started` to the end of the first frame.
    pub setup_ms: f64,
    /// The first scene's BVH build time, where it had one.
    pub bvh_ms: Option<f64>,
    /// The first scene's BVH node count and SAH cost.
    pub bvh_figures: Option<(usize, f64)>,
}

impl WindowedRun {
    /// The `--json` report of a window: the headless shape, with wall time
    /// frame to frame and no NaN count (nothing is read back).
    pub fn report(self, api: &str, device: DeviceInfo, validation_messages: u64) -> RunReport {
        RunReport::builder(api, device, self.scene.stats(), self.variant.label())
            .size(self.width, self.height)
            .path(self.path, self.workgroup)
            .frames(self.frames, self.setup_ms)
            .validation_messages(validation_messages)
            .bvh_figures(self.bvh_ms, self.bvh_figures)
            .build()
    }
}
