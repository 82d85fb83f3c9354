//! What runs without a window: `--explain`'s ordered steps on stderr, and the
//! one sentence (exit 3) when there is no X display at all.

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
        assert_eq!(
            steps,
            (1..=steps.len() as u32).collect::<Vec<_>>(),
            "{app:?}: steps out of order"
        );
    }
    // The Vulkan steps name the objects in the order the walkthrough teaches them.
    let o = twinray_tests::run(&App::Vulkan.exe(), &args, &[]);
    let err = stderr(&o);
    let order = [
        "VkInstance",
        "VkPhysicalDevice",
        "VkDevice",
        "VkRenderPass",
        "VkDescriptorSetLayout",
        "VkPipeline ",
        "VkFramebuffer",
        "VkCommandPool",
    ];
    let pos: Vec<usize> = order
        .iter()
        .map(|s| err.find(s).unwrap_or_else(|| panic!("no {s} in:\n{err}")))
        .collect();
    assert!(pos.windows(2).all(|w| w[0] < w[1]), "out of order:\n{err}");
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
