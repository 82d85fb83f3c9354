//! What runs without a window: `--explain`'s numbered steps on stderr, and the
//! one sentence (exit 3) when there is no X display at all. (Whether its numbers
//! and order agree with the walkthrough is tests/tests/walkthrough_steps.rs's.)

use crate::common::stderr;
use twinray_tests::{scratch, App};

#[test]
fn explain_prints_ordered_steps_on_stderr_only() {
    let dir = scratch("explain");
    let args = [
        "--explain",
        "--headless",
        "--scene",
        "box",
        "--size",
        "64x64",
    ];
    for app in App::BOTH {
        let o = twinray_tests::run(&app.exe(), &args, &[]);
        assert!(o.status.success(), "{app:?}: {}", stderr(&o));
        assert!(
            o.stdout.is_empty(),
            "{app:?}: --explain must leave stdout to --json"
        );
        let steps: Vec<u32> = stderr(&o)
            .lines()
            .filter_map(|l| {
                l.strip_prefix('[')
                    .and_then(|r| r.split(']').next())
                    .and_then(|n| n.trim().parse().ok())
            })
            .collect();
        assert!(
            steps.len() >= 12,
            "{app:?}: only {} steps:\n{}",
            steps.len(),
            stderr(&o)
        );
        // Each line carries the number of the walkthrough step it belongs to.
        assert!(
            steps.iter().all(|&n| n <= 22),
            "{app:?}: a step number past the walkthrough's 22:\n{}",
            stderr(&o)
        );
    }
    let _ = dir;
}

#[test]
fn no_display_is_exit_3_with_one_sentence() {
    for app in App::BOTH {
        let o = std::process::Command::new(app.exe())
            .args(["--scene", "box", "--frames", "1"])
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .unwrap();
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(3), "{app:?}: {err}");
        assert!(
            err.contains("xvfb-run") && err.lines().count() == 1,
            "{app:?}: {err}"
        );
    }
}
