//! The windowed apps' shared behaviour: the winit event loop, what every key
//! and mouse gesture does, the window title, the camera, scene, depth and
//! path (fragment / compute) switches, screenshots and `--frames`. Both apps hand this module a
//! [`Renderer`] (their API-specific half) and nothing else, so the two windows
//! cannot behave differently: only the drawing differs.
//!
//! Test hooks (not user options; the end-to-end tests use them under Xvfb):
//! `TWINRAY_TEST_RESIZE=1` makes the app resize its own window on every frame
//! and minimize/restore it now and then; `TWINRAY_TEST_KEYS=2,p,+,-,r,1` presses
//! those keys' actions, one per frame.

use crate::camera::Orbit;
use crate::cli::{RenderArgs, RenderPath, Workgroup};
use crate::error::{bad_input, no_device};
use crate::gpu::{GpuFrame, GpuScene};
use crate::image_io::FloatImage;
use crate::report::FrameTime;
use crate::scene::{Scene, MAX_DEPTH_LIMIT};
use crate::shader::{self, ComputeShader, Shaders, Variant};
use anyhow::Context;
use std::path::PathBuf;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::dpi::{PhysicalPosition, PhysicalSize};
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowAttributes, WindowId};

/// What an API's windowed app must provide. Sizes are physical pixels.
pub trait Renderer {
    /// "Vulkan" or "OpenGL", for the title.
    fn api(&self) -> &'static str;
    fn window(&self) -> &Window;
    /// The window's drawable area changed; 0 in either dimension means minimized.
    fn resize(&mut self, width: u32, height: u32) -> anyhow::Result<()>;
    /// Draws and presents one frame with this uniform block. `Ok(None)` when no
    /// frame could be drawn (e.g. a swapchain that must first be rebuilt);
    /// otherwise the GPU time of the most recent frame whose timing is known.
    fn draw(&mut self, frame: &GpuFrame) -> anyhow::Result<Option<Drawn>>;
    /// A new scene, shader variant or path: rebuild buffers, descriptors and
    /// program (or pipeline) for the path `shaders` belongs to, and draw with
    /// that path from now on.
    fn load_scene(&mut self, scene: &GpuScene, shaders: &PathShaders) -> anyhow::Result<()>;
    /// Renders `frame` at `width`×`height` (the window's size) with the current
    /// path into the RGBA32F image the headless path uses and reads it back, top
    /// row first, so that a screenshot is quantised by `image_io` exactly like
    /// `--headless --out`.
    fn capture(&mut self, frame: &GpuFrame, width: u32, height: u32) -> anyhow::Result<FloatImage>;
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drawn {
    pub gpu_ms: Option<f64>,
}

/// The shaders of the path a window draws with: the fullscreen pair, or the
/// compute entry point with its workgroup.
#[derive(Clone)]
pub enum PathShaders {
    Fragment(Shaders),
    Compute(ComputeShader),
}

impl PathShaders {
    pub fn build(
        variant: &Variant,
        path: RenderPath,
        workgroup: Workgroup,
    ) -> anyhow::Result<PathShaders> {
        Ok(match path {
            RenderPath::Fragment => PathShaders::Fragment(shader::build(variant)?),
            RenderPath::Compute => PathShaders::Compute(shader::build_compute(variant, workgroup)?),
        })
    }

    pub fn path(&self) -> RenderPath {
        match self {
            PathShaders::Fragment(_) => RenderPath::Fragment,
            PathShaders::Compute(_) => RenderPath::Compute,
        }
    }
}

/// What a key or gesture asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    Quit,
    Scene(&'static str),
    ResetCamera,
    Screenshot,
    DepthUp,
    DepthDown,
    /// Fragment ↔ compute.
    SwitchPath,
}

/// The keys of the README's Controls section. `=` counts as `+` (same key
/// without shift on US layouts), `_` as `-`.
pub fn action_for_key(key: &Key) -> Option<Action> {
    match key {
        Key::Named(NamedKey::Escape) => Some(Action::Quit),
        Key::Character(c) => action_for_char(c.as_str()),
        _ => None,
    }
}

fn action_for_char(c: &str) -> Option<Action> {
    Some(match c {
        "1" => Action::Scene("teapot"),
        "2" => Action::Scene("box"),
        "3" => Action::Scene("spherelist"),
        "r" | "R" => Action::ResetCamera,
        "p" | "P" => Action::Screenshot,
        "+" | "=" => Action::DepthUp,
        "-" | "_" => Action::DepthDown,
        "c" | "C" => Action::SwitchPath,
        _ => return None,
    })
}

/// The window title, identical in both apps:
/// `twinray — box — Vulkan compute — 61.3 FPS — 12.41 ms` (`n/a ms` where the
/// GPU time is unknown, e.g. OpenGL on llvmpipe; `— starting` until the first
/// figures, and after a switch until new ones).
pub fn window_title(
    scene: &str,
    api: &str,
    path: RenderPath,
    fps_gpu: Option<(f64, Option<f64>)>,
) -> String {
    let head = format!("twinray — {scene} — {api} {path}");
    match fps_gpu {
        None => format!("{head} — starting"),
        Some((fps, gpu_ms)) => {
            let gpu = gpu_ms.map_or_else(|| "n/a".to_string(), |ms| format!("{ms:.2}"));
            format!("{head} — {fps:.1} FPS — {gpu} ms")
        }
    }
}

/// Averages frames over half-second windows for the title.
#[derive(Debug)]
pub struct TitleClock {
    since: Instant,
    frames: u32,
    gpu_sum: f64,
    gpu_n: u32,
}

impl TitleClock {
    pub const PERIOD: Duration = Duration::from_millis(500);

    pub fn new(now: Instant) -> TitleClock {
        TitleClock {
            since: now,
            frames: 0,
            gpu_sum: 0.0,
            gpu_n: 0,
        }
    }

    /// Counts a frame; every `PERIOD` returns (FPS, mean GPU ms) and starts over.
    pub fn frame(&mut self, now: Instant, gpu_ms: Option<f64>) -> Option<(f64, Option<f64>)> {
        self.frames += 1;
        if let Some(g) = gpu_ms {
            self.gpu_sum += g;
            self.gpu_n += 1;
        }
        let elapsed = now - self.since;
        if elapsed < Self::PERIOD {
            return None;
        }
        let fps = self.frames as f64 / elapsed.as_secs_f64();
        let gpu = (self.gpu_n > 0).then(|| self.gpu_sum / self.gpu_n as f64);
        *self = TitleClock::new(now);
        Some((fps, gpu))
    }
}

/// The event loop, or a clear exit-3 error where there is no display.
pub fn event_loop() -> anyhow::Result<EventLoop<()>> {
    EventLoop::new().map_err(|e| {
        no_device(format!(
            "cannot open a window ({}): no X display (is DISPLAY set?); run under xvfb-run, or use --headless",
            crate::error::without_source_location(&e.to_string())
        ))
    })
}

/// The window both apps open: `--size` as the drawable size, a fixed title until
/// the first FPS figure.
pub fn window_attributes(args: &RenderArgs, scene: &str, api: &str) -> WindowAttributes {
    Window::default_attributes()
        .with_title(window_title(scene, api, args.path, None))
        .with_inner_size(PhysicalSize::new(args.size.width, args.size.height))
}

/// The scene and variant a windowed run starts with (the same choice as headless).
pub fn variant_for(args: &RenderArgs, scene: &Scene) -> Variant {
    Variant::chosen(scene, args)
}

/// The shaders a window starts with: `--path`'s, for the scene's variant.
pub fn first_shaders(args: &RenderArgs, scene: &Scene) -> anyhow::Result<PathShaders> {
    PathShaders::build(
        &variant_for(args, scene),
        args.path,
        args.compute_workgroup()?,
    )
}

/// What the run did, for `--json`.
pub struct WindowedRun {
    pub frames: Vec<FrameTime>,
    pub scene: Scene,
    pub variant: Variant,
    /// The path drawing at exit (`C` may have switched it).
    pub path: RenderPath,
    pub workgroup: Workgroup,
    pub width: u32,
    pub height: u32,
    /// Milliseconds from `started` to the end of the first frame.
    pub setup_ms: f64,
}

impl WindowedRun {
    /// The `--json` report of a window: the headless shape, with wall time
    /// frame to frame and no NaN count (nothing is read back).
    pub fn report(
        self,
        api: &str,
        device: crate::report::DeviceInfo,
        validation_messages: u64,
    ) -> crate::report::RunReport {
        crate::report::RunReport::builder(api, device, self.scene.stats(), self.variant.label())
            .size(self.width, self.height)
            .path(self.path, self.workgroup)
            .frames(self.frames, self.setup_ms)
            .validation_messages(validation_messages)
            .build()
    }
}

/// Runs the window until Esc, the close button or `--frames`, then saves `--out`.
/// The renderer is dropped (every API object destroyed) before this returns.
pub fn run<R: Renderer>(
    program: &'static str,
    event_loop: EventLoop<()>,
    renderer: R,
    args: &RenderArgs,
    scene: Scene,
    variant: Variant,
    started: Instant,
) -> anyhow::Result<WindowedRun> {
    let size = renderer.window().inner_size();
    let now = Instant::now();
    let workgroup = args.compute_workgroup()?;
    let mut session = Session {
        program,
        orbit: Orbit::new(&scene.camera),
        renderer: Some(renderer),
        args: args.clone(),
        scene,
        variant,
        path: args.path,
        workgroup,
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
        resize_test: std::env::var("TWINRAY_TEST_RESIZE")
            .is_ok_and(|v| v == "1")
            .then(ResizeTest::default),
        test_keys: test_keys()?,
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
    Ok(WindowedRun {
        frames: session.frames,
        scene: session.scene,
        variant: session.variant,
        path: session.path,
        workgroup: session.workgroup,
        width: session.size.width,
        height: session.size.height,
        setup_ms: session.setup_ms,
    })
}

fn test_keys() -> anyhow::Result<Vec<Action>> {
    let Ok(list) = std::env::var("TWINRAY_TEST_KEYS") else {
        return Ok(Vec::new());
    };
    let mut actions: Vec<Action> = list
        .split(',')
        .filter(|k| !k.trim().is_empty())
        .map(|k| match k.trim() {
            "esc" => Ok(Action::Quit),
            c => action_for_char(c)
                .ok_or_else(|| bad_input(format!("TWINRAY_TEST_KEYS: '{c}' is no key of the app"))),
        })
        .collect::<anyhow::Result<_>>()?;
    actions.reverse(); // popped from the end
    Ok(actions)
}

struct Session<R: Renderer> {
    program: &'static str,
    /// `None` once the run has finished: dropping it destroys every API object
    /// while the event loop (and so the window system connection) is still alive.
    renderer: Option<R>,
    args: RenderArgs,
    scene: Scene,
    variant: Variant,
    path: RenderPath,
    /// The compute path's, also kept while the fragment path draws.
    workgroup: Workgroup,
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
    fn minimized(&self) -> bool {
        self.size.width == 0 || self.size.height == 0
    }

    fn frame_uniform(&self) -> GpuFrame {
        GpuFrame::new(
            &self.scene,
            &self.orbit.camera(),
            self.size.width.max(1),
            self.size.height.max(1),
        )
    }

    /// Stops the loop; `Err` is kept and returned by `run`.
    fn finish(&mut self, event_loop: &ActiveEventLoop, result: anyhow::Result<()>) {
        if let Err(e) = result {
            self.error.get_or_insert(e);
        } else if let Some(out) = self.args.out.clone() {
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
            Action::ResetCamera => self.orbit.reset(),
            Action::Screenshot => {
                self.screenshots += 1;
                let api = if self.program.ends_with("vk") {
                    "vk"
                } else {
                    "gl"
                };
                let path = PathBuf::from(format!(
                    "twinray-{api}-{}-{}.png",
                    self.scene.name, self.screenshots
                ));
                match self.save(&path) {
                    Ok(()) => {}
                    // A full disk or a minimized window should not end the session.
                    Err(e) => eprintln!("{}: screenshot failed: {e:#}", self.program),
                }
            }
            Action::Scene(name) => {
                let scene = match self.args.overrides().and_then(|o| Scene::load(name, &o)) {
                    Ok(s) => s,
                    Err(e) => {
                        eprintln!("{}: cannot switch to '{name}': {e:#}", self.program);
                        return Ok(());
                    }
                };
                self.orbit = Orbit::new(&scene.camera);
                self.variant = variant_for(&self.args, &scene);
                self.scene = scene;
                self.rebuild()?;
                self.restart_title();
            }
            Action::SwitchPath => {
                self.path = match self.path {
                    RenderPath::Fragment => RenderPath::Compute,
                    RenderPath::Compute => RenderPath::Fragment,
                };
                self.rebuild()?;
                self.restart_title();
                eprintln!("{}: path {}", self.program, self.path);
            }
            Action::DepthUp | Action::DepthDown => {
                let d = self.scene.max_depth;
                let d = if action == Action::DepthUp {
                    (d + 1).min(MAX_DEPTH_LIMIT)
                } else {
                    d.saturating_sub(1).max(1)
                };
                self.scene.max_depth = d;
                // The uniform block carries the depth; only a deeper stack or a
                // feature the current shader compiled out needs a new variant.
                let needed = variant_for(&self.args, &self.scene);
                let rebuilt = !self.variant.covers(&needed);
                if rebuilt {
                    self.variant = needed;
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
                    self.variant.label()
                );
            }
        }
        Ok(())
    }

    fn rebuild(&mut self) -> anyhow::Result<()> {
        let shaders = PathShaders::build(&self.variant, self.path, self.workgroup)?;
        let gpu = GpuScene::new(&self.scene, self.size.width.max(1), self.size.height.max(1));
        if let Some(r) = self.renderer.as_mut() {
            r.load_scene(&gpu, &shaders)?;
        }
        Ok(())
    }

    fn set_title(&self, fps_gpu: Option<(f64, Option<f64>)>) {
        if let Some(r) = &self.renderer {
            let title = window_title(&self.scene.name, r.api(), self.path, fps_gpu);
            r.window().set_title(&title);
        }
    }

    /// After a switch: the old figures belong to the old scene or path.
    fn restart_title(&mut self) {
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
                if self.args.frames.is_some_and(|n| self.drawn >= n) {
                    self.finish(event_loop, Ok(()));
                    return Ok(());
                }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_map_to_the_documented_actions() {
        let ch = |s: &str| action_for_key(&Key::Character(s.into()));
        assert_eq!(
            action_for_key(&Key::Named(NamedKey::Escape)),
            Some(Action::Quit)
        );
        assert_eq!(ch("1"), Some(Action::Scene("teapot")));
        assert_eq!(ch("2"), Some(Action::Scene("box")));
        assert_eq!(ch("3"), Some(Action::Scene("spherelist")));
        assert_eq!(ch("R"), Some(Action::ResetCamera));
        assert_eq!(ch("p"), Some(Action::Screenshot));
        assert_eq!(ch("+"), Some(Action::DepthUp));
        assert_eq!(ch("="), Some(Action::DepthUp));
        assert_eq!(ch("-"), Some(Action::DepthDown));
        assert_eq!(ch("c"), Some(Action::SwitchPath));
        assert_eq!(ch("C"), Some(Action::SwitchPath));
        assert_eq!(ch("x"), None);
        assert_eq!(action_for_key(&Key::Named(NamedKey::Enter)), None);
    }

    #[test]
    fn title_format_is_fixed() {
        assert_eq!(
            window_title(
                "box",
                "Vulkan",
                RenderPath::Compute,
                Some((61.26, Some(12.414)))
            ),
            "twinray — box — Vulkan compute — 61.3 FPS — 12.41 ms"
        );
        assert_eq!(
            window_title("teapot", "OpenGL", RenderPath::Fragment, Some((5.0, None))),
            "twinray — teapot — OpenGL fragment — 5.0 FPS — n/a ms"
        );
        assert_eq!(
            window_title("box", "OpenGL", RenderPath::Compute, None),
            "twinray — box — OpenGL compute — starting"
        );
    }

    #[test]
    fn title_clock_reports_twice_a_second() {
        let t0 = Instant::now();
        let mut c = TitleClock::new(t0);
        assert_eq!(c.frame(t0 + Duration::from_millis(100), Some(2.0)), None);
        assert_eq!(c.frame(t0 + Duration::from_millis(200), None), None);
        let (fps, gpu) = c.frame(t0 + Duration::from_millis(500), Some(4.0)).unwrap();
        assert!((fps - 6.0).abs() < 1e-9, "3 frames in 0.5 s: {fps}");
        assert_eq!(gpu, Some(3.0));
        assert_eq!(
            c.frame(t0 + Duration::from_millis(600), None),
            None,
            "starts over"
        );
    }

    #[test]
    fn depth_changes_rebuild_only_when_the_variant_cannot_cover_them() {
        let scene = Scene::load("box", &[]).unwrap();
        let deep = Variant::for_scene(&scene);
        let mut shallow_scene = scene.clone();
        shallow_scene.max_depth = 2;
        let shallow = Variant::for_scene(&shallow_scene);
        assert!(
            deep.covers(&shallow),
            "a deeper stack draws shallower scenes"
        );
        assert!(!shallow.covers(&deep), "a stack too small for the depth");
        shallow_scene.max_depth = 1;
        let flat = Variant::for_scene(&shallow_scene);
        assert!(
            !flat.covers(&shallow),
            "depth 1 compiles mirror and glass out"
        );
        let mut generic = crate::cli::RenderArgs::headless("box", scene_size());
        generic.generic = true;
        assert!(Variant::chosen(&scene, &generic).covers(&deep));
        let teapot = Scene::load("teapot", &[]).unwrap();
        assert!(
            !Variant::chosen(&teapot, &generic).covers(&deep),
            "the counts are baked in: another scene's shader cannot draw this one"
        );
    }

    fn scene_size() -> crate::cli::Size {
        crate::cli::Size {
            width: 8,
            height: 8,
        }
    }
}
