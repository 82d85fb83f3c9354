//! Running the two apps as child processes (never in-process, so each API gets
//! a clean process, as in the study), and the CPU reference in-process.

use anyhow::Context;
use std::path::PathBuf;
use std::process::Command;
use std::time::Instant;
use twinray_common::cli::RenderArgs;
use twinray_common::error::{bad_input, Failure, FailureKind};
use twinray_common::report::{DeviceInfo, FrameTime, RunReport};
use twinray_common::scene::accel::Accel;

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Api {
    Vulkan,
    Opengl,
    /// OpenGL running naga's SPIR-V (GL_ARB_gl_spirv): the very binary Vulkan runs.
    #[value(name = "opengl-spirv")]
    OpenglSpirv,
    Reference,
}

impl Api {
    pub fn binary(self) -> Option<&'static str> {
        match self {
            Api::Vulkan => Some("twinray-vk"),
            Api::Opengl | Api::OpenglSpirv => Some("twinray-gl"),
            Api::Reference => None,
        }
    }
}

/// Where the app binaries live: `TWINRAY_BIN_DIR`, else next to this executable.
pub fn app_path(name: &str) -> anyhow::Result<PathBuf> {
    let dir = match std::env::var_os("TWINRAY_BIN_DIR") {
        Some(d) => PathBuf::from(d),
        None => std::env::current_exe()?
            .parent()
            .map(PathBuf::from)
            .unwrap_or_default(),
    };
    let path = dir.join(name);
    if !path.exists() {
        return Err(anyhow::anyhow!(
            "{name} was not found in '{}'; build the whole workspace (cargo build --release --workspace) or set TWINRAY_BIN_DIR",
            dir.display()
        ));
    }
    Ok(path)
}

/// The app's command line for `args` (always headless: the orchestrator never opens windows).
pub fn app_args(args: &RenderArgs) -> Vec<String> {
    let mut v = vec![
        "--headless".to_string(),
        "--scene".into(),
        args.scene.clone(),
        "--size".into(),
        args.size.to_string(),
    ];
    if let Some(f) = args.frames {
        v.extend(["--frames".into(), f.to_string()]);
    }
    if let Some(o) = &args.out {
        v.extend(["--out".into(), o.display().to_string()]);
    }
    for s in &args.set {
        v.extend(["--set".into(), s.clone()]);
    }
    if args.json {
        v.push("--json".into());
    }
    if args.validate {
        v.push("--validate".into());
    }
    if args.generic {
        v.push("--generic".into());
    }
    if args.specialize {
        v.push("--specialize".into());
    }
    if args.gl_spirv {
        v.push("--gl-spirv".into());
    }
    v.extend(["--accel".into(), args.accel.name().into()]);
    v.extend(["--path".into(), args.path.to_string()]);
    if let Some(wg) = args.workgroup {
        v.extend(["--workgroup".into(), wg.to_string()]);
    }
    for e in &args.experiment {
        v.extend(["--experiment".into(), e.name().into()]);
    }
    if let Some(dir) = &args.dump_shaders {
        v.extend(["--dump-shaders".into(), dir.display().to_string()]);
    }
    v
}

/// Runs an app, passing its output through, and exits with its exit code on failure.
pub fn render(api: Api, args: &RenderArgs) -> anyhow::Result<()> {
    match api.binary() {
        Some(bin) => {
            let mut args = args.clone();
            args.gl_spirv |= api == Api::OpenglSpirv;
            let status = Command::new(app_path(bin)?)
                .args(app_args(&args))
                .status()
                .with_context(|| format!("starting {bin}"))?;
            if !status.success() {
                // The app already printed its one-line error; keep its exit code.
                std::process::exit(status.code().unwrap_or(1));
            }
            Ok(())
        }
        None => render_reference(args),
    }
}

/// Runs an app with `--json` and returns its report; a failure carries the app's own message and exit code.
pub fn run_json(api: Api, args: &RenderArgs) -> anyhow::Result<RunReport> {
    let bin = api.binary().expect("an app");
    let mut args = args.clone();
    args.json = true;
    args.gl_spirv |= api == Api::OpenglSpirv;
    let out = Command::new(app_path(bin)?)
        .args(app_args(&args))
        .output()
        .with_context(|| format!("starting {bin}"))?;
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        let line = stderr
            .lines()
            .rev()
            .find(|l| !l.trim().is_empty())
            .unwrap_or("no message")
            .to_string();
        let kind = match out.status.code() {
            Some(2) => Some(FailureKind::BadInput),
            Some(3) => Some(FailureKind::NoDevice),
            _ => None,
        };
        return Err(match kind {
            Some(kind) => Failure {
                kind,
                message: line,
            }
            .into(),
            None => anyhow::anyhow!("{bin} failed ({}): {line}", out.status),
        });
    }
    let stdout = String::from_utf8_lossy(&out.stdout);
    let json = stdout
        .lines()
        .rev()
        .find(|l| l.starts_with('{'))
        .unwrap_or("");
    serde_json::from_str(json).with_context(|| format!("reading {bin}'s JSON report"))
}

/// The f64 CPU reference, in-process. With `--json` it prints a report in the
/// apps' format (api "reference", CPU time as wall time).
pub fn render_reference(args: &RenderArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    if !args.json && args.out.is_none() {
        return Err(bad_input(
            "render --api reference needs --out FILE.png or --json",
        ));
    }
    // The reference takes the apps' options; one that cannot apply is refused as they refuse it.
    args.compute_workgroup()?;
    let scene = args.load_scene()?;
    let (w, h) = (args.size.width, args.size.height);
    let t = Instant::now();
    // --accel none: brute force, a reference independent of the BVH code.
    let img = render_with_progress(&scene, w, h, args.accel != Accel::None);
    let ms = t.elapsed().as_secs_f64() * 1e3;
    if let Some(out) = &args.out {
        img.save_png_for("--out", out)?;
    }
    if args.json {
        let info = DeviceInfo {
            device: format!("CPU, {} threads", rayon_threads()),
            driver: "twinray f64 reference".into(),
            api_version: String::new(),
        };
        let frames = vec![FrameTime {
            gpu_ms: None,
            wall_ms: ms,
        }];
        let setup_ms = (t - start).as_secs_f64() * 1e3;
        let report = RunReport {
            nonfinite_pixels: img.nonfinite_pixels(),
            ..RunReport::new(
                "reference",
                info,
                scene.stats(),
                "f64".into(),
                w,
                h,
                frames,
                setup_ms,
            )
        };
        report.print_json()?;
    }
    Ok(())
}

/// The reference render, with a progress bar on stderr once it has run for a
/// second (short renders stay quiet; indicatif draws nothing when stderr is not
/// a terminal, so logs and pipes get no bar).
fn render_with_progress(
    scene: &twinray_common::scene::Scene,
    w: u32,
    h: u32,
    bvh: bool,
) -> twinray_common::reference::image_io::FloatImage {
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    let rows = AtomicUsize::new(0);
    let finished = AtomicBool::new(false);
    std::thread::scope(|s| {
        s.spawn(|| {
            let started = Instant::now();
            let mut bar: Option<indicatif::ProgressBar> = None;
            while !finished.load(Ordering::Relaxed) {
                std::thread::sleep(std::time::Duration::from_millis(100));
                if bar.is_none() && started.elapsed().as_secs_f64() >= 1.0 {
                    let b = indicatif::ProgressBar::with_draw_target(
                        Some(h as u64),
                        indicatif::ProgressDrawTarget::stderr(),
                    );
                    if let Ok(style) = indicatif::ProgressStyle::with_template(
                        "reference {bar:40} {pos}/{len} rows, {elapsed} elapsed, about {eta} left",
                    ) {
                        b.set_style(style);
                    }
                    bar = Some(b);
                }
                if let Some(b) = &bar {
                    b.set_position(rows.load(Ordering::Relaxed) as u64);
                }
            }
            if let Some(b) = bar {
                b.finish_and_clear();
            }
        });
        let img =
            twinray_common::reference::render_counting(scene, w, h, &scene.numerics, bvh, &rows);
        finished.store(true, Ordering::Relaxed);
        img
    })
}

fn rayon_threads() -> usize {
    rayon::current_num_threads()
}
