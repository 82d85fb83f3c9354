//! The windowed run, OpenGL's side: a glutin-winit window with an OpenGL 4.5
//! core context (EGL on X11, GLX as fallback), swap interval 0 (uncapped) or 1
//! with `--vsync`, and the same program, buffers and draw as headless, driven
//! by the shared event loop (`twinray_common::window`) exactly like the
//! Vulkan window.
//!
//! What Vulkan spells out and OpenGL does not: there is no surface format to
//! choose (the default framebuffer is 8-bit RGBA; GL_FRAMEBUFFER_SRGB stays
//! off, so, like Vulkan's UNORM swapchain, nothing is sRGB-encoded), no
//! swapchain, image views, framebuffers, semaphores or fences (the driver keeps
//! its own frames in flight behind `swap_buffers`), and a resize needs no
//! rebuild beyond `glViewport`.
//!
//! One difference must be handled: the default framebuffer's row 0 is the
//! bottom of the window, and the tracer treats `gl_FragCoord.y` as counting
//! down from the top (right for Vulkan, and for GL's bottom-up readback). So
//! the window's fragment shader redeclares `gl_FragCoord` with
//! `origin_upper_left`, which makes GL count rows like Vulkan does.
//!
//! The compute path (`--path compute`, or `C` at run time) dispatches into its
//! RGBA32F texture and blits that into the default framebuffer, flipping the
//! rows for the same reason (gl/src/compute.rs).

use crate::buffers::SceneBuffers;
use crate::compute::Compute;
use crate::debug::DebugLog;
use crate::program::{EmptyVertexArray, Program};
use crate::target::{self, Target};
use crate::timer::Timer;
use anyhow::{Context as _, Result};
use glow::HasContext;
use glutin::config::{Api, Config, ConfigTemplateBuilder, GlConfig};
use glutin::context::{
    ContextApi, ContextAttributesBuilder, GlProfile, PossiblyCurrentContext, Version,
};
use glutin::display::{GetGlDisplay, GlDisplay};
use glutin::prelude::*;
use glutin::surface::{Surface, SwapInterval, WindowSurface};
use glutin_winit::{ApiPreference, DisplayBuilder, GlWindow as _};
use raw_window_handle::HasWindowHandle;
use std::num::NonZeroU32;
use std::time::Instant;
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
use twinray_common::window::title::window_title;
use twinray_common::window::{self, Drawn, Renderer, WindowedRun};
use winit::window::Window;

/// Timer queries in a ring, so that reading one never waits for the GPU: a
/// result is read only once the driver says it is available.
const TIMERS: usize = 3;

/// Opens the window and runs until it is closed. Returns the run, the device
/// description and the number of GL errors seen.
// Long function: the OpenGL twin of vk's windowed run, kept in the same block order as vk/src/window.rs so the two read side by side.
pub fn run(planner: &Planner, started: Instant) -> Result<(WindowedRun, DeviceInfo, u64)> {
    let args = planner.args();
    let event_loop = window::event_loop()?;
    let attributes = window::window_attributes(args, &args.scene, "OpenGL");
    let template = ConfigTemplateBuilder::new()
        .with_api(Api::OPENGL)
        .with_transparency(false);
    // EGL first: the same library as the headless path. GLX if EGL has no X11 platform.
    let builder = DisplayBuilder::new()
        .with_preference(ApiPreference::PreferEgl)
        .with_window_attributes(Some(attributes));
    let (window, config) = builder
        .build(&event_loop, template, pick_config)
        .map_err(|e| no_device(format!("no OpenGL display configuration for a window: {e}")))?;
    let window = window.context("glutin-winit made no window")?;
    explain::numbered(
        12,
        "Window + display + config (glutin-winit DisplayBuilder)",
        || {
            let s = window.inner_size();
            format!(
                "{}x{} window; {}; config: RGBA {}-bit alpha {}, sRGB-capable {}, hardware {}",
                s.width,
                s.height,
                config.display().version_string(),
                config
                    .color_buffer_type()
                    .map_or("?".into(), |c| format!("{c:?}")),
                config.alpha_size(),
                config.srgb_capable(),
                config.hardware_accelerated()
            )
        },
    );

    let handle = window
        .window_handle()
        .context("getting the window handle")?
        .as_raw();
    let context_attributes = ContextAttributesBuilder::new()
        .with_debug(args.validate)
        .with_profile(GlProfile::Core)
        .with_context_api(ContextApi::OpenGl(Some(Version::new(4, 5))))
        .build(Some(handle));
    let display = config.display();
    // SAFETY: the config belongs to this display; the window outlives the context.
    let context = unsafe { display.create_context(&config, &context_attributes) }
        .map_err(|e| no_device(format!("no OpenGL 4.5 core context for the window: {e}")))?;
    let surface_attributes = window
        .build_surface_attributes(Default::default())
        .context("describing the window surface")?;
    // SAFETY: the window outlives the surface (declared before it).
    let surface = unsafe { display.create_window_surface(&config, &surface_attributes) }
        .context("creating the window surface")?;
    let context = context
        .make_current(&surface)
        .context("making the OpenGL context current")?;
    explain::numbered(4, "Context + window surface, made current", || {
        format!(
            "OpenGL 4.5 core{}; one surface, double-buffered by the driver",
            if args.validate { ", debug" } else { "" }
        )
    });
    let interval = if args.vsync {
        SwapInterval::Wait(NonZeroU32::MIN)
    } else {
        SwapInterval::DontWait
    };
    if let Err(e) = surface.set_swap_interval(&context, interval) {
        // Some X servers refuse interval 0; the window still works, capped.
        eprintln!("twinray-gl: note: could not set swap interval {interval:?}: {e}");
    }
    explain::numbered(13, "Swap interval", || {
        let how = if args.vsync {
            "1 (--vsync: wait for the display)"
        } else {
            "0 (uncapped)"
        };
        format!("{how}; the driver owns the back buffers and how many frames are in flight")
    });

    // SAFETY: the context is current on this thread, which glow requires.
    let mut gl =
        unsafe { glow::Context::from_loader_function_cstr(|s| display.get_proc_address(s)) };
    let info = crate::context::device_info(&gl);
    explain::numbered(4, "glow function table loaded (eglGetProcAddress)", || {
        format!("{} / {}", info.device, info.driver)
    });
    let log = DebugLog::install(&mut gl);
    let gl = &gl;

    let size = window.inner_size();
    // The plan comes after the context, whose storage limit it is checked against.
    let plan = planner.prepare(
        &crate::context::storage_limit(gl),
        size.width.max(1),
        size.height.max(1),
    )?;
    window.set_title(&window_title(
        &plan.scene.name,
        "OpenGL",
        args.path,
        None,
        None,
    ));
    // Declaration order is creation order, so the struct's fields (newest
    // first) and these locals go in reverse on every path.
    let drawing = path_program(gl, &plan.shaders, (size.width, size.height))?;
    let buffers = SceneBuffers::new(
        gl,
        &plan.gpu_in_rows(plan.size.0, plan.size.1),
        plan.shaders.reads_node_texels(),
    )?;
    let vao = EmptyVertexArray::new(gl)?;
    let timers = (0..TIMERS)
        .map(|_| Timer::new(gl, &info.device))
        .collect::<Result<Vec<_>>>()?;
    // SAFETY: plain state on the current context: no sRGB encoding on store (see above).
    unsafe {
        gl.disable(glow::FRAMEBUFFER_SRGB);
        gl.viewport(0, 0, size.width as i32, size.height as i32);
    }
    log.check(gl, "after window setup");
    let renderer = GlWindow {
        timers: timers.into_iter().map(|t| (t, false)).collect(),
        next_timer: 0,
        vao,
        buffers,
        drawing,
        size: (size.width, size.height),
        log: log.clone(),
        gl,
        surface: &surface,
        context: &context,
        window: &window,
    };
    explain::numbered(17, "Frame loop starts", || {
        "per frame: glBufferSubData (camera), glDrawArrays (fragment) or glDispatchCompute + glMemoryBarrier\n\
         + glBlitFramebuffer (compute), SwapBuffers: the driver queues, syncs and presents; C switches the path".into()
    });
    let run = window::session::run("twinray-gl", event_loop, renderer, planner, plan, started)?;
    Ok((run, info, log.errors()))
}

/// glutin returns an error rather than an empty list, so there is always one.
/// Prefer a config without alpha and without sRGB (nothing to encode, nothing
/// to blend with the desktop).
fn pick_config(configs: Box<dyn Iterator<Item = Config> + '_>) -> Config {
    configs
        .max_by_key(|c| {
            (
                c.alpha_size() == 0,
                !c.srgb_capable(),
                c.hardware_accelerated(),
            )
        })
        .expect("glutin reports BadConfig instead of calling the picker with no configs")
}

/// Redeclares `gl_FragCoord` with an upper-left origin (core since GLSL 1.50),
/// after naga's `#version`/`#extension` lines, where declarations may start.
pub fn upper_left_origin(glsl: &str) -> String {
    let mut out = String::with_capacity(glsl.len() + 64);
    let mut inserted = false;
    for line in glsl.lines() {
        if !inserted && !line.trim_start().starts_with('#') {
            out.push_str("layout(origin_upper_left) in vec4 gl_FragCoord;\n");
            inserted = true;
        }
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// The current path's program: the fullscreen pair, or the compute program
/// with its texture and the framebuffer its blit reads.
enum PathProgram<'gl> {
    Fragment(Program<'gl>),
    Compute(Compute<'gl>),
}

/// The program for `shaders`' path; the compute path's texture has `size`.
fn path_program<'gl>(
    gl: &'gl glow::Context,
    shaders: &PathShaders,
    size: (u32, u32),
) -> Result<PathProgram<'gl>> {
    Ok(match shaders {
        PathShaders::Fragment(s) => PathProgram::Fragment(Program::new(
            gl,
            &s.vertex.glsl,
            &upper_left_origin(&s.fragment.glsl),
        )?),
        PathShaders::Compute(s) => {
            let mut c = Compute::new(gl, s, None, size.0.max(1), size.1.max(1))?;
            c.attach()?;
            explain::numbered(22,
                "Compute path in the window: program + RGBA32F texture (glBindImageTexture) + read FBO",
                || {
                    format!(
                        "{}x{}, workgroup {}; per frame glDispatchCompute, glMemoryBarrier(FRAMEBUFFER_BARRIER_BIT),\n\
                         glBlitFramebuffer into the default framebuffer (rows flipped, NEAREST)",
                        c.width, c.height, s.workgroup
                    )
                },
            );
            PathProgram::Compute(c)
        }
    })
}

struct GlWindow<'gl> {
    /// Each with "has an unread result".
    timers: Vec<(Timer<'gl>, bool)>,
    next_timer: usize,
    vao: EmptyVertexArray<'gl>,
    buffers: SceneBuffers<'gl>,
    drawing: PathProgram<'gl>,
    size: (u32, u32),
    log: DebugLog,
    gl: &'gl glow::Context,
    surface: &'gl Surface<WindowSurface>,
    context: &'gl PossiblyCurrentContext,
    window: &'gl Window,
}

impl Renderer for GlWindow<'_> {
    /// The headless counting frame; it binds buffers, a program and a
    /// framebuffer of its own, so the window's are made and bound again after it.
    fn count_rays(&mut self, run: &CountingRun, shaders: &PathShaders) -> Result<RayKinds> {
        let kinds = crate::rays::count_rays(self.gl, run)?;
        self.load_scene(run.gpu, shaders)?;
        // SAFETY: plain state on the current context.
        unsafe {
            self.gl
                .viewport(0, 0, self.size.0 as i32, self.size.1 as i32)
        };
        Ok(kinds)
    }

    fn storage_limit(&self) -> StorageLimit {
        crate::context::storage_limit(self.gl)
    }

    fn api(&self) -> &'static str {
        "OpenGL"
    }

    fn window(&self) -> &Window {
        self.window
    }

    fn resize(&mut self, width: u32, height: u32) -> Result<()> {
        self.size = (width, height);
        let (Some(w), Some(h)) = (NonZeroU32::new(width), NonZeroU32::new(height)) else {
            return Ok(());
        };
        // EGL and GLX resize the surface with the window; the call is for platforms that don't.
        self.surface.resize(self.context, w, h);
        // SAFETY: plain state on the current context.
        unsafe { self.gl.viewport(0, 0, width as i32, height as i32) };
        if let PathProgram::Compute(c) = &mut self.drawing {
            c.resize(width, height)?;
        }
        self.log.check(self.gl, "after a resize");
        Ok(())
    }

    fn draw(&mut self, frame: &GpuFrame) -> Result<Option<Drawn>> {
        if self.size.0 == 0 || self.size.1 == 0 {
            return Ok(None);
        }
        self.buffers.update_frame(bytemuck::bytes_of(frame));
        let (timer, pending) = &mut self.timers[self.next_timer];
        // The ring's oldest query: read it if the GPU has finished it, else skip.
        let gpu_ms = if *pending {
            timer.try_result_ms()
        } else {
            None
        };
        timer.begin();
        // Bound every frame: a capture or a path switch may have bound others.
        match &self.drawing {
            PathProgram::Fragment(program) => {
                program.bind(&self.vao);
                // SAFETY: program, VAO and buffers are bound and alive.
                unsafe { self.gl.draw_arrays(glow::TRIANGLES, 0, 3) };
            }
            PathProgram::Compute(c) => {
                c.bind();
                c.barrier_between_frames();
                c.dispatch();
                c.blit_to_window();
            }
        }
        timer.end();
        *pending = true;
        self.next_timer = (self.next_timer + 1) % TIMERS;
        self.surface
            .swap_buffers(self.context)
            .context("swapping buffers")?;
        self.log.check(self.gl, "after a frame");
        Ok(Some(Drawn { gpu_ms }))
    }

    fn load_scene(&mut self, scene: &GpuScene, shaders: &PathShaders) -> Result<()> {
        let gl = self.gl;
        self.drawing = path_program(gl, shaders, self.size)?;
        self.buffers = SceneBuffers::new(gl, scene, shaders.reads_node_texels())?;
        self.log.check(gl, "after a scene or path switch");
        Ok(())
    }

    /// The headless path at the window's size, with the current path. Fragment:
    /// an RGBA32F FBO and glReadPixels; this program counts rows from the top
    /// (upper-left origin) and the readback returns the bottom row first, hence
    /// the flip. Compute: the window's own texture (the window's size) and
    /// glGetTexImage, top row first, as headless.
    fn capture(&mut self, frame: &GpuFrame, width: u32, height: u32) -> Result<FloatImage> {
        let gl = self.gl;
        target::check_size(gl, width, height)?;
        self.buffers.update_frame(bytemuck::bytes_of(frame));
        let program = match &mut self.drawing {
            PathProgram::Fragment(program) => program,
            PathProgram::Compute(c) => {
                if (c.width, c.height) != (width, height) {
                    c.resize(width, height)?;
                }
                c.bind();
                c.barrier_between_frames();
                c.dispatch();
                let pixels = c.read();
                self.log.check(gl, "after a capture");
                return Ok(FloatImage::from_rgba(width, height, &pixels));
            }
        };
        program.bind(&self.vao);
        let pixels = {
            let fbo = Target::new(gl, width, height)?;
            // SAFETY: the FBO is bound for drawing; program and buffers are bound.
            unsafe { gl.draw_arrays(glow::TRIANGLES, 0, 3) };
            fbo.read()
        }; // the FBO is deleted here and the window's framebuffer bound again
           // SAFETY: plain state on the current context.
        unsafe { gl.viewport(0, 0, self.size.0 as i32, self.size.1 as i32) };
        self.log.check(gl, "after a capture");
        Ok(FloatImage::from_rgba(width, height, &pixels).flip_rows())
    }
}

impl Drop for GlWindow<'_> {
    fn drop(&mut self) {
        // Orderly shutdown: let the GPU finish before the objects are deleted
        // (the fields drop after this, then the context and window in `run`).
        // SAFETY: no arguments; the context is current.
        unsafe { self.gl.finish() };
    }
}
