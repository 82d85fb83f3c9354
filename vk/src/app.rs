//! The run, top to bottom: the shared setup from twinray-common (scene, shader
//! variant, buffer bytes), then every Vulkan object in the order the reader met
//! them, the timed frame loop, the readback, and the report.
//!
//! Vulkan objects must be destroyed before the objects they were made from
//! (buffers before the device, the device before the instance). Here each one is
//! a local that destroys itself in `Drop`, and Rust drops locals in reverse order
//! of creation: exactly the order Vulkan needs, on success and on every error path.

use crate::commands::Commands;
use crate::compute::Compute;
use crate::device::Device;
use crate::instance::{Instance, VALIDATION_MESSAGES};
use crate::pipeline::RenderPass;
use crate::rays::count_rays;
use crate::scene::SceneResources;
use crate::target::Target;
use crate::timestamps::Timestamps;
use crate::window;
use anyhow::{bail, Result};
use std::sync::atomic::Ordering;
use std::time::Instant;
use twinray_common::cli::{
    Experiment, FrameWait, RenderArgs, RenderPath, SceneMemory, VulkanKnobs, Workgroup,
};
use twinray_common::error::bad_input;
use twinray_common::explain;
use twinray_common::fragment_pass::{check_experiments, FragmentPass};
use twinray_common::gpu::upload::GpuScene;
use twinray_common::reference::image_io::FloatImage;
use twinray_common::report::{dump_shaders, dump_statistics, FrameTime, RunReport};
use twinray_common::scene::Scene;
use twinray_common::shader::build::{build, build_compute, ComputeShader, Shaders};
use twinray_common::shader::variant::{CountingRun, Variant};

pub fn run(args: RenderArgs, knobs: &VulkanKnobs, process_start: Instant) -> Result<()> {
    if args.explain {
        explain::enable("twinray-vk", "Vulkan");
    }
    if args.gl_spirv {
        return Err(bad_input(
            "--gl-spirv is an OpenGL option: Vulkan always runs naga's SPIR-V",
        ));
    }
    check_experiments(&args, true)?;
    if !args.headless {
        return run_windowed(&args, knobs, process_start);
    }
    let scene = args.load_scene()?;
    let variant = Variant::chosen(&scene, &args);
    let (mut report, image) = render(&args, knobs, &scene, &variant, process_start)?;

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
fn run_windowed(args: &RenderArgs, knobs: &VulkanKnobs, process_start: Instant) -> Result<()> {
    let (run, info) = window::run(args, knobs, process_start)?;
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
    args: &RenderArgs,
    knobs: &VulkanKnobs,
    scene: &Scene,
    variant: &Variant,
    process_start: Instant,
) -> Result<(RunReport, FloatImage)> {
    let (width, height) = (args.size.width, args.size.height);
    let workgroup = args.compute_workgroup()?;
    let shaders = build_shaders(args, variant)?;
    let gpu_scene = GpuScene::new(scene, width, height);
    let instance = Instance::new(args.validate, knobs.validation, &[])?;
    let compute_only = args.experiment.contains(&Experiment::ComputeQueue);
    let robust_access = args.experiment.contains(&Experiment::RobustAccess);
    let device = Device::new(
        &instance,
        None,
        knobs,
        compute_only,
        args.count_rays,
        robust_access,
    )?;
    device.check_size(width, height)?;
    // --vk-wait idle waits for each frame with vkQueueWaitIdle +
    // vkDeviceWaitIdle, as the 2018 study did, instead of the frame's fence.
    let idle_wait = knobs.wait == FrameWait::Idle;
    let host_memory = device.scene_memory == SceneMemory::Host;
    let timestamps = Timestamps::new(&device)?;
    let frame_loop = FrameLoop {
        timestamps: timestamps.as_ref(),
        count: args.frame_count(),
        idle_wait,
        process_start,
    };
    let run = HeadlessRun {
        args,
        device: &device,
        gpu_scene: &gpu_scene,
        frame_loop,
    };
    let rendered = match args.path {
        RenderPath::Fragment => render_fragment(&run, &shaders)?,
        RenderPath::Compute => render_compute(&run, &build_compute(variant, workgroup)?)?,
    };
    let label = variant_label(variant, host_memory, idle_wait);
    let (mut report, image) = report(args, scene, &device, label, workgroup, rendered)?;
    if args.count_rays {
        let counting = CountingRun {
            scene: &gpu_scene,
            variant,
            path: args.path,
            workgroup,
            width,
            height,
        };
        report.add_rays(count_rays(&device, &counting)?);
    }
    Ok((report, image))
    // Every Vulkan object is dropped here, newest first: ..., device, instance.
}

/// What both paths render from.
struct HeadlessRun<'a> {
    args: &'a RenderArgs,
    device: &'a Device,
    gpu_scene: &'a GpuScene,
    frame_loop: FrameLoop<'a>,
}

impl HeadlessRun<'_> {
    /// `--dump-shaders`: the stages this run compiles.
    fn dump_shaders(&self, stages: &[(&str, &[u32], &str)]) -> Result<()> {
        match &self.args.dump_shaders {
            Some(dir) => dump_shaders(dir, stages),
            None => Ok(()),
        }
    }
}

/// The frames and the setup time `frame_loop` measured, and the last frame.
type Rendered = (Vec<FrameTime>, f64, FloatImage);

/// naga's vertex and fragment shaders for the scene's variant; `--dump-shaders`
/// turns on the driver's statistics before any pipeline is made.
fn build_shaders(args: &RenderArgs, variant: &Variant) -> Result<Shaders> {
    let shaders = build(variant)?;
    if args.dump_shaders.is_some() {
        crate::statistics::enable();
    }
    explain::step(
        "Shaders: GLSL -> naga module -> SPIR-V (twinray-common)",
        || format!("variant {}", variant.label()),
    );
    Ok(shaders)
}

/// The fragment path: render pass, scene buffers, descriptor set and pipeline,
/// the colour target, the recorded commands, the frames, the readback. Its
/// objects drop at the end, newest first, before the device.
fn render_fragment(run: &HeadlessRun, shaders: &Shaders) -> Result<Rendered> {
    let (device, frame_loop) = (run.device, &run.frame_loop);
    let (width, height) = (run.args.size.width, run.args.size.height);
    run.dump_shaders(&shaders.stages())?;
    let pass = FragmentPass::of(&run.args.experiment);
    let render_pass = RenderPass::offscreen(device, &pass)?;
    let rp = render_pass.render_pass;
    // None: a pipeline whose viewport and scissor are set while recording.
    let fixed_size = (!pass.dynamic_viewport).then_some((width, height));
    let resources = SceneResources::new(device, run.gpu_scene, shaders, rp, fixed_size)?;
    let (pipeline, descriptors) = (&resources.pipeline, &resources.descriptors);
    let target = Target::new(device, rp, width, height, &pass)?;
    let timestamps = frame_loop.timestamps;
    let commands = Commands::record(
        device,
        rp,
        pipeline,
        descriptors,
        &target,
        timestamps,
        &pass,
    )?;
    let (frames, setup_ms) = frame_loop.run(&commands)?;
    let image = target.read_back(device)?;
    explain::step(
        "Readback: vkCmdCopyImageToBuffer + HOST barrier, then map",
        || format!("{width}x{height} {}, top row first", pass.format_name()),
    );
    Ok((frames, setup_ms, image))
}

/// The same tracer as a compute shader: compute.rs owns its pipeline and
/// storage image.
fn render_compute(run: &HeadlessRun, shader: &ComputeShader) -> Result<Rendered> {
    let size = &run.args.size;
    run.dump_shaders(&[("compute", &shader.spirv, &shader.glsl)])?;
    let (frame, storage) = crate::scene::scene_buffers(run.device, run.gpu_scene)?;
    let timestamps = run.frame_loop.timestamps;
    let compute = Compute::new(
        run.device,
        &frame,
        &storage,
        shader,
        size.width,
        size.height,
        timestamps,
    )?;
    let (frames, setup_ms) = run.frame_loop.run(&compute.commands)?;
    Ok((frames, setup_ms, compute.read_back(run.device)?))
}

/// The variant as the report names it, with the naive choices it was asked for.
fn variant_label(variant: &Variant, host_memory: bool, idle_wait: bool) -> String {
    format!(
        "{}{}{}",
        variant.label(),
        if host_memory {
            " (host-visible buffers)"
        } else {
            ""
        },
        if idle_wait { " (idle wait)" } else { "" }
    )
}

/// The run's report (device, variant, size, frames, and what the driver said
/// of the compiled shaders), with the last frame.
fn report(
    args: &RenderArgs,
    scene: &Scene,
    device: &Device,
    variant_label: String,
    workgroup: Workgroup,
    (frames, setup_ms, image): Rendered,
) -> Result<(RunReport, FloatImage)> {
    let shader_stats = crate::statistics::captured();
    if let Some(dir) = &args.dump_shaders {
        dump_statistics(dir, &shader_stats)?;
    }
    let report = RunReport::builder("vulkan", device.info(), scene.stats(), variant_label)
        .size(args.size.width, args.size.height)
        .path(args.path, workgroup)
        .frames(frames, setup_ms)
        .nonfinite_pixels(image.nonfinite_pixels())
        .shader_stats(shader_stats)
        .build();
    Ok((report, image))
}

/// The timed loop, the same for both paths: one iteration = submit + wait,
/// as the original study measured.
struct FrameLoop<'a> {
    timestamps: Option<&'a Timestamps>,
    count: u32,
    idle_wait: bool,
    /// `setup_ms` runs from here to the first submit.
    process_start: Instant,
}

impl FrameLoop<'_> {
    /// Runs `commands` `count` times. Returns the frames and `setup_ms`.
    fn run(&self, commands: &Commands) -> Result<(Vec<FrameTime>, f64)> {
        let FrameLoop {
            timestamps,
            count,
            idle_wait,
            process_start,
        } = *self;
        let mut frames = Vec::new();
        let mut setup_ms = 0.0;
        for i in 0..count {
            let start = Instant::now();
            if i == 0 {
                setup_ms = (start - process_start).as_secs_f64() * 1e3;
            }
            commands.submit()?;
            commands.wait(idle_wait)?;
            let wall_ms = start.elapsed().as_secs_f64() * 1e3;
            let gpu_ms = timestamps.map(Timestamps::read_ms).transpose()?;
            commands.reset_fence()?;
            frames.push(FrameTime { gpu_ms, wall_ms });
            if i == 0 {
                explain::step(
                    "Frame 1: vkQueueSubmit + vkWaitForFences + vkResetFences",
                    || {
                        let gpu = gpu_ms.map_or("no timestamps on this queue".into(), |g| {
                            format!("GPU {g:.3} ms")
                        });
                        format!("wall {wall_ms:.3} ms, {gpu}; later frames resubmit the same command buffer")
                    },
                );
            }
        }
        Ok((frames, setup_ms))
    }
}
