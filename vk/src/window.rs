//! The windowed run: the same setup as headless, in the same order, with a
//! window, a surface and a swapchain in place of the offscreen image, and the
//! frame loop of frames.rs driven by the shared event loop
//! (`twinray_common::interactive`, which both apps use, so keys, title and
//! camera behave identically).
//!
//! `VkWindow` owns every object. Its fields are declared newest first, so Rust
//! drops them in the reverse order of creation, which is the order Vulkan
//! needs: frames, swapchain, scene, render pass, device, surface, instance,
//! and the window last of all (the surface refers to it).

use crate::commands::Commands;
use crate::device::Device;
use crate::frames::{FrameResult, Frames};
use crate::instance::Instance;
use crate::pipeline::{Pipeline, RenderPass};
use crate::scene::SceneResources;
use crate::surface::{self, Surface};
use crate::swapchain::{self, Swapchain};
use crate::target::Target;
use anyhow::{Context, Result};
use ash::{khr, vk};
use std::time::Instant;
use twinray_common::cli::RenderArgs;
use twinray_common::explain;
use twinray_common::gpu::{GpuFrame, GpuScene};
use twinray_common::image_io::FloatImage;
use twinray_common::interactive::{self, Drawn, Renderer, WindowedRun};
use twinray_common::shader::{self, Shaders};
use winit::window::Window;

pub struct VkWindow {
    frames: Frames,
    /// `None` while the window has no area (minimized).
    swapchain: Option<Swapchain>,
    scene: SceneResources,
    render_pass: RenderPass,
    shaders: Shaders,
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
pub fn run(args: &RenderArgs, started: Instant) -> Result<(WindowedRun, DeviceInfo)> {
    let scene = args.load_scene()?;
    let variant = interactive::variant_for(args, &scene);
    let shaders = shader::build(&variant)?;
    explain::step(
        "Shaders: GLSL -> naga module -> SPIR-V (twinray-common)",
        || format!("variant {}", variant.label()),
    );

    let event_loop = interactive::event_loop()?;
    // winit 0.30 prefers windows made inside `resumed` (for Android's and the
    // web's life cycles). On desktops a window made before the loop starts
    // works the same, and lets setup run top to bottom like the headless path.
    #[allow(deprecated)]
    let window = event_loop
        .create_window(interactive::window_attributes(args, &scene.name, "Vulkan"))
        .context("creating the window")?;
    explain::step("Window (winit)", || {
        let s = window.inner_size();
        format!("{}x{} physical pixels", s.width, s.height)
    });
    let instance = Instance::new(args.validate, surface::required_extensions(&window)?)?;
    let surface = Surface::new(&instance, &window)?;
    let device = Device::new(&instance, Some(&surface))?;
    let loader = khr::swapchain::Device::new(&instance.instance, &device.device);
    let format = swapchain::choose_format(&device, &surface)?;
    let present_mode = swapchain::choose_present_mode(&device, &surface, args.vsync)?;
    let render_pass = RenderPass::for_swapchain(&device, format.format)?;
    let size = window.inner_size();
    let gpu = GpuScene::new(&scene, size.width.max(1), size.height.max(1));
    let scene_resources =
        SceneResources::new(&device, &gpu, &shaders, render_pass.render_pass, None)?;
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
    let frames = Frames::new(&device)?;
    let info = DeviceInfo {
        name: device.name.clone(),
        driver: device.driver.clone(),
        api_version: device.api_version(),
    };
    let renderer = VkWindow {
        frames,
        swapchain: chain,
        scene: scene_resources,
        render_pass,
        shaders,
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
    explain::step("Frame loop starts", || {
        "per frame: wait fence, acquire image, re-record, submit (wait image-available, signal render-finished), present".into()
    });
    let run = interactive::run(
        "twinray-vk",
        event_loop,
        renderer,
        args,
        scene,
        variant,
        started,
    )?;
    Ok((run, info))
}

/// What the JSON report says about the device, kept after the device is gone.
pub struct DeviceInfo {
    pub name: String,
    pub driver: String,
    pub api_version: String,
}

impl VkWindow {
    /// Waits for the GPU, then replaces the swapchain (or drops it while minimized).
    fn rebuild_swapchain(&mut self) -> Result<()> {
        // SAFETY: nothing may be destroyed while a frame still uses it.
        unsafe { self.device.device.device_wait_idle() }
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
    fn api(&self) -> &'static str {
        "Vulkan"
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
        let rp = self.render_pass.render_pass;
        match self
            .frames
            .draw(&self.device, &self.loader, chain, rp, &self.scene, frame)?
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

    fn load_scene(&mut self, scene: &GpuScene, shaders: &Shaders) -> Result<()> {
        // SAFETY: the old scene's buffers and pipeline may still be in use.
        unsafe { self.device.device.device_wait_idle() }
            .context("waiting for the GPU before a scene switch")?;
        let rp = self.render_pass.render_pass;
        self.scene = SceneResources::new(&self.device, scene, shaders, rp, None)?;
        self.shaders = shaders.clone();
        Ok(())
    }

    /// The headless path, at the window's size: RGBA32F target, pre-recorded
    /// commands, readback. The uniform block is written first, so the picture
    /// is the current view.
    fn capture(&mut self, frame: &GpuFrame, width: u32, height: u32) -> Result<FloatImage> {
        let device = &self.device;
        unsafe { device.device.device_wait_idle() }
            .context("waiting for the GPU before a capture")?;
        device.check_size(width, height)?;
        let uniform = self.scene.frame.buffer;
        device.run_once("writing the frame uniform buffer", |cmd| unsafe {
            device
                .device
                .cmd_update_buffer(cmd, uniform, 0, bytemuck::bytes_of(frame));
            let barrier = vk::BufferMemoryBarrier::default()
                .src_access_mask(vk::AccessFlags::TRANSFER_WRITE)
                .dst_access_mask(vk::AccessFlags::UNIFORM_READ)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .buffer(uniform)
                .size(vk::WHOLE_SIZE);
            device.device.cmd_pipeline_barrier(
                cmd,
                vk::PipelineStageFlags::TRANSFER,
                vk::PipelineStageFlags::FRAGMENT_SHADER,
                vk::DependencyFlags::empty(),
                &[],
                &[barrier],
                &[],
            );
        })?;
        let render_pass = RenderPass::offscreen(device)?;
        let set_layout = self.scene.descriptors.set_layout;
        let pipeline = Pipeline::new(
            device,
            set_layout,
            &self.shaders,
            render_pass.render_pass,
            Some((width, height)),
        )?;
        let target = Target::new(device, render_pass.render_pass, width, height)?;
        let commands = Commands::record(
            device,
            render_pass.render_pass,
            &pipeline,
            &self.scene.descriptors,
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
        // SAFETY: plain wait on a live device.
        let _ = unsafe { self.device.device.device_wait_idle() };
    }
}
