//! The event loop of a window: input to actions, redraws, resizes and
//! minimizes, scene / depth / path switches, screenshots, `--frames` and `--out`.

use crate::cli::RenderPath;
use crate::error::bad_input;
use crate::gpu::layout::GpuFrame;
use crate::limits::MAX_DEPTH;
use crate::plan::{Planner, RunPlan};
use crate::report::FrameTime;
use crate::scene::camera::Orbit;
use crate::shader::build::PathShaders;
use crate::shader::variant::Variant;
use crate::window::keys::{action_for_key, Action};
use crate::window::title::{window_title, TitleClock};
use crate::window::{hooks, Renderer, WindowedRun};
use anyhow::Context;
use std::path::PathBuf;
use std::time::Instant;
use winit::application::ApplicationHandler;
use winit::dpi::{PhysicalPosition, PhysicalSize};
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::window::WindowId;

/// Runs the window until Esc, the close button or `--frames`, then saves `--out`.
/// `plan` is what the renderer was made with; `planner` makes the plans of
/// the scenes the window switches to. The renderer is dropped (every API
/// object destroyed) before this returns.
pub fn run<R: Renderer>(
    program: &'static str,
    event_loop: EventLoop<()>,
    renderer: R,
    planner: &Planner,
    plan: RunPlan,
    started: Instant,
) -> anyhow::Result<WindowedRun> {
    let size = renderer.window().inner_size();
    let now = Instant::now();
    let bvh_ms = plan.bvh_ms;
    let bvh_figures = plan.bvh.as_ref().map(|b| (b.node_count(), b.sah_cost()));
    let args = planner.args();
    let mut session = Session {
        program,
        orbit: Orbit::new(&plan.scene.camera),
        renderer: Some(renderer),
        planner: planner.clone(),
        plan,
        size,
        clock: TitleClock::new(now),
        frames: Vec::new(),
        last_frame_end: now,
        started,
        setup_ms: 0.0,
        drawn: 0,
        dragging: false,
        cursor: None,
        screenshots: 0,
        error: None,
        rays: None,
        rays_stale: args.count_rays,
        resize_test: hooks::resize_test()?.then(ResizeTest::default),
        test_keys: hooks::test_keys()?,
    };
    event_loop.set_control_flow(ControlFlow::Poll);
    event_loop
        .run_app(&mut session)
        .context("running the window's event loop")?;
    // Normally dropped in `finish`; here too on paths where winit stopped the loop.
    session.renderer = None;
    if let Some(e) = session.error.take() {
        return Err(e);
    }
    if let Some(t) = &session.resize_test {
        eprintln!(
            "{program}: test resize: {} window resizes handled, {} minimize/restore cycles",
            t.handled, t.minimizes
        );
    }
    let path = session.path();
    Ok(WindowedRun {
        frames: session.frames,
        path,
        workgroup: session.planner.workgroup(session.plan.bvh.as_ref()),
        scene: session.plan.scene,
        variant: session.plan.variant,
        width: session.size.width,
        height: session.size.height,
        setup_ms: session.setup_ms,
        bvh_ms,
        bvh_figures,
    })
}

struct Session<R: Renderer> {
    program: &'static str,
    /// `None` once the run has finished: dropping it destroys every API object
    /// while the event loop (and so the window system connection) is still alive.
    renderer: Option<R>,
    planner: Planner,
    /// The scene on screen, its BVH, variant (whose entry is the path
    /// drawing) and shaders.
    plan: RunPlan,
    orbit: Orbit,
    size: PhysicalSize<u32>,
    clock: TitleClock,
    frames: Vec<FrameTime>,
    last_frame_end: Instant,
    started: Instant,
    setup_ms: f64,
    drawn: u32,
    dragging: bool,
    cursor: Option<PhysicalPosition<f64>>,
    screenshots: u32,
    error: Option<anyhow::Error>,
    /// `--count-rays`: the current view's rays, for the title's Grays/s, and
    /// whether the view changed since they were counted.
    rays: Option<u64>,
    rays_stale: bool,
    resize_test: Option<ResizeTest>,
    test_keys: Vec<Action>,
}

#[derive(Default)]
struct ResizeTest {
    tick: u32,
    /// A requested size the window has not reached yet, and since which tick.
    pending: Option<(PhysicalSize<u32>, u32)>,
    requested: u32,
    handled: u32,
    /// Ticks left while "minimized".
    minimized_for: u32,
    minimizes: u32,
}

impl<R: Renderer> Session<R> {
    fn path(&self) -> RenderPath {
        self.plan.variant.entry.path()
    }

    fn minimized(&self) -> bool {
        self.size.width == 0 || self.size.height == 0
    }

    fn frame_uniform(&self) -> GpuFrame {
        GpuFrame::new(
            &self.plan.scene,
            &self.orbit.camera(),
            self.size.width.max(1),
            self.size.height.max(1),
        )
    }

    /// Stops the loop; `Err` is kept and returned by `run`.
    fn finish(&mut self, event_loop: &ActiveEventLoop, result: anyhow::Result<()>) {
        if let Err(e) = result {
            self.error.get_or_insert(e);
        } else if let Some(out) = self.planner.args().out.clone() {
            if let Err(e) = self.save(&out) {
                self.error.get_or_insert(e);
            }
        }
        self.renderer = None;
        event_loop.exit();
    }

    fn save(&mut self, path: &std::path::Path) -> anyhow::Result<()> {
        if self.minimized() {
            return Err(bad_input(format!(
                "cannot save '{}': the window is minimized",
                path.display()
            )));
        }
        let frame = self.frame_uniform();
        let (w, h) = (self.size.width, self.size.height);
        let Some(r) = self.renderer.as_mut() else {
            return Ok(());
        };
        let image = r.capture(&frame, w, h).context("capturing the frame")?;
        image.save_png(path)?;
        eprintln!("{}: saved {} ({w}x{h})", self.program, path.display());
        Ok(())
    }

    fn resize(&mut self, size: PhysicalSize<u32>) -> anyhow::Result<()> {
        if size == self.size {
            return Ok(());
        }
        self.size = size;
        self.rays_stale = true;
        if let Some(r) = self.renderer.as_mut() {
            r.resize(size.width, size.height)?;
        }
        if let Some(t) = self.resize_test.as_mut() {
            if size.width > 0 && size.height > 0 {
                t.handled += 1;
            }
            if t.pending.is_some_and(|(want, _)| want == size) {
                t.pending = None;
            }
        }
        Ok(())
    }

    /// Scene switches and depth changes rebuild what they must; the camera
    /// starts over with a new scene but not with a new depth.
    fn act(&mut self, event_loop: &ActiveEventLoop, action: Action) -> anyhow::Result<()> {
        match action {
            Action::Quit => self.finish(event_loop, Ok(())),
            Action::ResetCamera => {
                self.orbit.reset();
                self.rays_stale = true;
            }
            Action::Screenshot => {
                self.screenshots += 1;
                let api = if self.program.ends_with("vk") {
                    "vk"
                } else {
                    "gl"
                };
                let path = PathBuf::from(format!(
                    "twinray-{api}-{}-{}.png",
                    self.plan.scene.name, self.screenshots
                ));
                match self.save(&path) {
                    Ok(()) => {}
                    // A full disk or a minimized window should not end the session.
                    Err(e) => eprintln!("{}: screenshot failed: {e:#}", self.program),
                }
            }
            Action::Scene(name) => {
                let Some(r) = self.renderer.as_ref() else {
                    return Ok(());
                };
                let (w, h) = (self.size.width.max(1), self.size.height.max(1));
                let switched =
                    self.planner
                        .prepare_switch(name, self.path(), &r.storage_limit(), w, h);
                let (plan, dropped) = match switched {
                    Ok(p) => p,
                    Err(e) => {
                        eprintln!("{}: cannot switch to '{name}': {e:#}", self.program);
                        return Ok(());
                    }
                };
                for why in dropped {
                    eprintln!("{}: '{name}' without it: {why}", self.program);
                }
                self.orbit = Orbit::new(&plan.scene.camera);
                self.plan = plan;
                if let Some(r) = self.renderer.as_mut() {
                    r.load_scene(&self.plan.gpu_in_rows(w, h), &self.plan.shaders)?;
                }
                self.restart_title();
            }
            Action::SwitchPath => {
                let path = match self.path() {
                    RenderPath::Fragment => RenderPath::Compute,
                    RenderPath::Compute => RenderPath::Fragment,
                };
                // Decided afresh: some choices are the path's (the workgroup,
                // OpenGL's light order on the compute path).
                self.plan.variant = self.variant_on(path);
                self.rebuild()?;
                self.restart_title();
                eprintln!("{}: path {path}", self.program);
            }
            Action::DepthUp | Action::DepthDown => {
                let d = self.plan.scene.max_depth;
                let d = if action == Action::DepthUp {
                    (d + 1).min(MAX_DEPTH)
                } else {
                    d.saturating_sub(1).max(1)
                };
                self.plan.scene.max_depth = d;
                self.rays_stale = true;
                // The uniform block carries the depth; only a deeper stack or a
                // feature the current shader compiled out needs a new variant.
                let needed = self.variant_on(self.path());
                let rebuilt = !self.plan.variant.covers(&needed);
                if rebuilt {
                    self.plan.variant = needed;
                    self.rebuild()?;
                }
                let how = if rebuilt {
                    "new shader variant"
                } else {
                    "same shader"
                };
                eprintln!(
                    "{}: max depth {d} ({how}: {})",
                    self.program,
                    self.plan.variant.label()
                );
            }
        }
        Ok(())
    }

    /// The variant the planner decides for the current scene on `path`.
    fn variant_on(&self, path: RenderPath) -> Variant {
        let texels = self
            .renderer
            .as_ref()
            .map_or(0, |r| r.storage_limit().texel_buffer);
        let plan = &self.plan;
        self.planner
            .variant(&plan.scene, plan.bvh.as_ref(), path, texels)
    }

    /// The plan's variant changed (path or depth): its shaders and buffers anew.
    fn rebuild(&mut self) -> anyhow::Result<()> {
        let plan = &mut self.plan;
        plan.shaders = PathShaders::build(&plan.variant)?;
        let (w, h) = (self.size.width.max(1), self.size.height.max(1));
        if let Some(r) = self.renderer.as_mut() {
            r.load_scene(&plan.gpu_in_rows(w, h), &plan.shaders)?;
        }
        Ok(())
    }

    /// `--count-rays`: once the view has changed (a switch, a resize, the end
    /// of a drag, a zoom) its rays are counted again, between two frames and
    /// outside both of them: the next frame's wall time starts after the count.
    fn recount_rays(&mut self) -> anyhow::Result<()> {
        if !(self.planner.args().count_rays && self.rays_stale) || self.dragging || self.minimized()
        {
            return Ok(());
        }
        self.rays_stale = false;
        let (width, height) = (self.size.width, self.size.height);
        let plan = &self.plan;
        let mut gpu = plan.gpu_in_rows(width, height);
        gpu.frame = self.frame_uniform();
        let run = plan.counting(&gpu, width, height);
        if let Some(r) = self.renderer.as_mut() {
            self.rays = Some(r.count_rays(&run, &plan.shaders)?.total());
        }
        self.last_frame_end = Instant::now();
        self.clock = TitleClock::new(self.last_frame_end);
        Ok(())
    }

    fn set_title(&self, fps_gpu: Option<(f64, Option<f64>)>) {
        if let Some(r) = &self.renderer {
            let title = window_title(
                &self.plan.scene.name,
                r.api(),
                self.path(),
                fps_gpu,
                self.rays,
            );
            r.window().set_title(&title);
        }
    }

    /// After a switch: the old figures belong to the old scene or path.
    fn restart_title(&mut self) {
        self.rays = None;
        self.rays_stale = true;
        self.clock = TitleClock::new(Instant::now());
        self.set_title(None);
    }

    fn redraw(&mut self, event_loop: &ActiveEventLoop) -> anyhow::Result<()> {
        if !self.minimized() {
            let frame = self.frame_uniform();
            let drawn = match self.renderer.as_mut() {
                Some(r) => r.draw(&frame)?,
                None => return Ok(()),
            };
            if let Some(d) = drawn {
                let now = Instant::now();
                if self.drawn == 0 {
                    self.setup_ms = (now - self.started).as_secs_f64() * 1e3;
                }
                self.frames.push(FrameTime {
                    warmup: false,
                    gpu_ms: d.gpu_ms,
                    wall_ms: (now - self.last_frame_end).as_secs_f64() * 1e3,
                });
                self.last_frame_end = now;
                self.drawn += 1;
                if let Some(figures) = self.clock.frame(now, d.gpu_ms) {
                    self.set_title(Some(figures));
                }
                if let Some(a) = self.test_keys.pop() {
                    self.act(event_loop, a)?;
                }
                if self.planner.args().frames.is_some_and(|n| self.drawn >= n) {
                    self.finish(event_loop, Ok(()));
                    return Ok(());
                }
                self.recount_rays()?;
            }
        }
        self.drive_resize_test()
    }

    /// One step of `TWINRAY_TEST_RESIZE`: a new size each frame, and every 20th
    /// tick a minimize: the window is iconified and unmapped, and the app sees the
    /// zero size that Windows and Wayland report for a minimized window (X11
    /// reports none), until it is restored three ticks later.
    fn drive_resize_test(&mut self) -> anyhow::Result<()> {
        enum Step {
            Wait,
            Minimize,
            Restore,
            Request(PhysicalSize<u32>),
        }
        let Some(t) = self.resize_test.as_mut() else {
            return Ok(());
        };
        t.tick += 1;
        let step = if t.minimized_for > 0 {
            t.minimized_for -= 1;
            if t.minimized_for == 0 {
                Step::Restore
            } else {
                Step::Wait
            }
        } else if t.tick % 20 == 0 {
            t.minimized_for = 3;
            t.minimizes += 1;
            Step::Minimize
        } else if t.pending.is_none_or(|(_, since)| t.tick - since > 10) {
            // A new size once the last one has arrived (or was lost).
            t.requested += 1;
            let k = t.requested;
            let size = PhysicalSize::new(96 + (k * 37) % 160, 64 + (k * 23) % 120);
            t.pending = Some((size, t.tick));
            Step::Request(size)
        } else {
            Step::Wait
        };
        let Some(window) = self.renderer.as_ref().map(R::window) else {
            return Ok(());
        };
        match step {
            Step::Wait => Ok(()),
            Step::Request(size) => {
                let _ = window.request_inner_size(size);
                Ok(())
            }
            Step::Minimize => {
                window.set_minimized(true);
                window.set_visible(false);
                self.resize(PhysicalSize::new(0, 0))
            }
            Step::Restore => {
                window.set_visible(true);
                window.set_minimized(false);
                let real = window.inner_size();
                self.resize(real)
            }
        }
    }
}

impl<R: Renderer> ApplicationHandler for Session<R> {
    fn resumed(&mut self, _event_loop: &ActiveEventLoop) {
        // The window exists before the loop starts (see the apps' window modules).
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        if self.renderer.is_none() {
            return;
        }
        let result = match event {
            WindowEvent::CloseRequested => {
                self.finish(event_loop, Ok(()));
                Ok(())
            }
            WindowEvent::Resized(size) => self.resize(size),
            WindowEvent::RedrawRequested => self.redraw(event_loop),
            // winit invents a press for each key held while the window gains
            // focus (`is_synthetic`): a key pressed as the window was focused
            // would act twice, and C would switch the path and back again.
            WindowEvent::KeyboardInput {
                event,
                is_synthetic: false,
                ..
            } if event.state == ElementState::Pressed => {
                match action_for_key(&event.logical_key) {
                    // Holding +/- repeats; holding a scene key would rebuild it over and over.
                    Some(a @ (Action::DepthUp | Action::DepthDown)) => self.act(event_loop, a),
                    Some(a) if !event.repeat => self.act(event_loop, a),
                    _ => Ok(()),
                }
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                self.dragging = state == ElementState::Pressed;
                self.rays_stale = true;
                Ok(())
            }
            WindowEvent::CursorMoved { position, .. } => {
                if let (true, Some(prev)) = (self.dragging, self.cursor) {
                    self.orbit
                        .drag(position.x - prev.x, position.y - prev.y, self.size.height);
                }
                self.cursor = Some(position);
                Ok(())
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y as f64,
                    // Touchpads scroll in pixels; about 40 make a wheel line.
                    MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
                };
                self.orbit.zoom(lines);
                self.rays_stale = true;
                Ok(())
            }
            _ => Ok(()),
        };
        if let Err(e) = result {
            self.finish(event_loop, Err(e));
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        let Some(r) = &self.renderer else { return };
        // Continuous redraws (uncapped FPS) while there is something to draw; a
        // minimized window waits for events instead of spinning.
        if !self.minimized() || self.resize_test.is_some() {
            event_loop.set_control_flow(ControlFlow::Poll);
            r.window().request_redraw();
        } else {
            event_loop.set_control_flow(ControlFlow::Wait);
        }
    }
}
