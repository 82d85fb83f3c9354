//! The run, top to bottom, with the same functions in the same order as the
//! Vulkan twin (vk/src/app.rs): the options checked once (`Planner`), the
//! context (OpenGL's instance and device in one), then the run plan from
//! twinray-common (scene, BVH, shader variant, buffer bytes, checked against
//! the context's limits), then every GL object the path needs, the timed frame
//! loop, the readback, and the report.
//!
//! GL objects are deleted before the context they live in. Here each one is a
//! local that deletes itself in `Drop`, and Rust drops locals in reverse order
//! of creation, so on success and on every error path they go first.

use crate::buffers::SceneBuffers;
use crate::compute::Compute;
use crate::context::{self, Gl};
use crate::debug::DebugLog;
use crate::probe::WarpProbe;
use crate::program::{self, EmptyVertexArray, Program};
use crate::rays::count_rays;
use crate::target::{self, Target};
use crate::timer::Timer;
use anyhow::{anyhow, Result};
use glow::HasContext;
use std::time::Instant;
use twinray_common::cli::{OpenGlKnobs, RenderArgs};
use twinray_common::explain;
use twinray_common::plan::requests::Api;
use twinray_common::plan::{Planner, RunPlan};
use twinray_common::reference::image_io::FloatImage;
use twinray_common::report::{
    dump_shaders, timed_frames, DeviceInfo, FrameTime, RunReport, ShaderStats,
};
use twinray_common::shader::build::{ComputeShader, PathShaders, Shaders};

/// `started` is taken first thing in main, so `setup_ms` includes process,
/// driver and shader start-up, as in the Vulkan app.
pub fn run(args: RenderArgs, knobs: &OpenGlKnobs, started: Instant) -> Result<()> {
    let Some(planner) = Planner::start(&args, Api::OpenGl)? else {
        return Ok(());
    };
    if !args.headless {
        return run_windowed(&planner, started);
    }
    let (report, image) = render(&planner, knobs, started)?;

    if let Some(out) = &args.out {
        image.save_png_for("--out", out)?;
    }
    if args.json {
        report.print_json()?;
    }
    if args.validate && report.validation_messages > 0 {
        return Err(anyhow!(
            "{} GL debug errors (see above)",
            report.validation_messages
        ));
    }
    Ok(())
}

/// The window: `window::run` owns the loop; the report has the headless shape
/// (wall time = frame to frame; no NaN count, nothing is read back).
fn run_windowed(planner: &Planner, started: Instant) -> Result<()> {
    let args = planner.args();
    let (run, info, errors) = crate::window::run(planner, started)?;
    if args.json {
        run.report("opengl", info, errors).print_json()?;
    }
    if args.validate && errors > 0 {
        return Err(anyhow!("{errors} GL debug errors (see above)"));
    }
    Ok(())
}

/// Everything OpenGL, from the context to the readback, one named step per
/// line. Returns the report (with the debug-error count) and the last frame.
fn render(
    planner: &Planner,
    knobs: &OpenGlKnobs,
    started: Instant,
) -> Result<(RunReport, FloatImage)> {
    let args = planner.args();
    let (width, height) = (args.size.width, args.size.height);
    let mut ctx = Gl::headless(args.validate, knobs)?;
    let log = DebugLog::install(&mut ctx.gl);
    let ctx = &ctx;
    let gl = &ctx.gl;
    let info = context::device_info(gl);
    target::check_size(gl, width, height)?;
    // The plan comes after the context, whose storage limit it is checked
    // against before any buffer exists.
    let plan = planner.prepare(&context::storage_limit(gl), width, height)?;
    if let Some(dir) = &args.dump_shaders {
        dump_shaders(dir, &plan.shaders.stages())?;
    }
    let run = HeadlessRun {
        args,
        ctx,
        log: &log,
        info: &info,
        plan: &plan,
        started,
    };
    let (rendered, shader_stats) = match &plan.shaders {
        PathShaders::Fragment(shaders) => render_fragment(&run, shaders)?,
        PathShaders::Compute(shader) => render_compute(&run, shader)?,
    };
    log.check(gl, "after the frame loop");
    let label = variant_label(&plan, args.gl_spirv);
    let (frames, setup_ms, pixels) = rendered;
    let image = FloatImage::from_rgba(width, height, &pixels);
    let api = ("opengl", info.clone(), label);
    let mut report = planner.report(&plan, api, (frames, setup_ms), &image, shader_stats)?;
    if args.count_rays {
        let gpu = plan.gpu_in_rows(width, height);
        let counting = plan.counting(&gpu, width, height);
        report.add_rays(count_rays(gl, &counting)?);
        log.check(gl, "after the ray count");
    }
    report.validation_messages = log.errors();
    Ok((report, image))
    // Every GL object is deleted here, newest first, then the context.
}

/// What both paths render from.
struct HeadlessRun<'a> {
    args: &'a RenderArgs,
    ctx: &'a Gl,
    log: &'a DebugLog,
    info: &'a DeviceInfo,
    plan: &'a RunPlan,
    /// `setup_ms` runs from here to the first frame.
    started: Instant,
}

impl HeadlessRun<'_> {
    /// The timed loop, the same for both paths: one iteration = the GPU-timed
    /// `draw` (the draw call or the dispatch), then glFinish, not a fence: the
    /// wait is part of what the study timed, and it completes the frame before
    /// the next begins.
    fn frames(&self, timer: &Timer, draw: &dyn Fn()) -> Result<(Vec<FrameTime>, f64)> {
        let gl = &self.ctx.gl;
        self.log.check(gl, "after setup");
        timed_frames(
            self.args.frame_plan(),
            self.started,
            "Frame 1: the draw or dispatch between timer queries, then glFinish",
            || {
                timer.begin();
                draw();
                timer.end();
                // SAFETY: no arguments; the context is current.
                unsafe { gl.finish() };
                Ok(())
            },
            || Ok(timer.result_ms()),
        )
    }

    /// `--dump-shaders`: what the driver made of `program`.
    fn dump_binary(&self, program: glow::Program) -> Result<Vec<ShaderStats>> {
        match &self.args.dump_shaders {
            Some(dir) => Ok(vec![program::dump_binary(
                &self.ctx.gl,
                program,
                self.args.gl_spirv,
                dir,
                "gl-program",
            )?]),
            None => Ok(Vec::new()),
        }
    }
}

/// The frames and the setup time the loop measured, and the last frame's pixels.
type Rendered = (Vec<FrameTime>, f64, Vec<f32>);

/// The fragment path, in the Vulkan twin's steps: the program (GL's pipeline),
/// the scene buffers, the colour target, the timer, the frames, the readback.
fn render_fragment(run: &HeadlessRun, shaders: &Shaders) -> Result<(Rendered, Vec<ShaderStats>)> {
    let (ctx, gl) = (run.ctx, &run.ctx.gl);
    let (width, height) = (run.args.size.width, run.args.size.height);
    let program = if run.args.gl_spirv {
        let fs = shaders.fragment_spirv_for_opengl();
        Program::from_spirv(
            gl,
            &|name| ctx.proc_address(name),
            &shaders.vertex.glsl,
            &fs,
        )?
    } else {
        Program::new(gl, &shaders.vertex.glsl, &shaders.fragment.glsl)?
    };
    let stats = run.dump_binary(program.raw())?;
    let _buffers = SceneBuffers::new(gl, &run.plan.gpu(), run.plan.variant.node_texels)?;
    let target = Target::new(gl, width, height)?;
    let vao = EmptyVertexArray::new(gl)?;
    let timer = Timer::new(gl, &run.info.device)?;
    program.bind(&vao);
    // SAFETY: program, VAO, buffers and FBO are bound and alive.
    let draw = || unsafe { gl.draw_arrays(glow::TRIANGLES, 0, 3) };
    let (frames, setup_ms) = run.frames(&timer, &draw)?;
    let pixels = target.read();
    explain::numbered(11, "Readback", || {
        format!("{width}x{height} RGBA32F, top row first")
    });
    Ok(((frames, setup_ms, pixels), stats))
}

/// The same tracer as a compute shader: compute.rs owns its program and texture.
fn render_compute(
    run: &HeadlessRun,
    shader: &ComputeShader,
) -> Result<(Rendered, Vec<ShaderStats>)> {
    let (ctx, gl) = (run.ctx, &run.ctx.gl);
    let size = &run.args.size;
    // Before the compile, so that a driver without the extension gets a clear refusal.
    let probe = if shader.variant.passes.warp_probe {
        Some(WarpProbe::new(gl)?)
    } else {
        None
    };
    let proc_address = |name: &std::ffi::CStr| ctx.proc_address(name);
    let spirv = run
        .args
        .gl_spirv
        .then_some(&proc_address as &dyn Fn(&std::ffi::CStr) -> *const std::ffi::c_void);
    let compute = Compute::new(gl, shader, spirv, size.width, size.height)?;
    let stats = run.dump_binary(compute.program())?;
    let _buffers = SceneBuffers::new(gl, &run.plan.gpu(), shader.variant.node_texels)?;
    let timer = Timer::new(gl, &run.info.device)?;
    // No barrier between headless frames: the glFinish that ends each one has
    // completed its image stores before the next dispatch. Issued before the
    // timer starts, NVIDIA's driver does a glMemoryBarrier's work with the next
    // dispatch, inside the timed span (0.4-0.6 us of a 300x300 frame:
    // docs/findings/opengl-compute.md#the-small-frames-a-fixed-cost-h200). Vulkan's
    // fence wait orders nothing on the GPU, so Vulkan records its barrier, before
    // its first timestamp: both time the dispatch alone. The laboratory's
    // `timed_barrier` times the barrier in both; `frame_dispatches` above 1
    // dispatches again with no barrier between (each stores the same values),
    // as Vulkan does.
    let (timed_barrier, dispatches) = (run.plan.timed_barrier, run.plan.frame_dispatches);
    let (frames, setup_ms) = run.frames(&timer, &|| {
        if timed_barrier {
            compute.barrier_between_frames();
        }
        for _ in 0..dispatches {
            compute.dispatch();
        }
    })?;
    if let Some(probe) = &probe {
        eprintln!("twinray-gl: {}", probe.summary()?);
    }
    let pixels = compute.read();
    explain::numbered(11, "Readback", || {
        format!("{}x{} RGBA32F, top row first", size.width, size.height)
    });
    Ok(((frames, setup_ms, pixels), stats))
}

/// The variant as the report names it, and how the driver was handed it.
fn variant_label(plan: &RunPlan, gl_spirv: bool) -> String {
    if gl_spirv {
        format!("{} (SPIR-V)", plan.variant.label())
    } else {
        plan.variant.label()
    }
}
