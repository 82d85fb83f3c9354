//! What the windowed scenarios share: a run's stderr, its clean validated
//! report, the resize hook's counts, xdotool that retries a refused connection,
//! and what a failed xdotool chain reports.

use std::io::Read;
use std::process::{Child, Output};
use twinray_common::report::RunReport;
use twinray_tests::{box_window, App, Xvfb};

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Asserts success, no panic and a clean validated JSON report.
pub fn clean_report(app: App, o: &Output) -> RunReport {
    let err = stderr(o);
    assert!(o.status.success(), "{app:?} failed ({}): {err}", o.status);
    assert!(!err.contains("panicked"), "{app:?} panicked: {err}");
    let out = String::from_utf8_lossy(&o.stdout);
    let report: RunReport = serde_json::from_str(out.trim())
        .unwrap_or_else(|e| panic!("{app:?}: not JSON ({e}): {out}"));
    assert_eq!(report.validation_messages, 0, "{app:?}: {err}");
    report
}

/// A validated `--json` run of the box window at `size` for `frames` frames,
/// with `extra` arguments, which must end cleanly: its report and stderr.
pub fn clean_box_run(
    x: &Xvfb,
    app: App,
    (size, frames): (&str, &str),
    extra: &[&str],
    env: &[(&str, &str)],
    dir: &std::path::Path,
) -> (RunReport, String) {
    let args = box_window(size, frames, &[extra, &["--validate", "--json"]].concat());
    let o = x.run(&app.exe(), &args, env, dir);
    (clean_report(app, &o), stderr(&o))
}

/// Asserts that the resize hook's line on stderr (`TWINRAY_TEST_RESIZE`)
/// counts at least `resizes` resizes and one minimize/restore.
pub fn assert_resized(app: App, err: &str, resizes: u32) {
    let line = err
        .lines()
        .find(|l| l.contains("test resize:"))
        .unwrap_or_else(|| panic!("{app:?}: {err}"));
    let numbers: Vec<u32> = line
        .split_whitespace()
        .filter_map(|w| w.parse().ok())
        .collect();
    assert!(
        numbers[0] >= resizes,
        "{app:?}: only {} resizes: {line}",
        numbers[0]
    );
    assert!(numbers[1] >= 1, "{app:?}: no minimize/restore: {line}");
}

/// xdotool's steps that wait for the app's window (its title starts with
/// "twinray") and focus it, so that keys and the mouse reach it as `%1`.
pub const FOCUS: [&str; 7] = [
    "search",
    "--sync",
    "--name",
    "^twinray",
    "windowfocus",
    "--sync",
    "%1",
];

/// Under load (a fresh shader cache, other windows in parallel tests) the X
/// server now and then refuses xdotool's connection outright ("Can't open
/// display"): nothing has happened yet, so try again.
pub fn xdotool_retrying(x: &Xvfb, app: App, cmd: &[&str]) -> Output {
    let mut xd = x.xdotool(cmd);
    for _ in 0..10 {
        if xd.status.success()
            || !String::from_utf8_lossy(&xd.stderr).contains("Can't open display")
        {
            break;
        }
        eprintln!(
            "{app:?}: xdotool could not connect to {}; trying again",
            x.display
        );
        std::thread::sleep(std::time::Duration::from_millis(300));
        xd = x.xdotool(cmd);
    }
    xd
}

/// Whether xdotool's chain ending in `key Escape` did its job. The app quits on
/// the key's press, so the release that xdotool sends next can find the window
/// gone: "BadWindow" on X_SendEvent, with the app already on its way out. The
/// caller's check of the app's exit status says whether it quit as asked.
pub fn escape_delivered(xd: &Output) -> bool {
    let err = String::from_utf8_lossy(&xd.stderr);
    xd.status.success() || (err.contains("BadWindow") && err.contains("X_SendEvent"))
}

/// Ends a test whose xdotool chain failed: stops the app and panics with
/// xdotool's error, whether the app was still running, and what it printed,
/// which tells a window that went away from one that never answered.
pub fn xdotool_failed(app: App, cmd: &[&str], xd: &Output, child: &mut Child) -> ! {
    let running = matches!(child.try_wait(), Ok(None));
    let _ = child.kill();
    let mut app_err = String::new();
    if let Some(mut e) = child.stderr.take() {
        let _ = e.read_to_string(&mut app_err);
    }
    let _ = child.wait();
    panic!(
        "{app:?}: xdotool {cmd:?} ({}): {}\nthe app {}; its stderr:\n{app_err}",
        xd.status,
        String::from_utf8_lossy(&xd.stderr),
        if running {
            "was still running"
        } else {
            "had exited"
        },
    );
}
