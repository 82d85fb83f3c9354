//! How `twinray compare` ends when it cannot finish: a run that failed makes
//! the command fail, in the apps' own words, and a signal (SIGTERM, SIGHUP,
//! SIGINT) at any step keeps the finished runs, writes the report marked
//! interrupted, and gives the signal's exit code (128 + its number).
//! Linux only: the tests read /proc for the orchestrator's children.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};
use twinray_tests::{bin, scratch, stand_in, stderr_of};

/// Two stand-in apps that fail every run the way a real one fails on bad
/// input (clap's `error:` line, then its "For more information" line), and
/// that take `slow_s` seconds over a run with `--dump-shaders`, so that a
/// test can catch the orchestrator in its shader-statistics step.
fn failing_apps(dir: &Path, slow_s: u32) -> String {
    let bin_dir = dir.join("apps");
    std::fs::create_dir_all(&bin_dir).unwrap();
    for app in ["twinray-vk", "twinray-gl"] {
        let script = format!(
            "#!/bin/sh\n\
             case \"$*\" in *--dump-shaders*) sleep {slow_s} ;; esac\n\
             echo \"error: unexpected argument '--frobnicate' found ({app})\" >&2\n\
             echo >&2\n\
             echo \"For more information, try '--help'.\" >&2\n\
             exit 2\n"
        );
        stand_in(&bin_dir, app, &script);
    }
    bin_dir.to_str().unwrap().to_string()
}

fn compare(out: &Path, bin_dir: Option<&str>, extra: &[&str]) -> Child {
    let mut args = Vec::new();
    if let Some(dir) = bin_dir {
        args.extend(["--bin-dir", dir]);
    }
    args.extend(["compare", "--quick", "--out", out.to_str().unwrap()]);
    args.extend(extra);
    orchestrator(&args)
}

/// `twinray ARGS`, its stderr captured, with the tests' Mesa cache.
fn orchestrator(args: &[&str]) -> Child {
    Command::new(bin("twinray"))
        .args(args)
        .env(
            "MESA_SHADER_CACHE_DIR",
            std::env::temp_dir().join("twinray-mesa-cache"),
        )
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starting twinray")
}

/// The command lines of `pid`'s children now.
fn children(pid: u32) -> Vec<(u32, String)> {
    let list =
        std::fs::read_to_string(format!("/proc/{pid}/task/{pid}/children")).unwrap_or_default();
    list.split_whitespace()
        .filter_map(|c| c.parse::<u32>().ok())
        .map(|c| {
            let cmdline = std::fs::read(format!("/proc/{c}/cmdline")).unwrap_or_default();
            (c, String::from_utf8_lossy(&cmdline).replace('\0', " "))
        })
        .collect()
}

/// Waits (at most `limit`) until `ready` says yes about the children seen so far.
fn wait_for(child: &Child, limit: Duration, mut ready: impl FnMut(&[(u32, String)]) -> bool) {
    let started = Instant::now();
    let mut seen: Vec<(u32, String)> = Vec::new();
    while started.elapsed() < limit {
        for c in children(child.id()) {
            if !seen.iter().any(|s| s.0 == c.0) {
                seen.push(c);
            }
        }
        if ready(&seen) {
            return;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    panic!("gave up after {limit:?}; children seen: {seen:?}");
}

fn signal(child: &Child, name: &str) {
    let ok = Command::new("kill")
        .args([format!("-{name}"), child.id().to_string()])
        .status()
        .expect("running kill")
        .success();
    assert!(ok, "kill -{name} failed");
}

/// Its exit code and stderr, within `limit`, or the test fails (no hang).
fn finish(mut child: Child, limit: Duration) -> (Option<i32>, String) {
    let started = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return (status.code(), stderr_of(&mut child));
        }
        if started.elapsed() > limit {
            let _ = child.kill();
            panic!("twinray compare still ran {limit:?} after the signal");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// The report an interrupted run wrote to `out`, whose title holds `title`
/// and whose text holds `says`.
fn interrupted_report(out: &Path, title: &str, says: &str) -> String {
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    let first = report.lines().next().unwrap_or_default();
    assert!(first.contains(title), "{first}");
    assert!(report.contains(says), "{report}");
    report
}

#[test]
fn a_comparison_in_which_runs_failed_fails_quoting_the_apps_error() {
    let dir = scratch("orch-failed-runs");
    let apps = failing_apps(&dir, 0);
    let out = dir.join("out");
    let child = compare(&out, Some(&apps), &["--only", "box", "--paths", "fragment"]);
    let (code, stderr) = finish(child, Duration::from_secs(60));
    assert_eq!(code, Some(1), "{stderr}");
    let last = stderr.lines().last().unwrap_or_default();
    assert!(
        last.starts_with("twinray: error: ") && last.contains(" runs failed"),
        "{stderr}"
    );
    // The app's own sentence, not clap's closing line.
    assert!(
        last.contains("unexpected argument '--frobnicate' found (twinray-vk)"),
        "{last}"
    );
    assert!(!stderr.contains("For more information"), "{stderr}");
    // Nothing is lost: the report is written and names the failed points.
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("## Failed points"), "{report}");
    assert!(report.contains("--frobnicate"), "{report}");
}

#[test]
fn sigterm_during_the_sweep_keeps_the_finished_points_and_exits_143() {
    let dir = scratch("orch-sigterm");
    let out = dir.join("out");
    // Box at three sizes, fragment path: six runs of the real apps.
    let child = compare(&out, None, &["--only", "box", "--paths", "fragment"]);
    // The third app started: two runs finished.
    wait_for(&child, Duration::from_secs(40), |seen| {
        seen.iter().filter(|c| c.1.contains("twinray-")).count() >= 3
    });
    signal(&child, "TERM");
    let (code, stderr) = finish(child, Duration::from_secs(30));
    assert_eq!(code, Some(143), "{stderr}");
    let report = interrupted_report(
        &out,
        "(interrupted by SIGTERM during the sweep)",
        "> Interrupted by SIGTERM during the sweep",
    );
    assert!(report.contains("## Points not run"), "{report}");
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let ok = csv.lines().filter(|l| l.contains(",ok,")).count();
    assert!((2..6).contains(&ok), "{ok} finished rows:\n{csv}");
}

#[test]
fn sighup_and_sigint_after_the_sweep_are_stated_and_exit_129_and_130() {
    for (name, code) in [("HUP", 129), ("INT", 130)] {
        let dir = scratch(&format!("orch-sig{name}"));
        let apps = failing_apps(&dir, 3);
        let out = dir.join("out");
        let child = compare(&out, Some(&apps), &["--only", "box", "--paths", "fragment"]);
        // The shader statistics come after the sweep and the image agreement.
        wait_for(&child, Duration::from_secs(40), |seen| {
            seen.iter().any(|c| c.1.contains("--dump-shaders"))
        });
        signal(&child, name);
        let (got, stderr) = finish(child, Duration::from_secs(30));
        // Interrupted, not failed: the signal's code, though every run failed.
        assert_eq!(got, Some(code), "SIG{name}: {stderr}");
        interrupted_report(
            &out,
            &format!("interrupted by SIG{name} during the shader statistics"),
            &format!("> Interrupted by SIG{name} during the shader statistics"),
        );
        assert!(out.join("results.csv").is_file());
    }
}

#[test]
fn sigterm_during_the_accuracy_sweeps_keeps_the_finished_runs_and_exits_143() {
    let dir = scratch("orch-accuracy-sigterm");
    let out = dir.join("out");
    let out_dir = out.to_str().unwrap();
    let child = orchestrator(&[
        "accuracy",
        "--quick",
        "--no-hard",
        "--random",
        "0",
        "--out",
        out_dir,
    ]);
    // Two warm-up runs, the default's first timing in both APIs, then the
    // measured runs: the seventh app started, so at least two rows finished.
    wait_for(&child, Duration::from_secs(180), |seen| {
        seen.iter().filter(|c| c.1.contains("twinray-")).count() >= 7
    });
    signal(&child, "TERM");
    let (code, stderr) = finish(child, Duration::from_secs(60));
    assert_eq!(code, Some(143), "{stderr}");
    interrupted_report(
        &out,
        "(interrupted by SIGTERM during the sweeps)",
        "The run was interrupted by SIGTERM",
    );
    let csv = std::fs::read_to_string(out.join("accuracy.csv")).unwrap();
    assert!(
        csv.lines().count() >= 2,
        "the finished runs are kept:\n{csv}"
    );
}

/// Stand-in apps that hang, ignoring every signal, on a run whose command
/// line matches the shell pattern `hang_on` (after touching `dir/hanging`, so
/// that a test knows the step has reached it), and fail at once on any
/// other, so that the orchestrator reaches the step under test quickly.
fn hanging_apps(dir: &Path, hang_on: &str) -> String {
    let bin_dir = dir.join("apps");
    std::fs::create_dir_all(&bin_dir).unwrap();
    let marker = dir.join("hanging");
    for app in ["twinray-vk", "twinray-gl"] {
        let script = format!(
            "#!/bin/sh\n\
             case \"$*\" in {hang_on})\n\
               trap '' TERM INT HUP\n\
               touch '{}'\n\
               while :; do sleep 0.05; done ;;\n\
             esac\n\
             echo \"error: not a real app ({app})\" >&2\n\
             exit 2\n",
            marker.display()
        );
        stand_in(&bin_dir, app, &script);
    }
    bin_dir.to_str().unwrap().to_string()
}

/// Every process whose command line names `dir`: what a stopped run must not leave.
fn processes_under(dir: &Path) -> Vec<String> {
    let dir = dir.to_string_lossy().to_string();
    std::fs::read_dir("/proc")
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().to_str()?.parse::<u32>().ok())
        .filter_map(|pid| {
            let cmdline = std::fs::read(format!("/proc/{pid}/cmdline")).ok()?;
            let cmdline = String::from_utf8_lossy(&cmdline).replace('\0', " ");
            cmdline.contains(&dir).then(|| format!("{pid}: {cmdline}"))
        })
        .collect()
}

/// One step of one command, with the shell pattern of the run that hangs in
/// it, the words its report's title gives the step, and its CSV.
struct Step {
    command: &'static [&'static str],
    hang_on: &'static str,
    during: &'static str,
    csv: &'static str,
}

const fn step(
    command: &'static [&'static str],
    hang_on: &'static str,
    during: &'static str,
    csv: &'static str,
) -> Step {
    Step {
        command,
        hang_on,
        during,
        csv,
    }
}

const COMPARE_ACCEL: &[&str] = &[
    "compare",
    "--quick",
    "--only",
    "box,accel",
    "--paths",
    "fragment",
];
const COMPARE_BOX: &[&str] = &["compare", "--quick", "--only", "box", "--paths", "fragment"];
const COMPARE_WHY: &[&str] = &["compare", "--quick", "--only", "why", "--paths", "fragment"];
const ACCURACY: &[&str] = &["accuracy", "--quick", "--random", "1"];

#[rustfmt::skip]
const STEPS: [Step; 9] = [
    step(COMPARE_ACCEL, "*--frames*--accel\\ none*", "during the sweep", "results.csv"),
    step(COMPARE_ACCEL, "*--accel\\ bvh*", "during the acceleration runs", "results.csv"),
    step(COMPARE_BOX, "*/images/*", "during the image agreement", "results.csv"),
    step(COMPARE_BOX, "*--dump-shaders*", "during the shader statistics", "results.csv"),
    step(COMPARE_WHY, "*--experiment*", "during the why step", "why.csv"),
    step(ACCURACY, "*", "during the sweeps", "accuracy.csv"),
    step(ACCURACY, "*/hard/*", "during the hard cases", "hard_cases.csv"),
    step(&["accuracy", "--quick", "--no-hard", "--random", "1"], "*random:*", "during the random scenes", "random.csv"),
    // Every operation at the default 2^20 inputs: the CPU's column of all
    // of them, computed after the signal, once took 2.6 s more.
    step(&["ulp"], "*", "interrupted by", "ulp.csv"),
];

/// One step, one signal: the orchestrator ends within 2 s with the signal's
/// code although the app it runs ignores the signal, writes its report and
/// CSV marked interrupted, and leaves no app running and no scratch folder.
fn stop_while_an_app_hangs(n: usize, step: &Step, (name, code): (&str, i32)) -> Result<(), String> {
    let dir = scratch(&format!("hang-{n}-{name}"));
    let apps = hanging_apps(&dir, step.hang_on);
    let out = dir.join("out");
    let mut args = vec!["--bin-dir", &apps];
    args.extend(step.command);
    args.extend(["--out", out.to_str().unwrap()]);
    let mut child = orchestrator(&args);
    let at = format!("{:?} with SIG{name}", step.command);
    let started = Instant::now();
    while !dir.join("hanging").exists() {
        if started.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!(
                "{at}: never reached the run matching {}",
                step.hang_on
            ));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let pid = child.id();
    signal(&child, name);
    let sent = Instant::now();
    let (got, stderr) = finish(child, Duration::from_secs(10));
    let secs = sent.elapsed().as_secs_f64();
    let mut faults = Vec::new();
    if got != Some(code) {
        faults.push(format!("exit {got:?}, not {code}: {stderr}"));
    }
    if secs > 2.0 {
        faults.push(format!("took {secs:.1} s after the signal"));
    }
    let report = if step.csv == "ulp.csv" {
        "ulp.md"
    } else {
        "report.md"
    };
    let title = std::fs::read_to_string(out.join(report)).unwrap_or_default();
    let title = title.lines().next().unwrap_or_default();
    let stated = format!("interrupted by SIG{name}");
    if !title.contains(&stated) || !title.contains(step.during) {
        faults.push(format!(
            "{report}'s title does not say '{stated} {}': {title}",
            step.during
        ));
    }
    let csv = std::fs::read_to_string(out.join(step.csv)).unwrap_or_default();
    if !csv
        .lines()
        .last()
        .is_some_and(|l| l.starts_with(&format!("# {stated}")))
    {
        faults.push(format!(
            "{} does not end marked interrupted:\n{csv}",
            step.csv
        ));
    }
    let left = processes_under(&dir);
    if !left.is_empty() {
        faults.push(format!("apps left running: {left:?}"));
    }
    let scratch_dir = std::env::temp_dir().join(format!("twinray-ulp-{pid}"));
    if scratch_dir.exists() {
        faults.push(format!("{} left behind", scratch_dir.display()));
    }
    let _ = std::fs::remove_dir_all(&dir);
    match faults.is_empty() {
        true => Ok(()),
        false => Err(format!("{at}: {}", faults.join("; "))),
    }
}

#[test]
fn every_signal_in_every_step_ends_the_run_at_once_even_while_an_app_hangs() {
    // A signal to the orchestrator alone once waited for the app to end (35 s,
    // 108 s), and forever for an app that hangs; `ulp` had no handler at all.
    let signals = [("TERM", 143), ("INT", 130), ("HUP", 129)];
    let failures: Vec<String> = std::thread::scope(|s| {
        let handles: Vec<_> = STEPS
            .iter()
            .enumerate()
            .flat_map(|(n, step)| signals.iter().map(move |&sig| (n, step, sig)))
            .map(|(n, step, sig)| s.spawn(move || stop_while_an_app_hangs(n, step, sig)))
            .collect();
        handles
            .into_iter()
            .filter_map(|h| h.join().unwrap().err())
            .collect()
    });
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn render_passes_every_signal_on_to_the_app_it_runs() {
    // `twinray render --api vulkan` waited on its app: a signal to it alone
    // ended it and left the app running.
    for (name, code) in [("TERM", 143), ("INT", 130), ("HUP", 129)] {
        let dir = scratch(&format!("render-{name}"));
        let apps = hanging_apps(&dir, "*");
        let child = orchestrator(&["--bin-dir", &apps, "render", "--api", "vulkan"]);
        let started = Instant::now();
        while !dir.join("hanging").exists() {
            assert!(
                started.elapsed() < Duration::from_secs(30),
                "the app never started"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
        signal(&child, name);
        let sent = Instant::now();
        let (got, stderr) = finish(child, Duration::from_secs(10));
        assert_eq!(got, Some(code), "SIG{name}: {stderr}");
        assert!(
            sent.elapsed() < Duration::from_secs(2),
            "SIG{name}: {:?}",
            sent.elapsed()
        );
        assert_eq!(processes_under(&dir), Vec::<String>::new(), "SIG{name}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
