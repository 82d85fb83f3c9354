//! Helpers for the end-to-end tests in tests/tests/: locating the built apps,
//! running them the way a user does, and reading back their PNG + JSON.

pub mod markdown;
pub mod repo;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use twinray_common::report::RunReport;

/// `target/<profile>/`, found from this test executable (`target/<profile>/deps/…`),
/// with the three apps built there for this profile. A test must never fail
/// because nobody built them first (a fresh clone's `cargo test --workspace`),
/// nor run stale ones after an edit: so the first call in each test process
/// runs `cargo build` for them, which takes a second when they are up to date.
pub fn bin_dir() -> PathBuf {
    static BUILT: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    BUILT.get_or_init(build_apps).clone()
}

/// Builds twinray-vk, twinray-gl and twinray with the profile and target
/// folder of this test executable. Cargo does not hold its build lock while
/// tests run, so this nested build cannot wait on the `cargo test` that started it.
fn build_apps() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    let dir = exe
        .parent()
        .and_then(Path::parent)
        .expect("target/<profile>")
        .to_path_buf();
    let profile = match dir.file_name().and_then(|n| n.to_str()) {
        Some("debug") => "dev".to_string(),
        Some(name) => name.to_string(),
        None => panic!("{} is not a target/<profile> folder", dir.display()),
    };
    let target_dir = dir.parent().expect("target/");
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR")).join("../Cargo.toml");
    // Cargo runs tests with CARGO set to itself; `cargo` is the fallback elsewhere.
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let status = Command::new(&cargo)
        .args(["build", "--quiet", "--profile", &profile])
        .args(["-p", "twinray-vk", "-p", "twinray-gl", "-p", "twinray"])
        // As tests/run.sh builds them: the windowed tests drive the apps
        // through their test hooks. The same features make this a no-op there.
        .args(["--features", "twinray-vk/test-hooks,twinray-gl/test-hooks"])
        .arg("--manifest-path")
        .arg(&manifest)
        .arg("--target-dir")
        .arg(target_dir)
        .status()
        .unwrap_or_else(|e| {
            panic!(
                "starting {} to build the apps: {e}",
                cargo.to_string_lossy()
            )
        });
    assert!(
        status.success(),
        "building the apps for the end-to-end tests failed ({status}); the output above says why"
    );
    for name in ["twinray-vk", "twinray-gl", "twinray"] {
        assert!(
            dir.join(name).exists(),
            "cargo built the apps but {name} is not in {}",
            dir.display()
        );
    }
    dir
}

pub fn bin(name: &str) -> PathBuf {
    bin_dir().join(name)
}

/// A fresh scratch folder for one test.
pub fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("twinray-test-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs a command with a writable Mesa shader cache (lavapipe/llvmpipe recompile
/// every frame without one) and returns its output.
pub fn run(program: &Path, args: &[&str], env: &[(&str, &str)]) -> Output {
    let cache = std::env::temp_dir().join("twinray-mesa-cache");
    let mut cmd = Command::new(program);
    cmd.args(args).env("MESA_SHADER_CACHE_DIR", &cache);
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.output()
        .unwrap_or_else(|e| panic!("starting {}: {e}", program.display()))
}

/// Runs a command as [`run`] does and expects it to succeed; its output.
pub fn run_ok(program: &Path, args: &[&str], env: &[(&str, &str)]) -> Output {
    let o = run(program, args, env);
    assert!(
        o.status.success(),
        "{} {args:?} failed ({}): {}",
        program.display(),
        o.status,
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

/// Which app to run.
#[derive(Clone, Copy, Debug)]
pub enum App {
    Vulkan,
    OpenGl,
}

impl App {
    pub const BOTH: [App; 2] = [App::Vulkan, App::OpenGl];

    pub fn exe(self) -> PathBuf {
        bin(match self {
            App::Vulkan => "twinray-vk",
            App::OpenGl => "twinray-gl",
        })
    }
}

/// `--set` overrides as (key, value) pairs.
pub type Overrides = &'static [(&'static str, &'static str)];

/// The standard scenes as the image-agreement tests render them: (scene,
/// size, `--set` overrides). The sphere list with 100 more spheres, hidden in
/// the visible one, so that a wrong sphere count shows.
pub const STANDARD_SCENES: [(&str, &str, Overrides); 3] = [
    ("box", "160x120", &[]),
    ("teapot", "64x48", &[]),
    ("spherelist", "160x120", &[("extra_spheres", "100")]),
];

/// `--set KEY=VALUE` for each of `overrides`.
pub fn set_args(overrides: &[(&str, &str)]) -> Vec<String> {
    overrides
        .iter()
        .flat_map(|(k, v)| ["--set".to_string(), format!("{k}={v}")])
        .collect()
}

/// A successful validated headless render: its report and its 8-bit image.
pub fn render(
    app: App,
    scene: &str,
    size: &str,
    extra: &[&str],
    out: &Path,
) -> (RunReport, image::RgbImage) {
    let mut args = vec![
        "--headless",
        "--validate",
        "--json",
        "--scene",
        scene,
        "--size",
        size,
        "--out",
    ];
    let out_s = out.to_str().unwrap();
    args.push(out_s);
    args.extend_from_slice(extra);
    let o = run(&app.exe(), &args, &[]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        o.status.success(),
        "{app:?} {args:?} failed ({}): {stderr}",
        o.status
    );
    let stdout = String::from_utf8_lossy(&o.stdout);
    let report: RunReport = serde_json::from_str(stdout.trim())
        .unwrap_or_else(|e| panic!("{app:?}: stdout is not one JSON report ({e}): {stdout}"));
    let img = twinray_common::reference::image_io::load_png(out).unwrap();
    (report, img)
}

/// `twinray render --api API --scene SCENE --size SIZE EXTRA --out OUT` as a
/// user runs it, which must succeed; the image it wrote.
pub fn orchestrator_render(
    api: &str,
    scene: &str,
    size: &str,
    extra: &[&str],
    out: &Path,
) -> image::RgbImage {
    let mut args = vec!["render", "--api", api, "--scene", scene, "--size", size];
    args.extend_from_slice(extra);
    args.extend(["--out", out.to_str().unwrap()]);
    let o = run(&bin("twinray"), &args, &[]);
    assert!(
        o.status.success(),
        "twinray {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    twinray_common::reference::image_io::load_png(out).unwrap()
}

/// A render that is clean: no validation message (or GL debug error) and no
/// NaN/Inf pixel before quantisation.
pub fn assert_clean(report: &RunReport, what: &str) {
    assert_eq!(report.validation_messages, 0, "{what}: validation messages");
    assert_eq!(
        report.nonfinite_pixels, 0,
        "{what}: NaN/Inf pixels before quantisation"
    );
}

/// Two images agree: at least the share `min` of their pixels within 1/255
/// of each other. The share is printed as well, so that a passing run still
/// shows its margin.
pub fn assert_within_1(a: &image::RgbImage, b: &image::RgbImage, min: f64, what: &str) {
    let m = twinray_common::reference::metrics::compare(a, b).unwrap();
    let within = 100.0 * m.within_1();
    println!("{what}: {within:.4}% within 1/255, max {}", m.max_abs);
    assert!(
        m.within_1() >= min,
        "{what}: only {within:.4}% within 1/255 (at least {}% expected)",
        100.0 * min
    );
}

/// Two images are the same byte for byte; otherwise the test fails saying
/// how many pixels differ.
pub fn assert_identical(a: &image::RgbImage, b: &image::RgbImage, what: &str) {
    let differing = a.pixels().zip(b.pixels()).filter(|(a, b)| a != b).count();
    assert_eq!(differing, 0, "{what}: {differing} pixels differ");
}

/// Nothing went wrong; otherwise the test fails naming `problem`, how many
/// there are, and each of them.
pub fn assert_none(problem: &str, wrong: &[String]) {
    assert!(
        wrong.is_empty(),
        "{problem} ({}):\n{}",
        wrong.len(),
        wrong.join("\n")
    );
}

/// The exit code and stderr of a run that is expected to fail.
pub fn fail(program: &Path, args: &[&str], env: &[(&str, &str)]) -> (i32, String) {
    let o = run(program, args, env);
    let stderr = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(
        !stderr.contains("panicked"),
        "{} {args:?} panicked: {stderr}",
        program.display()
    );
    (o.status.code().unwrap_or(-1), stderr)
}

/// Runs `app` with `args` and expects a refusal: exit 2 and a stderr that
/// contains `sentence`.
pub fn refused(app: App, args: &[&str], sentence: &str) {
    let (code, stderr) = fail(&app.exe(), args, &[]);
    assert_eq!(code, 2, "{app:?} {args:?}: exit code (stderr: {stderr})");
    assert!(
        stderr.contains(sentence),
        "{app:?} {args:?}: stderr must say '{sentence}', got: {stderr}"
    );
}

/// The arguments of a windowed run of the box scene at `size` for `frames`
/// frames, then `extra`: the windowed tests' common start.
pub fn box_window<'a>(size: &'a str, frames: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec!["--scene", "box", "--size", size, "--frames", frames];
    args.extend_from_slice(extra);
    args
}

/// The validation layer's synchronisation validation (hazards between
/// commands, submits and presents), on top of `--validate`'s core checks; the
/// GL app ignores it.
pub const SYNC_VALIDATION: (&str, &str) = (
    "VK_LAYER_ENABLES",
    "VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT",
);

/// Writes an executable shell script `name` into `dir`: a stand-in for an
/// app, for tests of how the orchestrator takes an app's failure.
pub fn stand_in(dir: &Path, name: &str, script: &str) -> PathBuf {
    use std::os::unix::fs::PermissionsExt;
    let path = dir.join(name);
    std::fs::write(&path, script).unwrap();
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
    path
}

/// All of a finished child's piped stderr.
pub fn stderr_of(child: &mut std::process::Child) -> String {
    use std::io::Read;
    let mut stderr = Vec::new();
    child
        .stderr
        .take()
        .expect("stderr piped")
        .read_to_end(&mut stderr)
        .unwrap();
    String::from_utf8_lossy(&stderr).into_owned()
}

/// A private X server for one windowed test (Debian's `xvfb`; tests/run.sh
/// installs it). `-displayfd` lets Xvfb pick a free display number itself, so
/// tests running in parallel never collide. `-fbdir` keeps the screen in a
/// file, so a test can read what a window really shows ([`Xvfb::screen`]).
/// Killed on drop.
pub struct Xvfb {
    child: std::process::Child,
    pub display: String,
    fbdir: PathBuf,
}

impl Xvfb {
    pub fn start() -> Xvfb {
        use std::io::BufRead;
        static SERVERS: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
        let k = SERVERS.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        let fbdir = std::env::temp_dir().join(format!("twinray-xvfb-{}-{k}", std::process::id()));
        std::fs::create_dir_all(&fbdir).unwrap();
        let mut child = Command::new("Xvfb")
            .args([
                "-displayfd",
                "1",
                "-screen",
                "0",
                "640x480x24",
                "-nolisten",
                "tcp",
                "-fbdir",
            ])
            .arg(&fbdir)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap_or_else(|e| panic!("starting Xvfb ({e}): install xvfb (tests/run.sh does)"));
        let mut line = String::new();
        std::io::BufReader::new(child.stdout.take().expect("piped"))
            .read_line(&mut line)
            .expect("Xvfb display number");
        let n: u32 = line
            .trim()
            .parse()
            .unwrap_or_else(|_| panic!("Xvfb printed '{line}' instead of a display number"));
        Xvfb {
            child,
            display: format!(":{n}"),
            fbdir,
        }
    }

    /// The screen's pixels in the rectangle at (`x`, `y`) of `width`×`height`,
    /// as shown now: Xvfb's screen file is an XWD image (a 100-byte header of
    /// 25 big-endian u32 fields, the colour map, then the rows), which at depth
    /// 24 holds 32-bit pixels.
    pub fn screen(&self, x: u32, y: u32, width: u32, height: u32) -> image::RgbImage {
        let data = std::fs::read(self.fbdir.join("Xvfb_screen0")).expect("Xvfb's screen file");
        let field = |i: usize| u32::from_be_bytes(data[i * 4..i * 4 + 4].try_into().unwrap());
        let (header, byte_order, bpp, line, colours) =
            (field(0), field(7), field(11), field(12), field(19));
        assert_eq!(bpp, 32, "Xvfb's screen is not 32 bits per pixel");
        let start = (header + colours * 12) as usize;
        image::RgbImage::from_fn(width, height, |i, j| {
            let at = start + ((y + j) * line + (x + i) * 4) as usize;
            let p = &data[at..at + 4];
            // 0x00RRGGBB, least significant byte first unless byte_order is 1.
            let v = if byte_order == 1 {
                u32::from_be_bytes(p.try_into().unwrap())
            } else {
                u32::from_le_bytes(p.try_into().unwrap())
            };
            image::Rgb([(v >> 16) as u8, (v >> 8) as u8, v as u8])
        })
    }

    fn command(&self, program: &Path, args: &[&str], env: &[(&str, &str)], dir: &Path) -> Command {
        let cache = std::env::temp_dir().join("twinray-mesa-cache");
        let mut cmd = Command::new(program);
        cmd.args(args)
            .current_dir(dir)
            .env("MESA_SHADER_CACHE_DIR", &cache)
            .env("DISPLAY", &self.display)
            .env_remove("WAYLAND_DISPLAY");
        for (k, v) in env {
            cmd.env(k, v);
        }
        cmd
    }

    /// Runs `program` on this display (and nowhere else: WAYLAND_DISPLAY is
    /// cleared). Under load the X server now and then refuses a connection
    /// outright, as it does xdotool's (windowed/common.rs,
    /// `xdotool_retrying`): once in a CI run on two cores, twinray-gl exited 3
    /// with winit's "Failed to open connection to X server" on a display
    /// that had just served twinray-vk. An app that could not connect has
    /// done nothing yet, so it is started again, up to ten times; any other
    /// outcome is returned as it is.
    pub fn run(&self, program: &Path, args: &[&str], env: &[(&str, &str)], dir: &Path) -> Output {
        let start = || {
            self.command(program, args, env, dir)
                .output()
                .unwrap_or_else(|e| panic!("starting {}: {e}", program.display()))
        };
        let mut o = start();
        for _ in 0..10 {
            if !refused_by_the_x_server(&o) {
                break;
            }
            eprintln!(
                "{}: the X server {} refused the connection; trying again",
                program.display(),
                self.display
            );
            std::thread::sleep(std::time::Duration::from_millis(300));
            o = start();
        }
        o
    }

    /// Starts `program` on this display without waiting, its output captured.
    pub fn spawn(
        &self,
        program: &Path,
        args: &[&str],
        env: &[(&str, &str)],
        dir: &Path,
    ) -> std::process::Child {
        self.command(program, args, env, dir)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap_or_else(|e| panic!("starting {}: {e}", program.display()))
    }

    /// Real X input through XTEST, as a user's mouse and keyboard make it
    /// (xdotool; tests/run.sh installs it). A window or title that never comes
    /// would leave `search --sync` waiting for ever, so 120 s at most
    /// (coreutils' `timeout`, exit 124).
    pub fn xdotool(&self, args: &[&str]) -> Output {
        Command::new("timeout")
            .arg("120")
            .arg("xdotool")
            .args(args)
            .env("DISPLAY", &self.display)
            .output()
            .unwrap_or_else(|e| {
                panic!("running xdotool ({e}): install xdotool (tests/run.sh does)")
            })
    }
}

/// An app's exit when the X server refused its connection: exit 3 (no
/// display) with winit's words for a failed XOpenDisplay.
fn refused_by_the_x_server(o: &Output) -> bool {
    o.status.code() == Some(3)
        && String::from_utf8_lossy(&o.stderr).contains("Failed to open connection to X server")
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_dir_all(&self.fbdir);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::process::ExitStatusExt;

    fn exited(code: i32, stderr: &str) -> Output {
        Output {
            status: std::process::ExitStatus::from_raw(code << 8),
            stdout: Vec::new(),
            stderr: stderr.as_bytes().to_vec(),
        }
    }

    #[test]
    fn only_a_refused_x_connection_is_started_again() {
        let refused = "twinray-gl: error: cannot open a window (Failed to open connection to X server): no X display (is DISPLAY set?); run under xvfb-run, or use --headless";
        assert!(refused_by_the_x_server(&exited(3, refused)));
        assert!(!refused_by_the_x_server(&exited(
            3,
            "twinray-vk: error: no Vulkan device"
        )));
        assert!(!refused_by_the_x_server(&exited(2, refused)));
        assert!(!refused_by_the_x_server(&exited(0, "")));
    }
}
