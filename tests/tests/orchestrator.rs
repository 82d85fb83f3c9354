//! `twinray render --api reference` and `twinray diff` as a user runs them.

use twinray_tests::{bin, orchestrator_render, run, scratch};

#[test]
fn reference_render_and_diff_of_identical_images() {
    let dir = scratch("orch");
    let out = dir.join("ref.png");
    orchestrator_render("reference", "box", "64x48", &[], &out);
    let o = run(
        &bin("twinray"),
        &[
            "diff",
            out.to_str().unwrap(),
            out.to_str().unwrap(),
            "--json",
        ],
        &[],
    );
    assert!(o.status.success());
    let m: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(m["rmse"], 0.0);
    assert_eq!(m["above_1"], 0.0);
    assert_eq!(m["max_abs"], 0);
}

#[test]
fn render_through_the_orchestrator_matches_the_app() {
    let dir = scratch("orch-app");
    let out = dir.join("vk.png");
    let img = orchestrator_render("vulkan", "spherelist", "48x32", &[], &out);
    assert_eq!(img.dimensions(), (48, 32));
}

/// The hidden `render --truth` and `hard-runs` that
/// comparison/investigations/accuracy/gpu-tolerances.sh measures with: the
/// truth is the very image tests/tests/hard_cases.rs compares against (not the
/// reference with the scene's own numerics, which on coplanar differs from it),
/// and the runs are the test's.
#[test]
fn the_tolerance_script_gets_the_hard_cases_truth_and_runs() {
    use twinray_common::scene::{hard, Scene};
    let dir = scratch("truth");
    let scene = format!("{}/coplanar.toml", hard::SOURCE_DIR);
    let render = |extra: &[&str], name: &str| {
        orchestrator_render("reference", &scene, "64x64", extra, &dir.join(name))
    };
    let truth = render(&["--truth"], "truth.png");
    let own = render(&[], "own.png");
    let expected =
        twinray_common::reference::render_truth(&Scene::load(&scene, &[]).unwrap(), 64, 64)
            .to_rgb8();
    assert!(
        truth == expected,
        "render --truth is not reference::render_truth"
    );
    assert!(
        truth != own,
        "coplanar's truth equals its own numerics' render"
    );
    let o = run(&bin("twinray"), &["hard-runs"], &[]);
    let printed: Vec<String> = String::from_utf8_lossy(&o.stdout)
        .lines()
        .map(String::from)
        .collect();
    let runs: Vec<String> = hard::RUNS.iter().map(|r| r.join(" ")).collect();
    assert_eq!(printed, runs);
    std::fs::remove_dir_all(dir).ok();
}
