//! Running the two apps as child processes (never in-process, so each API gets
//! a clean process, as in the study); `reference` runs the CPU reference in-process.

mod reference;

use anyhow::Context;
use std::path::PathBuf;
use std::process::Command;
use std::sync::OnceLock;
use twinray_common::cli::RenderArgs;
use twinray_common::error::{bad_input, Failure, FailureKind};
use twinray_common::report::RunReport;
use twinray_common::value_name::ValueName;

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

/// `--bin-dir` (`TWINRAY_BIN_DIR`), set once by `main` after parsing: every
/// run of an app, however deep in a sweep, looks its binary up here.
static BIN_DIR: OnceLock<PathBuf> = OnceLock::new();

/// Records `--bin-dir`; without it the apps are looked for next to this executable.
pub fn set_bin_dir(dir: Option<PathBuf>) {
    if let Some(dir) = dir {
        let _ = BIN_DIR.set(dir);
    }
}

/// `--bin-dir`'s check, at parse time, the same whether the folder came from
/// the option or from `TWINRAY_BIN_DIR` (clap names whichever it was): a
/// folder that does not exist or lacks the apps is a typo worth one sentence
/// before any render, not a failure in every run of a sweep.
pub fn parse_bin_dir(s: &str) -> Result<PathBuf, String> {
    let dir = PathBuf::from(s);
    if !dir.is_dir() {
        return Err("not a folder".to_string());
    }
    let missing: Vec<&str> = [Api::Vulkan, Api::Opengl]
        .iter()
        .filter_map(|api| api.binary())
        .filter(|bin| !dir.join(bin).is_file())
        .collect();
    match missing.as_slice() {
        [] => Ok(dir),
        _ => Err(format!(
            "the folder holds no {}; point it at the folder of the release build",
            missing.join(" or ")
        )),
    }
}

/// The line of an app's stderr that says why it failed: its own
/// `twinray-vk: error: ...` sentence or clap's `error: ...` line (not the
/// "For more information, try '--help'." that clap ends with), else the last
/// line it wrote.
pub fn error_line(stderr: &str) -> &str {
    let lines = || stderr.lines().map(str::trim).filter(|l| !l.is_empty());
    lines()
        .find(|l| l.starts_with("error:") || l.contains(": error: "))
        .or_else(|| lines().next_back())
        .unwrap_or("no message")
}

/// Where the app binaries live: `--bin-dir` (`TWINRAY_BIN_DIR`), else next to this executable.
pub fn app_path(name: &str) -> anyhow::Result<PathBuf> {
    let (dir, chosen) = match BIN_DIR.get() {
        Some(d) => (d.clone(), true),
        None => (
            std::env::current_exe()?
                .parent()
                .map(PathBuf::from)
                .unwrap_or_default(),
            false,
        ),
    };
    let path = dir.join(name);
    if !path.exists() {
        // A folder the user chose that lacks the apps is bad input; a build without them is not.
        if chosen {
            return Err(bad_input(format!(
                "--bin-dir (TWINRAY_BIN_DIR) '{}' holds no {name}; point it at the folder of the release build",
                dir.display()
            )));
        }
        return Err(anyhow::anyhow!(
            "{name} was not found in '{}'; build the whole workspace (cargo build --release --workspace) or set --bin-dir (TWINRAY_BIN_DIR)",
            dir.display()
        ));
    }
    Ok(path)
}

/// Both apps are where the runs will look for them: checked before the first
/// render, so a build without them is one error, not a failure per run.
pub fn check_present() -> anyhow::Result<()> {
    for api in [Api::Vulkan, Api::Opengl] {
        if let Some(bin) = api.binary() {
            app_path(bin)?;
        }
    }
    Ok(())
}

/// The app's command line for `args` (always headless: the orchestrator never opens windows).
pub fn app_args(args: &RenderArgs) -> Vec<String> {
    // Destructured field by field, so that an option added to RenderArgs does
    // not compile until it is passed on here (and `app_args_round_trip` checks it).
    let RenderArgs {
        scene,
        size,
        headless: _,
        frames,
        settle,
        out,
        json,
        count_rays,
        set,
        validate,
        generic,
        specialize,
        accel,
        gl_spirv,
        vsync,
        explain,
        path,
        workgroup,
        shared_pad,
        experiment,
        ulp_op,
        experiments,
        dump_shaders,
    } = args;
    let mut v = vec![
        "--headless".to_string(),
        "--scene".into(),
        scene.clone(),
        "--size".into(),
        size.to_string(),
    ];
    if let Some(f) = frames {
        v.extend(["--frames".into(), f.to_string()]);
    }
    if let Some(p) = settle {
        v.extend(["--settle".into(), p.to_string()]);
    }
    if let Some(o) = out {
        v.extend(["--out".into(), o.display().to_string()]);
    }
    for s in set {
        v.extend(["--set".into(), s.clone()]);
    }
    let flags = [
        (json, "--json"),
        (count_rays, "--count-rays"),
        (validate, "--validate"),
        (generic, "--generic"),
        (specialize, "--specialize"),
        (gl_spirv, "--gl-spirv"),
        (vsync, "--vsync"),
        (explain, "--explain"),
        (experiments, "--experiments"),
    ];
    v.extend(
        flags
            .iter()
            .filter(|(on, _)| **on)
            .map(|(_, f)| f.to_string()),
    );
    v.extend(["--accel".into(), accel.name()]);
    v.extend(["--path".into(), path.name()]);
    if let Some(wg) = workgroup {
        v.extend(["--workgroup".into(), wg.to_string()]);
    }
    if let Some(kib) = shared_pad {
        v.extend(["--shared-pad".into(), kib.to_string()]);
    }
    for e in experiment {
        v.extend(["--experiment".into(), e.name()]);
    }
    if let Some(op) = ulp_op {
        v.extend(["--ulp-op".into(), op.name()]);
    }
    if let Some(dir) = dump_shaders {
        v.extend(["--dump-shaders".into(), dir.display().to_string()]);
    }
    v
}

/// Runs an app, passing its output through, and exits with its exit code on
/// failure; `truth` (reference only) renders the f64 truth.
pub fn render(api: Api, args: &RenderArgs, truth: bool) -> anyhow::Result<()> {
    if truth && api != Api::Reference {
        return Err(twinray_common::error::bad_input(format!(
            "render --truth is the f64 truth of the reference only; --api {} cannot render it",
            api_name(api)
        )));
    }
    match api.binary() {
        Some(bin) => {
            let mut args = args.clone();
            args.gl_spirv |= api == Api::OpenglSpirv;
            // A signal to this process alone reaches the app too, and the exit
            // code says which it was, as for a signal that ended the app.
            let stop = crate::interrupt::Stop::install()?;
            let mut cmd = Command::new(app_path(bin)?);
            cmd.args(app_args(&args));
            let status = match crate::supervisor::status(cmd, bin) {
                Err(e) if crate::supervisor::is_interrupted(&e) => {
                    std::process::exit(stop.signal().map_or(1, |(_, code)| code))
                }
                other => other?,
            };
            if !status.success() {
                // The app already printed its one-line error; keep its exit code.
                std::process::exit(status.code().unwrap_or(1));
            }
            Ok(())
        }
        None => reference::render_reference(args, truth),
    }
}

/// Software rasterisers (Mesa's lavapipe/llvmpipe, SwiftShader): they get the
/// quick preset, and their ratios say nothing about GPUs.
pub fn is_software(device: &str) -> bool {
    let d = device.to_lowercase();
    ["llvmpipe", "lavapipe", "softpipe", "swiftshader"]
        .iter()
        .any(|s| d.contains(s))
}

/// How many app processes this orchestrator has started: the reports state it.
static RUNS_STARTED: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// The app runs started so far (every `run_json`).
pub fn runs_started() -> usize {
    RUNS_STARTED.load(std::sync::atomic::Ordering::Relaxed)
}

/// Runs an app with `--json` and returns its report; a failure carries the app's own message and exit code.
pub fn run_json(api: Api, args: &RenderArgs) -> anyhow::Result<RunReport> {
    run_json_with(api, args, &Launch::default()).map(|ran| ran.report)
}

/// Where and how `run_json_with` starts an app, beyond its `RenderArgs`: a
/// sweep runs builds side by side, so the binary folder is per call here
/// rather than the process's one `--bin-dir`.
#[derive(Debug, Default, Clone)]
pub struct Launch {
    /// The folder holding the app; `None` is `app_path`'s folder.
    pub bin_dir: Option<PathBuf>,
    /// Options after `RenderArgs`'s own (an app's knobs), already checked by its parser.
    pub extra: Vec<String>,
    /// Environment variables set for this run only.
    pub env: Vec<(String, String)>,
}

/// One finished `--json` run: the parsed report, the app's JSON as it
/// printed it (fields this orchestrator does not know are kept), and the
/// child's process id.
pub struct Ran {
    pub report: RunReport,
    pub json: serde_json::Value,
    pub pid: u32,
}

/// [`run_json`] with a [`Launch`]: the one place an app is started for a report.
pub fn run_json_with(api: Api, args: &RenderArgs, launch: &Launch) -> anyhow::Result<Ran> {
    let bin = api.binary().expect("an app");
    RUNS_STARTED.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let mut args = args.clone();
    args.json = true;
    args.gl_spirv |= api == Api::OpenglSpirv;
    let path = match &launch.bin_dir {
        Some(dir) => dir.join(bin),
        None => app_path(bin)?,
    };
    let mut cmd = Command::new(path);
    cmd.args(app_args(&args))
        .args(&launch.extra)
        .envs(launch.env.iter().map(|(k, v)| (k, v)));
    let (out, pid) = crate::supervisor::output_with_pid(cmd, bin)?;
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        let line = error_line(&stderr).to_string();
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
    let report =
        serde_json::from_str(json).with_context(|| format!("reading {bin}'s JSON report"))?;
    let json =
        serde_json::from_str(json).with_context(|| format!("reading {bin}'s JSON report"))?;
    Ok(Ran { report, json, pid })
}

/// The API's name in every CSV, table, plot and file name.
pub fn api_name(api: Api) -> &'static str {
    match api {
        Api::Vulkan => "vulkan",
        Api::Opengl => "opengl",
        Api::OpenglSpirv => "opengl-spirv",
        Api::Reference => "reference",
    }
}

/// A run's `--set KEY=VALUE` list as the (key, value) pairs `Scene::load`
/// takes: the orchestrator loads the scene a run renders for its reference
/// image, its BVH figures or its shader's defines.
pub fn overrides(set: &[String]) -> Vec<(String, String)> {
    set.iter()
        .filter_map(|kv| kv.split_once('='))
        .map(|(k, v)| (k.into(), v.into()))
        .collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_error_line_is_the_apps_sentence_not_claps_last_line() {
        let clap = "error: invalid value 'x' for '--size <WxH>': no 'x'\n\nFor more information, try '--help'.\n";
        assert_eq!(
            super::error_line(clap),
            "error: invalid value 'x' for '--size <WxH>': no 'x'"
        );
        let own = "warning: slow\ntwinray-vk: error: scene 'kettle' does not exist\n";
        assert_eq!(
            super::error_line(own),
            "twinray-vk: error: scene 'kettle' does not exist"
        );
        assert_eq!(
            super::error_line("Segmentation fault\n\n"),
            "Segmentation fault"
        );
        assert_eq!(super::error_line(""), "no message");
    }

    use super::app_args;
    use clap::Parser;
    use std::path::PathBuf;
    use twinray_common::cli::{RenderArgs, RenderPath, Size, VulkanCli, Workgroup};
    use twinray_common::lab::experiment::{Experiment, UlpOp};
    use twinray_common::scene::accel::Accel;

    /// Every option away from its default, so that one the argv builder drops
    /// or misspells parses back different. Written as a struct literal: a new
    /// option does not compile until it is given a value here too.
    fn every_option_set() -> RenderArgs {
        RenderArgs {
            scene: "spherelist".into(),
            size: Size {
                width: 33,
                height: 17,
            },
            // app_args always adds --headless: the orchestrator never opens a window.
            headless: true,
            frames: Some(7),
            settle: Some(1.5),
            out: Some(PathBuf::from("out dir/a.png")),
            json: true,
            count_rays: true,
            set: vec!["max_depth=3".into(), "extra_spheres=10".into()],
            validate: true,
            generic: false,
            specialize: true,
            accel: Accel::Bvh,
            gl_spirv: true,
            vsync: true,
            explain: true,
            path: RenderPath::Compute,
            workgroup: Some(Workgroup { x: 8, y: 4 }),
            shared_pad: Some(24),
            experiment: vec![Experiment::NagaLoopBounding, Experiment::LocalBvhStack],
            ulp_op: Some(UlpOp::Refract),
            experiments: true,
            dump_shaders: Some(PathBuf::from("dump")),
        }
    }

    fn round_trip(args: &RenderArgs) -> RenderArgs {
        let argv = std::iter::once("twinray-vk".to_string()).chain(app_args(args));
        VulkanCli::try_parse_from(argv)
            .unwrap_or_else(|e| panic!("app_args({args:?}) does not parse: {e}"))
            .render
    }

    #[test]
    fn app_args_round_trip() {
        let args = every_option_set();
        assert_eq!(round_trip(&args), args);
        // --generic conflicts with --specialize, so it gets its own run.
        let generic = RenderArgs {
            generic: true,
            specialize: false,
            ..every_option_set()
        };
        assert_eq!(round_trip(&generic), generic);
        let plain = RenderArgs::headless(
            "box",
            Size {
                width: 800,
                height: 600,
            },
        );
        assert_eq!(round_trip(&plain), plain);
    }

    #[test]
    fn every_option_is_exercised() {
        // An option left at its default would pass the round trip even if
        // app_args dropped it: the two runs above must name every option.
        use clap::CommandFactory;
        let generic = RenderArgs {
            generic: true,
            ..every_option_set()
        };
        let argv = [app_args(&every_option_set()), app_args(&generic)].concat();
        for option in RenderArgs::command().get_arguments() {
            let Some(long) = option.get_long() else {
                continue;
            };
            let long = format!("--{long}");
            assert!(
                argv.contains(&long),
                "every_option_set() leaves {long} at its default"
            );
        }
    }

    #[test]
    fn each_option_alone_round_trips() {
        // One option at a time, taken from the parser itself, so that two
        // options swapped in app_args cannot hide behind each other.
        use clap::CommandFactory;
        let sample = |long: &str| match long {
            "scene" => "spherelist",
            "size" => "33x17",
            "frames" => "7",
            "settle" => "1.5",
            "out" => "a.png",
            "set" => "max_depth=3",
            "workgroup" => "8x4",
            "shared-pad" => "24",
            "dump-shaders" => "dump",
            other => panic!("--{other} needs a sample value in this test"),
        };
        for option in RenderArgs::command().get_arguments() {
            let Some(long) = option.get_long() else {
                continue;
            };
            // app_args always adds --headless, so every run has it.
            let mut argv = vec!["twinray-vk".to_string(), "--headless".into()];
            if long != "headless" {
                argv.push(format!("--{long}"));
            }
            if option.get_action().takes_values() {
                let values = option.get_possible_values();
                // The last possible value: never the first, which is each enum's default.
                argv.push(match values.last() {
                    Some(v) => v.get_name().to_string(),
                    None => sample(long).to_string(),
                });
            }
            let args = VulkanCli::try_parse_from(&argv)
                .unwrap_or_else(|e| panic!("{argv:?} does not parse: {e}"))
                .render;
            assert_eq!(
                round_trip(&args),
                args,
                "--{long} does not survive app_args"
            );
        }
    }
}
