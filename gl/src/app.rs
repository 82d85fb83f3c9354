//! One headless run, in the order of the Vulkan twin: scene and shader from
//! `common`, context, limits, program, buffers, target, frame loop, readback,
//! PNG and JSON.

use crate::buffers::SceneBuffers;
use crate::context::Gl;
use crate::debug::DebugLog;
use crate::program::{EmptyVertexArray, Program};
use crate::target::{self, Target};
use crate::timer::Timer;
use anyhow::{anyhow, Context as _};
use glow::HasContext;
use std::time::Instant;
use twinray_common::cli::RenderArgs;
use twinray_common::error::bad_input;
use twinray_common::gpu::{check_storage_limit, GpuScene};
use twinray_common::image_io::FloatImage;
use twinray_common::report::{os_description, FrameTime, RunReport};
use twinray_common::shader::{self, Variant};

/// `started` is taken first thing in main, so `setup_ms` includes process,
/// driver and shader start-up, as in the Vulkan app.
pub fn run(args: RenderArgs, started: Instant) -> anyhow::Result<()> {
    if !args.headless {
        return Err(bad_input("windowed mode is not available yet; run with --headless"));
    }
    let scene = args.load_scene()?;
    let variant = if args.generic { Variant::generic(scene.numerics) } else { Variant::for_scene(&scene) };
    let shaders = shader::build(&variant)?;
    let (width, height) = (args.size.width, args.size.height);
    let gpu_scene = GpuScene::new(&scene, width, height);

    let mut ctx = Gl::headless(args.validate)?;
    let log = DebugLog::install(&mut ctx.gl);
    let gl = &ctx.gl;
    // SAFETY: plain string queries on the current context.
    let (renderer, vendor, version) = unsafe {
        (
            gl.get_parameter_string(glow::RENDERER),
            gl.get_parameter_string(glow::VENDOR),
            gl.get_parameter_string(glow::VERSION),
        )
    };
    target::check_size(gl, width, height)?;
    // SAFETY: plain query; 64-bit because the limit may exceed 2 GiB.
    let max_ssbo = unsafe { gl.get_parameter_i64(glow::MAX_SHADER_STORAGE_BLOCK_SIZE) };
    check_storage_limit(&gpu_scene, max_ssbo.max(0) as u64, "GL_MAX_SHADER_STORAGE_BLOCK_SIZE")?;

    // Declaration order is creation order; Rust drops locals in reverse, so GL
    // objects are deleted in reverse order on success and on every error path.
    let program = Program::new(gl, &shaders.vertex_glsl, &shaders.fragment_glsl)?;
    let _buffers = SceneBuffers::new(gl, &gpu_scene)?;
    let target = Target::new(gl, width, height)?;
    let vao = EmptyVertexArray::new(gl)?;
    let timer = Timer::new(gl, &renderer)?;
    program.bind(&vao);
    log.check(gl, "after setup");

    let (frames, setup_ms) = frame_loop(gl, &timer, args.frame_count(), started);
    let image = FloatImage::from_rgba(width, height, &target.read());
    log.check(gl, "after the frame loop");

    if let Some(out) = &args.out {
        image.save_png(out)?;
    }
    let errors = log.errors();
    if args.json {
        let mut report = RunReport {
            api: "opengl".into(),
            device: renderer,
            driver: format!("{vendor} {version}"),
            api_version: format!("OpenGL {version}"),
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
            validation_messages: errors,
        };
        report.summarise();
        println!("{}", serde_json::to_string(&report).context("serialising the JSON report")?);
    }
    if args.validate && errors > 0 {
        return Err(anyhow!("{errors} GL debug errors (see above)"));
    }
    Ok(())
}

/// The same loop as Vulkan's: one iteration is submit + wait, timed on the
/// wall clock around the GPU-timed draw. Returns the frames and `setup_ms`.
fn frame_loop(gl: &glow::Context, timer: &Timer, count: u32, started: Instant) -> (Vec<FrameTime>, f64) {
    let mut frames = Vec::with_capacity(count as usize);
    let mut setup_ms = 0.0;
    for i in 0..count {
        let t0 = Instant::now();
        if i == 0 {
            setup_ms = ms(t0 - started);
        }
        timer.begin();
        // SAFETY: program, VAO, buffers and FBO are bound and alive.
        unsafe { gl.draw_arrays(glow::TRIANGLES, 0, 3) };
        timer.end();
        // glFinish, not a fence: the wait is part of what the study timed.
        // SAFETY: no arguments; the context is current.
        unsafe { gl.finish() };
        let wall_ms = ms(t0.elapsed());
        frames.push(FrameTime { gpu_ms: timer.result_ms(), wall_ms });
    }
    (frames, setup_ms)
}

fn ms(d: std::time::Duration) -> f64 {
    d.as_secs_f64() * 1e3
}
