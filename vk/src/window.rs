//! The windowed run: the same setup as headless, in the same order, with a
//! window, a surface and a swapchain in place of the offscreen image, and the
//! frame loop of frames.rs driven by the shared event loop
//! (`twinray_common::window`, which both apps use, so keys, title and
//! camera behave identically).
//!
//! Either path draws in the window: the fragment path's render pass into the
//! swapchain's framebuffers, or the compute path's dispatch into a storage
//! image that each frame blits into the swapchain image (compute.rs,
//! `WindowCompute`). `C` switches between them by rebuilding the per-scene
//! bundle for the other path; device, swapchain and frames stay.
//!
//! `VkWindow` owns every object. Its fields are declared newest first, so Rust
//! drops them in the reverse order of creation, which is the order Vulkan
//! needs: frames, swapchain, the path's per-scene objects, render pass, device, surface, instance,
//! and the window last of all (the surface refers to it).

use crate::barrier;
use crate::commands::Commands;
use crate::compute::{self, Compute, WindowCompute};
use crate::device::Device;
use crate::frames::{Draw, FrameResult, Frames};
use crate::instance::Instance;
use crate::pipeline::{Pipeline, RenderPass};
use crate::pipeline_barrier::{self, On};
use crate::scene::SceneResources;
use crate::surface::{self, Surface};
use crate::swapchain::{self, Swapchain};
use crate::target::Target;
use crate::timestamps::Span;
use anyhow::{Context, Result};
use ash::{khr, vk};
use std::time::Instant;
use twinray_common::cli::VulkanKnobs;
use twinray_common::error::no_device;
use twinray_common::explain;
use twinray_common::gpu::layout::GpuFrame;
use twinray_common::gpu::upload::GpuScene;
use twinray_common::limits::StorageLimit;
use twinray_common::plan::{CountingRun, Planner};
use twinray_common::rays::RayKinds;
use twinray_common::reference::image_io::FloatImage;
use twinray_common::report::DeviceInfo;
use twinray_common::shader::build::PathShaders;
use twinray_common::shader::build::Shaders;
use twinray_common::window::{self, Drawn, Renderer, WindowedRun};
use winit::window::Window;

/// The current path's per-scene objects, and the shaders they were built
/// from (a capture builds its headless pipeline from them).
// Both variants are kilobytes in size (the state they own inline) and the window keeps
// exactly one, so boxing either would only add an indirection.
#[allow(clippy::large_enum_variant)]
enum PathResources {
    Fragment(SceneResources, Shaders),
    Compute(WindowCompute),
}

pub struct VkWindow {
    frames: Frames,
    /// `None` while the window has no area (minimized).
    swapchain: Option<Swapchain>,
    drawing: PathResources,
    render_pass: RenderPass,
    /// Why the compute path cannot show its image here, if it cannot.
    compute_blocker: Option<String>,
    loader: khr::swapchain::Device,
    format: vk::SurfaceFormatKHR,
    present_mode: vk::PresentModeKHR,
    size: (u32, u32),
    /// Set when acquire or present said the swapchain no longer fits.
    stale: bool,
    pub device: Device,
    surface: Surface,
    _instance: Instance,
    window: Window,
}

/// Opens the window and runs until it is closed; returns what `--json` reports.
pub fn run(
    planner: &Planner,
    knobs: &VulkanKnobs,
    started: Instant,
) -> Result<(WindowedRun, DeviceInfo)> {
    let args = planner.args();
    let event_loop = window::event_loop()?;
    // winit 0.30 prefers windows made inside `resumed` (for Android's and the
    // web's life cycles). On desktops a window made before the loop starts
    // works the same, and lets setup run top to bottom like the headless path.
    #[allow(deprecated)]
    let window = event_loop
        .create_window(window::window_attributes(args, &args.scene, "Vulkan"))
        .context("creating the window")?;
    explain::numbered(12, "Window (winit)", || {
        let s = window.inner_size();
        format!("{}x{} physical pixels", s.width, s.height)
    });
    let instance = Instance::new(
        args.validate,
        knobs.validation,
        surface::required_extensions(&window)?,
        knobs.sync2,
    )?;
    let surface = Surface::new(&instance, &window)?;
    let device = Device::new(&instance, Some(&surface), knobs, &planner.device())?;
    let loader = khr::swapchain::Device::new(&instance.instance, &device.device);
    let format = swapchain::choose_format(&device, &surface)?;
    let present_mode = swapchain::choose_present_mode(&device, &surface, args.vsync)?;
    let compute_blocker = compute::window_blocker(
        &instance.instance,
        &device,
        swapchain::accepts_transfer_writes(&device, &surface)?,
        format.format,
    );
    let size = window.inner_size();
    // The plan comes after the device, whose storage limit it is checked against.
    let plan = planner.prepare(
        &device.storage_limit(),
        size.width.max(1),
        size.height.max(1),
    )?;
    window.set_title(&twinray_common::window::title::window_title(
        &plan.scene.name,
        "Vulkan",
        args.path,
        None,
        None,
    ));
    let render_pass = RenderPass::for_swapchain(&device, format.format)?;
    let size = (size.width, size.height);
    let chain = Swapchain::new(
        &device,
        &surface,
        &loader,
        render_pass.render_pass,
        format,
        present_mode,
        size,
        None,
    )?;
    let extent = chain.as_ref().map_or(
        vk::Extent2D {
            width: size.0.max(1),
            height: size.1.max(1),
        },
        |c| c.extent,
    );
    let drawing = path_resources(
        &device,
        &plan.gpu_in_rows(plan.size.0, plan.size.1),
        &plan.shaders,
        render_pass.render_pass,
        format.format,
        extent,
        compute_blocker.as_deref(),
    )?;
    let frames = Frames::new(&device)?;
    let info = device.info();
    let renderer = VkWindow {
        frames,
        swapchain: chain,
        drawing,
        render_pass,
        compute_blocker,
        loader,
        format,
        present_mode,
        size,
        stale: false,
        device,
        surface,
        _instance: instance,
        window,
    };
    explain::numbered(17, "Frame loop starts", || {
        "per frame: wait fence, acquire image, re-record (fragment: render pass; compute: dispatch + blit),\n\
         submit (wait image-available, signal render-finished), present; C switches the path".into()
    });
    let run = window::session::run("twinray-vk", event_loop, renderer, planner, plan, started)?;
    Ok((run, info))
}

/// The per-scene objects of the path `shaders` belongs to: the fragment
/// path's pipeline for the swapchain's render pass, or the compute path's
/// pipeline and a storage image of the swapchain's `extent`.
fn path_resources(
    device: &Device,
    scene: &GpuScene,
    shaders: &PathShaders,
    render_pass: vk::RenderPass,
    format: vk::Format,
    extent: vk::Extent2D,
    compute_blocker: Option<&str>,
) -> Result<PathResources> {
    Ok(match shaders {
        PathShaders::Fragment(s) => PathResources::Fragment(
            SceneResources::new(device, scene, s, render_pass, None)?,
            s.clone(),
        ),
        PathShaders::Compute(s) => {
            if let Some(why) = compute_blocker {
                return Err(no_device(why));
            }
            PathResources::Compute(WindowCompute::new(device, scene, s, format, extent)?)
        }
    })
}

impl VkWindow {
    /// Waits for the GPU, then replaces the swapchain (or drops it while minimized).
    fn rebuild_swapchain(&mut self) -> Result<()> {
        // Nothing may be destroyed while a frame still uses it.
        self.device
            .wait_idle()
            .context("waiting for the GPU before a resize")?;
        self.stale = false;
        let old = self.swapchain.take();
        if self.size.0 == 0 || self.size.1 == 0 {
            return Ok(());
        }
        self.swapchain = Swapchain::new(
            &self.device,
            &self.surface,
            &self.loader,
            self.render_pass.render_pass,
            self.format,
            self.present_mode,
            self.size,
            old.as_ref(),
        )?;
        Ok(()) // the old swapchain is destroyed here, after the new one replaced it
    }
}

impl Renderer for VkWindow {
    /// The headless counting frame on the window's device: its own buffers,
    /// pipeline and target, so the window's are untouched.
    fn count_rays(&mut self, run: &CountingRun, _shaders: &PathShaders) -> Result<RayKinds> {
        crate::rays::count_rays(&self.device, run)
    }

    fn api(&self) -> &'static str {
        "Vulkan"
    }

    fn storage_limit(&self) -> StorageLimit {
        self.device.storage_limit()
    }

    fn window(&self) -> &Window {
        &self.window
    }

    fn resize(&mut self, width: u32, height: u32) -> Result<()> {
        self.size = (width, height);
        self.rebuild_swapchain()
    }

    fn draw(&mut self, frame: &GpuFrame) -> Result<Option<Drawn>> {
        if self.stale {
            self.rebuild_swapchain()?;
        }
        let Some(chain) = &self.swapchain else {
            return Ok(None);
        };
        let draw = match &mut self.drawing {
            PathResources::Fragment(scene, _) => Draw::Fragment {
                render_pass: self.render_pass.render_pass,
                scene,
            },
            PathResources::Compute(compute) => {
                // The blit copies texel for texel: the storage image follows the swapchain.
                if compute.extent != chain.extent {
                    // The old image may still be in use by a frame.
                    self.device
                        .wait_idle()
                        .context("waiting for the GPU before resizing the storage image")?;
                    compute.resize(&self.device, chain.extent)?;
                }
                Draw::Compute(compute)
            }
        };
        match self
            .frames
            .draw(&self.device, &self.loader, chain, draw, frame)?
        {
            FrameResult::OutOfDate => {
                self.stale = true;
                Ok(None)
            }
            FrameResult::Presented { gpu_ms, suboptimal } => {
                self.stale = suboptimal;
                Ok(Some(Drawn { gpu_ms }))
            }
        }
    }

    fn load_scene(&mut self, scene: &GpuScene, shaders: &PathShaders) -> Result<()> {
        // The old scene's buffers and pipeline may still be in use.
        self.device
            .wait_idle()
            .context("waiting for the GPU before a scene or path switch")?;
        let extent = match (&self.swapchain, &self.drawing) {
            (Some(c), _) => c.extent,
            (None, PathResources::Compute(c)) => c.extent,
            (None, PathResources::Fragment(..)) => vk::Extent2D {
                width: self.size.0.max(1),
                height: self.size.1.max(1),
            },
        };
        self.drawing = path_resources(
            &self.device,
            scene,
            shaders,
            self.render_pass.render_pass,
            self.format.format,
            extent,
            self.compute_blocker.as_deref(),
        )?;
        Ok(())
    }

    /// The headless path, at the window's size, with the current path: the
    /// fragment path's RGBA32F target and render pass, or the compute path's
    /// storage image and dispatch, each with its pre-recorded commands and
    /// readback. The uniform block is written first, so the picture is the
    /// current view.
    fn capture(&mut self, frame: &GpuFrame, width: u32, height: u32) -> Result<FloatImage> {
        let device = &self.device;
        device
            .wait_idle()
            .context("waiting for the GPU before a capture")?;
        device.check_size(width, height)?;
        let uniform = match &self.drawing {
            PathResources::Fragment(s, _) => s.frame.buffer,
            PathResources::Compute(c) => c.frame.buffer,
        };
        device.run_once("writing the frame uniform buffer", |cmd| {
            let d = &device.device;
            // Read after write: the capture's tracer, of either path, reads
            // the block the update wrote.
            let written = [uniform];
            // SAFETY: `cmd` is run_once's, recording; the GPU is idle (waited
            // above), so no frame reads the uniform buffer, which `self.drawing`
            // owns; `frame` fits vkCmdUpdateBuffer (asserted in frames.rs).
            unsafe {
                d.cmd_update_buffer(cmd, uniform, 0, bytemuck::bytes_of(frame));
                pipeline_barrier::record(
                    device,
                    cmd,
                    &[(barrier::UNIFORM_TO_CAPTURE, On::Buffers(&written))],
                );
            }
        })?;
        let (scene, shaders) = match &self.drawing {
            PathResources::Fragment(scene, shaders) => (scene, shaders),
            PathResources::Compute(c) => {
                let compute = Compute::new(
                    device,
                    &c.frame,
                    &c.storage,
                    &c.shader,
                    width,
                    height,
                    (None, Span::DISPATCH),
                )?;
                compute.commands.submit()?;
                compute.commands.wait(false)?;
                return compute.read_back(device);
            }
        };
        let render_pass = RenderPass::offscreen(device)?;
        let set_layout = scene.descriptors.set_layout;
        let pipeline = Pipeline::new(
            device,
            set_layout,
            shaders,
            render_pass.render_pass,
            Some((width, height)),
        )?;
        let target = Target::new(device, render_pass.render_pass, width, height)?;
        let commands = Commands::record(
            device,
            render_pass.render_pass,
            &pipeline,
            &scene.descriptors,
            &target,
            None,
        )?;
        commands.submit()?;
        commands.wait(false)?;
        target.read_back(device)
    }
}

impl Drop for VkWindow {
    fn drop(&mut self) {
        // Orderly shutdown: let the GPU finish, then the fields drop in order.
        let _ = self.device.wait_idle();
    }
}
