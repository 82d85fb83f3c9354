//! One headless run, in the order of the Vulkan twin: scene and shader from
//! `common`, context, limits, program, buffers, target, frame loop, readback,
//! PNG and JSON.

use crate::buffers::SceneBuffers;
use crate::compute::Compute;
use crate::context::{self, Gl};
use crate::debug::DebugLog;
use crate::probe::WarpProbe;
use crate::program::{self, EmptyVertexArray, Program};
use crate::rays::count_rays;
use crate::target::{self, Target};
use crate::timer::Timer;
use anyhow::anyhow;
use glow::HasContext;
use std::time::Instant;
use twinray_common::cli::{Experiment, OpenGlKnobs, RenderArgs, RenderPath};
use twinray_common::error::bad_input;
use twinray_common::explain;
use twinray_common::fragment_pass::{check_experiments, FragmentPass};
use twinray_common::gpu::upload::{check_storage_limit, GpuScene};
use twinray_common::reference::image_io::FloatImage;
use twinray_common::report::{dump_shaders, dump_statistics, FrameTime, RunReport};
use twinray_common::shader::build::{build, build_compute, restricts_resources};
use twinray_common::shader::variant::{CountingRun, Variant};

/// `started` is taken first thing in main, so `setup_ms` includes process,
/// driver and shader start-up, as in the Vulkan app.
// Long function: the OpenGL twin of vk's headless run, one block per step in the same order as vk/src/app.rs, so the two read side by side.
pub fn run(args: RenderArgs, knobs: &OpenGlKnobs, started: Instant) -> anyhow::Result<()> {
    if args.explain {
        explain::enable("twinray-gl", "OpenGL");
    }
    check_experiments(&args, false)?;
    if !args.headless {
        if args.gl_spirv {
            return Err(bad_input(
                "--gl-spirv is a headless measurement option; run it with --headless",
            ));
        }
        return run_windowed(&args, started);
    }
    if args.gl_spirv && args.experiment.contains(&Experiment::WarpProbe) {
        return Err(bad_input(
            "--gl-spirv with --experiment warp-probe: the probe is added to naga's GLSL, which --gl-spirv does not load; drop one of them",
        ));
    }
    if args.gl_spirv && args.experiment.contains(&Experiment::Glslang) {
        return Err(bad_input(
            "--gl-spirv with --experiment glslang: glslang's SPIR-V is 1.3 for Vulkan 1.1, and OpenGL loads SPIR-V 1.0 only; drop one of them",
        ));
    }
    let scene = args.load_scene()?;
    let variant = Variant::chosen(&scene, &args);
    let workgroup = args.compute_workgroup()?;
    let (width, height) = (args.size.width, args.size.height);
    let gpu_scene = GpuScene::new(&scene, width, height);

    let robust = args.experiment.contains(&Experiment::RobustAccess);
    let mut ctx = Gl::headless(args.validate, robust, knobs)?;
    let log = DebugLog::install(&mut ctx.gl);
    let gl = &ctx.gl;
    let info = context::device_info(gl);
    target::check_size(gl, width, height)?;
    // SAFETY: plain query; 64-bit because the limit may exceed 2 GiB.
    let max_ssbo = unsafe { gl.get_parameter_i64(glow::MAX_SHADER_STORAGE_BLOCK_SIZE) };
    check_storage_limit(
        &gpu_scene,
        max_ssbo.max(0) as u64,
        "GL_MAX_SHADER_STORAGE_BLOCK_SIZE",
    )?;

    // Declaration order is creation order; Rust drops locals in reverse, so GL
    // objects are deleted in reverse order on success and on every error path.
    let mut shader_stats = Vec::new();
    let (frames, setup_ms, pixels) = match args.path {
        RenderPath::Fragment => {
            let shaders = build(&variant)?;
            if let Some(dir) = &args.dump_shaders {
                dump_shaders(dir, &shaders.stages())?;
            }
            explain::step(
                "Shaders: GLSL -> naga module -> GLSL 450 core (twinray-common)",
                || format!("variant {}", variant.label()),
            );
            let program = if args.gl_spirv {
                let fs = twinray_common::shader::post::spirv_for_opengl(
                    &shaders.fragment_spirv,
                    restricts_resources(&variant),
                );
                Program::from_spirv(
                    gl,
                    &|name| ctx.proc_address(name),
                    &shaders.vertex_glsl,
                    &fs,
                )?
            } else {
                Program::new(gl, &shaders.vertex_glsl, &shaders.fragment_glsl)?
            };
            if let Some(dir) = &args.dump_shaders {
                shader_stats.push(program::dump_binary(
                    gl,
                    program.raw(),
                    args.gl_spirv,
                    dir,
                    "gl-program",
                )?);
            }
            let _buffers = SceneBuffers::new(gl, &gpu_scene)?;
            let pass = FragmentPass::of(&args.experiment);
            let target = Target::new(gl, width, height, &pass)?;
            let vao = EmptyVertexArray::new(gl)?;
            let timer = Timer::new(gl, &info.device)?;
            program.bind(&vao);
            log.check(gl, "after setup");
            // SAFETY: program, VAO, buffers and FBO are bound and alive.
            let draw = || unsafe {
                if pass.clear {
                    gl.clear(glow::COLOR_BUFFER_BIT);
                }
                gl.draw_arrays(glow::TRIANGLES, 0, pass.vertices() as i32);
            };
            let (frames, setup_ms) =
                frame_loop(gl, &timer, args.frame_count(), started, &|| {}, &draw);
            (frames, setup_ms, target.read())
        }
        // The same tracer as a compute shader: compute.rs owns its program and texture.
        RenderPath::Compute => {
            let shader = build_compute(&variant, workgroup)?;
            // Before the compile, so that a driver without the extension gets a clear refusal.
            let probe = if args.experiment.contains(&Experiment::WarpProbe) {
                Some(WarpProbe::new(gl)?)
            } else {
                None
            };
            let proc_address = |name: &std::ffi::CStr| ctx.proc_address(name);
            let spirv = args
                .gl_spirv
                .then_some(&proc_address as &dyn Fn(&std::ffi::CStr) -> *const std::ffi::c_void);
            let compute = Compute::new(gl, &shader, spirv, width, height)?;
            if let Some(dir) = &args.dump_shaders {
                dump_shaders(dir, &[("compute", &shader.spirv, &shader.glsl)])?;
                shader_stats.push(program::dump_binary(
                    gl,
                    compute.program(),
                    args.gl_spirv,
                    dir,
                    "gl-program",
                )?);
            }
            let _buffers = SceneBuffers::new(gl, &gpu_scene)?;
            let timer = Timer::new(gl, &info.device)?;
            log.check(gl, "after setup");
            // The barrier before the timer starts, as Vulkan records its
            // barrier before the first timestamp: both time the dispatch alone.
            let (frames, setup_ms) = frame_loop(
                gl,
                &timer,
                args.frame_count(),
                started,
                &|| compute.barrier_between_frames(),
                &|| compute.dispatch(),
            );
            if let Some(probe) = &probe {
                eprintln!("twinray-gl: {}", probe.summary()?);
            }
            (frames, setup_ms, compute.read())
        }
    };
    if let Some(dir) = &args.dump_shaders {
        dump_statistics(dir, &shader_stats)?;
    }
    explain::step("Frames: the draw or dispatch + glFinish each", || {
        format!(
            "{} frame(s); first wall {:.3} ms",
            frames.len(),
            frames.first().map_or(0.0, |f| f.wall_ms)
        )
    });
    let image = FloatImage::from_rgba(width, height, &pixels);
    explain::step("Readback", || {
        format!("{width}x{height} RGBA32F, top row first")
    });
    let rays = if args.count_rays {
        let counting = CountingRun {
            scene: &gpu_scene,
            variant: &variant,
            path: args.path,
            workgroup,
            width,
            height,
        };
        Some(count_rays(gl, &counting)?)
    } else {
        None
    };
    log.check(gl, "after the frame loop");

    if let Some(out) = &args.out {
        image.save_png_for("--out", out)?;
    }
    let errors = log.errors();
    if args.json {
        let label = if args.gl_spirv {
            format!("{} (SPIR-V)", variant.label())
        } else {
            variant.label()
        };
        let mut report = RunReport::builder("opengl", info, scene.stats(), label)
            .size(width, height)
            .path(args.path, workgroup)
            .frames(frames, setup_ms)
            .nonfinite_pixels(image.nonfinite_pixels())
            .validation_messages(errors)
            .shader_stats(shader_stats)
            .build();
        if let Some(kinds) = rays {
            report.add_rays(kinds);
        }
        report.print_json()?;
    }
    if args.validate && errors > 0 {
        return Err(anyhow!("{errors} GL debug errors (see above)"));
    }
    Ok(())
}

/// The window: `window::run` owns the loop; the report has the headless shape
/// (wall time = frame to frame; no NaN count, nothing is read back).
fn run_windowed(args: &RenderArgs, started: Instant) -> anyhow::Result<()> {
    let (run, info, errors) = crate::window::run(args, started)?;
    if args.json {
        run.report("opengl", info, errors).print_json()?;
    }
    if args.validate && errors > 0 {
        return Err(anyhow!("{errors} GL debug errors (see above)"));
    }
    Ok(())
}

/// The same loop as Vulkan's: one iteration is submit + wait, timed on the
/// wall clock around `before` (what Vulkan records ahead of its first
/// timestamp) and the GPU-timed `draw` (the draw call or the dispatch).
/// Returns the frames and `setup_ms`.
fn frame_loop(
    gl: &glow::Context,
    timer: &Timer,
    count: u32,
    started: Instant,
    before: &dyn Fn(),
    draw: &dyn Fn(),
) -> (Vec<FrameTime>, f64) {
    let mut frames = Vec::with_capacity(count as usize);
    let mut setup_ms = 0.0;
    for i in 0..count {
        let t0 = Instant::now();
        if i == 0 {
            setup_ms = ms(t0 - started);
        }
        before();
        timer.begin();
        draw();
        timer.end();
        // glFinish, not a fence: the wait is part of what the study timed.
        // SAFETY: no arguments; the context is current.
        unsafe { gl.finish() };
        let wall_ms = ms(t0.elapsed());
        frames.push(FrameTime {
            gpu_ms: timer.result_ms(),
            wall_ms,
        });
    }
    (frames, setup_ms)
}

fn ms(d: std::time::Duration) -> f64 {
    d.as_secs_f64() * 1e3
}
