//! The run, top to bottom: the shared setup from twinray-common (scene, shader
//! variant, buffer bytes), then every Vulkan object in the order the reader met
//! them, the timed frame loop, the readback, and the report.
//!
//! Vulkan objects must be destroyed before the objects they were made from
//! (buffers before the device, the device before the instance). Here each one is
//! a local that destroys itself in `Drop`, and Rust drops locals in reverse order
//! of creation: exactly the order Vulkan needs, on success and on every error path.

use crate::commands::Commands;
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
use twinray_common::cli::RenderArgs;
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
    let scene = args.load_scene()?;
    let variant = if args.generic { Variant::generic(scene.numerics) } else { Variant::for_scene(&scene) };
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
    let shaders = shader::build(variant)?;
    let gpu_scene = GpuScene::new(scene, width, height);

    let instance = Instance::new(args.validate)?;
    let device = Device::new(&instance)?;
    device.check_size(width, height)?;
    let limit = device.properties.limits.max_storage_buffer_range as u64;
    check_storage_limit(&gpu_scene, limit, "maxStorageBufferRange")?;

    let uniform = vk::BufferUsageFlags::UNIFORM_BUFFER;
    let frame = Buffer::device_local_with(&device, gpu_scene.frame_bytes(), uniform, "frame uniform buffer")?;
    let storage = binding::STORAGE
        .iter()
        .map(|&b| {
            let what = format!("{} storage buffer", storage_name(b));
            let usage = vk::BufferUsageFlags::STORAGE_BUFFER;
            Ok((b, Buffer::device_local_with(&device, gpu_scene.storage_bytes(b), usage, &what)?))
        })
        .collect::<Result<Vec<_>>>()?;
    let descriptors = Descriptors::new(&device, &frame, &storage)?;
    let pipeline = Pipeline::new(&device, descriptors.set_layout, &shaders, width, height)?;
    let target = Target::new(&device, pipeline.render_pass, width, height)?;
    let timestamps = Timestamps::new(&device)?;
    let commands = Commands::record(&device, &pipeline, &descriptors, &target, timestamps.as_ref())?;

    // The timed loop: one iteration = submit + wait, as the original study measured.
    let mut frames = Vec::new();
    let mut setup_ms = 0.0;
    for i in 0..args.frame_count() {
        let start = Instant::now();
        if i == 0 {
            setup_ms = (start - process_start).as_secs_f64() * 1e3;
        }
        commands.submit()?;
        commands.wait()?;
        let wall_ms = start.elapsed().as_secs_f64() * 1e3;
        let gpu_ms = timestamps.as_ref().map(Timestamps::read_ms).transpose()?;
        commands.reset_fence()?;
        frames.push(FrameTime { gpu_ms, wall_ms });
    }

    let image = target.read_back(&device)?;
    let mut report = RunReport {
        api: "vulkan".into(),
        device: device.name.clone(),
        driver: device.driver.clone(),
        api_version: device.api_version(),
        os: os_description(),
        scene: scene.stats(),
        variant: variant.label(),
        width,
        height,
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
