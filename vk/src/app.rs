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
use twinray_common::shader::{self, Shaders, Variant};

/// What the Vulkan part of the run hands back once every Vulkan object is gone.
struct Rendered {
    device: String,
    driver: String,
    api_version: String,
    frames: Vec<FrameTime>,
    setup_ms: f64,
    image: FloatImage,
}

pub fn run(args: RenderArgs, process_start: Instant) -> Result<()> {
    if !args.headless {
        return Err(bad_input("twinray-vk: windowed mode is not available yet; run with --headless"));
    }
    let scene = args.load_scene()?;
    let variant = if args.generic { Variant::generic() } else { Variant::for_scene(&scene) };
    let shaders = shader::build(&variant)?;
    let (width, height) = (args.size.width, args.size.height);
    let gpu_scene = GpuScene::new(&scene, width, height);

    let rendered = render(&args, &shaders, &gpu_scene, process_start)?;
    // Read only now: teardown mistakes (e.g. a leaked object) are reported too.
    let validation_messages = VALIDATION_MESSAGES.load(Ordering::SeqCst);

    if let Some(path) = &args.out {
        rendered.image.save_png(path)?;
    }
    let mut report = RunReport {
        api: "vulkan".into(),
        device: rendered.device,
        driver: rendered.driver,
        api_version: rendered.api_version,
        os: os_description(),
        scene: scene.stats(),
        variant: variant.label(),
        width,
        height,
        frames: rendered.frames,
        gpu_ms: None,
        wall_ms: None,
        nonfinite_pixels: rendered.image.nonfinite_pixels(),
        setup_ms: rendered.setup_ms,
        validation_messages,
    };
    report.summarise();
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    }
    if args.validate && validation_messages > 0 {
        bail!("{validation_messages} validation messages (see above)");
    }
    Ok(())
}

fn render(args: &RenderArgs, shaders: &Shaders, gpu_scene: &GpuScene, process_start: Instant) -> Result<Rendered> {
    let (width, height) = (args.size.width, args.size.height);
    let instance = Instance::new(args.validate)?;
    let device = Device::new(&instance)?;
    device.check_size(width, height)?;
    let limit = device.properties.limits.max_storage_buffer_range as u64;
    check_storage_limit(gpu_scene, limit, "maxStorageBufferRange")?;

    let frame = Buffer::device_local_with(&device, gpu_scene.frame_bytes(), vk::BufferUsageFlags::UNIFORM_BUFFER, "frame uniform buffer")?;
    let storage = binding::STORAGE
        .iter()
        .map(|&b| {
            let what = format!("{} storage buffer", storage_name(b));
            let bytes = gpu_scene.storage_bytes(b);
            Ok((b, Buffer::device_local_with(&device, &bytes, vk::BufferUsageFlags::STORAGE_BUFFER, &what)?))
        })
        .collect::<Result<Vec<_>>>()?;
    let descriptors = Descriptors::new(&device, &frame, &storage)?;
    let pipeline = Pipeline::new(&device, descriptors.set_layout, shaders, width, height)?;
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
    Ok(Rendered {
        device: device.name.clone(),
        driver: device.driver.clone(),
        api_version: device.api_version(),
        frames,
        setup_ms,
        image,
    })
    // Every Vulkan object is dropped here, newest first: commands ... device, instance.
}
