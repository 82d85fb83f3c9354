//! The run, top to bottom, in the walkthrough's order: the options checked
//! once (`Planner`), the instance and the device, then the run plan from
//! twinray-common (scene, BVH, shader variant, buffer bytes, checked against
//! the device's limits), then every Vulkan object the path needs, the timed
//! frame loop, the readback, and the report.
//!
//! Vulkan objects must be destroyed before the objects they were made from
//! (buffers before the device, the device before the instance). Here each one is
//! a local that destroys itself in `Drop`, and Rust drops locals in reverse order
//! of creation: exactly the order Vulkan needs, on success and on every error path.

use crate::commands::Commands;
use crate::compute::Compute;
use crate::descriptors::Descriptors;
use crate::device::Device;
use crate::instance::{Instance, VALIDATION_MESSAGES};
use crate::pipeline::{Pipeline, RenderPass};
use crate::rays::count_rays;
use crate::scene::scene_buffers;
use crate::target::Target;
use crate::timestamps::{Span, Timestamps};
use crate::window;
use anyhow::{bail, Result};
use std::sync::atomic::Ordering;
use std::time::Instant;
use twinray_common::cli::{FrameWait, RenderArgs, SceneMemory, VulkanKnobs};
use twinray_common::explain;
use twinray_common::plan::requests::Api;
use twinray_common::plan::{Planner, RunPlan};
use twinray_common::reference::image_io::FloatImage;
use twinray_common::report::{dump_shaders, timed_frames, FrameTime, RunReport};
use twinray_common::shader::build::{ComputeShader, PathShaders, Shaders};

pub fn run(args: RenderArgs, knobs: &VulkanKnobs, process_start: Instant) -> Result<()> {
    let Some(planner) = Planner::start(&args, Api::Vulkan)? else {
        return Ok(());
    };
    if !args.headless {
        return run_windowed(&planner, knobs, process_start);
    }
    let (mut report, image) = render(&planner, knobs, process_start)?;

    // Counted only now that every Vulkan object is gone, so teardown mistakes count too.
    report.validation_messages = VALIDATION_MESSAGES.load(Ordering::SeqCst);
    if let Some(path) = &args.out {
        image.save_png_for("--out", path)?;
    }
    if args.json {
        report.print_json()?;
    }
    if args.validate && report.validation_messages > 0 {
        bail!(
            "{} validation messages (see above)",
            report.validation_messages
        );
    }
    Ok(())
}

/// The window: `window::run` owns the loop; the report is the same shape as
/// headless (wall time = frame to frame; no NaN count, nothing is read back).
fn run_windowed(planner: &Planner, knobs: &VulkanKnobs, process_start: Instant) -> Result<()> {
    let args = planner.args();
    let (run, info) = window::run(planner, knobs, process_start)?;
    // Every Vulkan object is gone by now, so teardown mistakes count too.
    let messages = VALIDATION_MESSAGES.load(Ordering::SeqCst);
    if args.json {
        run.report("vulkan", info, messages).print_json()?;
    }
    if args.validate && messages > 0 {
        bail!("{messages} validation messages (see above)");
    }
    Ok(())
}

/// Everything Vulkan, from the instance to the readback, one named step per
/// line. Returns the report (without the validation count) and the last frame.
fn render(
    planner: &Planner,
    knobs: &VulkanKnobs,
    process_start: Instant,
) -> Result<(RunReport, FloatImage)> {
    let args = planner.args();
    let (width, height) = (args.size.width, args.size.height);
    let instance = Instance::new(args.validate, knobs.validation, &[], knobs.sync2)?;
    let device = Device::new(&instance, None, knobs, &planner.device())?;
    device.check_size(width, height)?;
    // The plan comes after the device, whose storage limit it is checked
    // against before any buffer exists.
    let plan = planner.prepare(&device.storage_limit(), width, height)?;
    if let Some(dir) = &args.dump_shaders {
        // The driver keeps its statistics only for pipelines made from now on.
        crate::statistics::enable();
        dump_shaders(dir, &plan.shaders.stages())?;
    }
    let run = HeadlessRun {
        args,
        device: &device,
        plan: &plan,
        idle_wait: knobs.wait == FrameWait::Idle,
        process_start,
    };
    let rendered = match &plan.shaders {
        PathShaders::Fragment(shaders) => render_fragment(&run, shaders)?,
        PathShaders::Compute(shader) => render_compute(&run, shader)?,
    };
    let host_memory = device.scene_memory == SceneMemory::Host;
    let label = variant_label(&plan, host_memory, run.idle_wait);
    let (frames, setup_ms, image) = rendered;
    let stats = crate::statistics::captured();
    let api = ("vulkan", device.info(), label);
    let mut report = planner.report(&plan, api, (frames, setup_ms), &image, stats)?;
    if args.count_rays {
        let gpu = plan.gpu_in_rows(width, height);
        let counting = plan.counting(&gpu, width, height);
        report.add_rays(count_rays(&device, &counting)?);
    }
    Ok((report, image))
    // Every Vulkan object is dropped here, newest first: ..., device, instance.
}

/// What both paths render from.
struct HeadlessRun<'a> {
    args: &'a RenderArgs,
    device: &'a Device,
    plan: &'a RunPlan,
    /// vkQueueWaitIdle + vkDeviceWaitIdle after each frame, as the 2018 study
    /// did, instead of the frame's fence (`--vk-wait idle`).
    idle_wait: bool,
    /// `setup_ms` runs from here to the first submit.
    process_start: Instant,
}

impl HeadlessRun<'_> {
    /// The timed loop, the same for both paths: one iteration = submit + wait.
    fn frames(
        &self,
        commands: &Commands,
        timestamps: Option<&Timestamps>,
    ) -> Result<(Vec<FrameTime>, f64)> {
        timed_frames(
            self.args.frame_plan(),
            self.process_start,
            "Frame 1: vkQueueSubmit + vkWaitForFences, timestamps read, vkResetFences",
            || {
                commands.submit()?;
                commands.wait(self.idle_wait)
            },
            || {
                let gpu_ms = timestamps.map(Timestamps::read_ms).transpose()?;
                commands.reset_fence()?;
                Ok(gpu_ms)
            },
        )
    }
}

/// The frames and the setup time the loop measured, and the last frame.
type Rendered = (Vec<FrameTime>, f64, FloatImage);

/// The fragment path, in the walkthrough's steps: scene buffers, descriptor
/// set, render pass, pipeline, the colour target, timestamps, the recorded
/// commands, the frames, the readback. Its objects drop at the end, newest
/// first, before the device.
fn render_fragment(run: &HeadlessRun, shaders: &Shaders) -> Result<Rendered> {
    let device = run.device;
    let (width, height) = (run.args.size.width, run.args.size.height);
    let (frame, storage) = scene_buffers(device, &run.plan.gpu())?;
    let descriptors = Descriptors::new(device, &frame, &storage)?;
    let render_pass = RenderPass::offscreen(device)?;
    let rp = render_pass.render_pass;
    let fixed_size = Some((width, height));
    let pipeline = Pipeline::new(device, descriptors.set_layout, shaders, rp, fixed_size)?;
    let target = Target::new(device, rp, width, height)?;
    let timestamps = Timestamps::new(device)?;
    let commands = Commands::record(
        device,
        rp,
        &pipeline,
        &descriptors,
        &target,
        timestamps.as_ref(),
    )?;
    let (frames, setup_ms) = run.frames(&commands, timestamps.as_ref())?;
    let image = target.read_back(device)?;
    explain::numbered(
        11,
        "Readback: vkCmdCopyImageToBuffer + HOST barrier, then map",
        || format!("{width}x{height} RGBA32F, top row first"),
    );
    Ok((frames, setup_ms, image))
}

/// The same tracer as a compute shader: the scene buffers, timestamps, then
/// compute.rs's pipeline, storage image and commands.
fn render_compute(run: &HeadlessRun, shader: &ComputeShader) -> Result<Rendered> {
    let size = &run.args.size;
    let (frame, storage) = scene_buffers(run.device, &run.plan.gpu())?;
    let timestamps = Timestamps::new(run.device)?;
    let compute = Compute::new(
        run.device,
        &frame,
        &storage,
        shader,
        size.width,
        size.height,
        (timestamps.as_ref(), Span::of(run.plan)),
    )?;
    let (frames, setup_ms) = run.frames(&compute.commands, timestamps.as_ref())?;
    let image = compute.read_back(run.device)?;
    explain::numbered(
        11,
        "Readback: vkCmdCopyImageToBuffer + HOST barrier, then map",
        || {
            format!(
                "{}x{} R32G32B32A32_SFLOAT storage image, top row first",
                size.width, size.height
            )
        },
    );
    Ok((frames, setup_ms, image))
}

/// The variant as the report names it, with the naive choices it was asked for.
fn variant_label(plan: &RunPlan, host_memory: bool, idle_wait: bool) -> String {
    format!(
        "{}{}{}",
        plan.variant.label(),
        if host_memory {
            " (host-visible buffers)"
        } else {
            ""
        },
        if idle_wait { " (idle wait)" } else { "" }
    )
}
