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
use crate::descriptors::Descriptors;
use crate::device::Device;
use crate::instance::{Instance, VALIDATION_MESSAGES};
use crate::memory::Buffer;
use crate::pipeline::Pipeline;
use crate::target::Target;
use crate::timestamps::Timestamps;
use anyhow::{bail, Result};
use ash::vk;
use std::sync::atomic::Ordering;
use std::time::Instant;
use twinray_common::cli::{RenderArgs, RenderPath};
use twinray_common::error::bad_input;
use twinray_common::gpu::{binding, check_storage_limit, storage_name, GpuScene};
use twinray_common::image_io::FloatImage;
use twinray_common::report::{os_description, FrameTime, RunReport};
use twinray_common::scene::Scene;
use twinray_common::shader::{self, Variant};

pub fn run(args: RenderArgs, process_start: Instant) -> Result<()> {
    if !args.headless {
        return Err(bad_input("windowed mode is not available yet; run with --headless"));
    }
    if args.gl_spirv {
        return Err(bad_input("--gl-spirv is an OpenGL option: Vulkan always runs naga's SPIR-V"));
    }
    let scene = args.load_scene()?;
    let variant = if args.generic { Variant::generic() } else { Variant::for_scene(&scene) };
    let (mut report, image) = render(&args, &scene, &variant, process_start)?;

    // Counted only now that every Vulkan object is gone, so teardown mistakes count too.
    report.validation_messages = VALIDATION_MESSAGES.load(Ordering::SeqCst);
    if let Some(path) = &args.out {
        image.save_png(path)?;
    }
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    }
    if args.validate && report.validation_messages > 0 {
        bail!("{} validation messages (see above)", report.validation_messages);
    }
    Ok(())
}

/// Everything Vulkan, from the instance to the readback. Returns the report
/// (without the validation count) and the last frame.
fn render(
    args: &RenderArgs,
    scene: &Scene,
    variant: &Variant,
    process_start: Instant,
) -> Result<(RunReport, FloatImage)> {
    let (width, height) = (args.size.width, args.size.height);
    let workgroup = args.compute_workgroup()?;
    let gpu_scene = GpuScene::new(scene, width, height);

    let instance = Instance::new(args.validate)?;
    let device = Device::new(&instance)?;
    device.check_size(width, height)?;
    let limit = device.properties.limits.max_storage_buffer_range as u64;
    check_storage_limit(&gpu_scene, limit, "maxStorageBufferRange")?;

    // Device-local memory, filled once through a staging buffer, is the careful
    // choice. TWINRAY_VK_MEMORY=host keeps the scene in host memory instead, so
    // the comparison can show what a naive placement costs.
    let host_memory = match std::env::var("TWINRAY_VK_MEMORY").as_deref() {
        Ok("host") => true,
        Ok("device") | Err(_) => false,
        Ok(other) => {
            return Err(bad_input(format!("TWINRAY_VK_MEMORY='{other}' is not 'device' or 'host'")));
        }
    };
    // TWINRAY_VK_WAIT=idle waits for each frame with vkQueueWaitIdle +
    // vkDeviceWaitIdle, as the 2018 study did, instead of the frame's fence.
    let idle_wait = match std::env::var("TWINRAY_VK_WAIT").as_deref() {
        Ok("idle") => true,
        Ok("fence") | Err(_) => false,
        Ok(other) => return Err(bad_input(format!("TWINRAY_VK_WAIT='{other}' is not 'fence' or 'idle'"))),
    };
    let place = |bytes: &[u8], usage: vk::BufferUsageFlags, what: &str| {
        if host_memory {
            Buffer::host_visible_with(&device, bytes, usage, what)
        } else {
            Buffer::device_local_with(&device, bytes, usage, what)
        }
    };
    let uniform = vk::BufferUsageFlags::UNIFORM_BUFFER;
    let frame = place(gpu_scene.frame_bytes(), uniform, "frame uniform buffer")?;
    let storage = binding::STORAGE
        .iter()
        .map(|&b| {
            let what = format!("{} storage buffer", storage_name(b));
            let usage = vk::BufferUsageFlags::STORAGE_BUFFER;
            Ok((b, place(gpu_scene.storage_bytes(b), usage, &what)?))
        })
        .collect::<Result<Vec<_>>>()?;
    let timestamps = Timestamps::new(&device)?;
    let run_frames = |commands: &Commands| frame_loop(commands, timestamps.as_ref(), args.frame_count(), idle_wait, process_start);
    let (frames, setup_ms, image) = match args.path {
        RenderPath::Fragment => {
            let shaders = shader::build(variant)?;
            let descriptors = Descriptors::new(&device, &frame, &storage)?;
            let pipeline = Pipeline::new(&device, descriptors.set_layout, &shaders, width, height)?;
            let target = Target::new(&device, pipeline.render_pass, width, height)?;
            let commands = Commands::record(&device, &pipeline, &descriptors, &target, timestamps.as_ref())?;
            let (frames, setup_ms) = run_frames(&commands)?;
            (frames, setup_ms, target.read_back(&device)?)
        }
        // The same tracer as a compute shader: compute.rs owns its pipeline and storage image.
        RenderPath::Compute => {
            let shader = shader::build_compute(variant, workgroup)?;
            let compute = Compute::new(&device, &frame, &storage, &shader, width, height, timestamps.as_ref())?;
            let (frames, setup_ms) = run_frames(&compute.commands)?;
            (frames, setup_ms, compute.read_back(&device)?)
        }
    };
    let mut report = RunReport {
        api: "vulkan".into(),
        device: device.name.clone(),
        driver: device.driver.clone(),
        api_version: device.api_version(),
        os: os_description(),
        scene: scene.stats(),
        variant: format!(
            "{}{}{}",
            variant.label(),
            if host_memory { " (host-visible buffers)" } else { "" },
            if idle_wait { " (idle wait)" } else { "" }
        ),
        width,
        height,
        path: args.path,
        workgroup: (args.path == RenderPath::Compute).then(|| workgroup.to_string()),
        frames,
        gpu_ms: None,
        wall_ms: None,
        nonfinite_pixels: image.nonfinite_pixels(),
        setup_ms,
        validation_messages: 0,
    };
    report.summarise();
    Ok((report, image))
    // Every Vulkan object is dropped here, newest first: commands, ..., device, instance.
}

/// The timed loop: one iteration = submit + wait, as the original study measured.
/// Returns the frames and `setup_ms` (process start to the first submit).
fn frame_loop(
    commands: &Commands,
    timestamps: Option<&Timestamps>,
    count: u32,
    idle_wait: bool,
    process_start: Instant,
) -> Result<(Vec<FrameTime>, f64)> {
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
    }
    Ok((frames, setup_ms))
}
