//! `twinray render --api reference` and `twinray diff` as a user runs them.

use twinray_tests::{bin, run, scratch};

#[test]
fn reference_render_and_diff_of_identical_images() {
    let dir = scratch("orch");
    let out = dir.join("ref.png");
    let o = run(
        &bin("twinray"),
        &[
            "render",
            "--api",
            "reference",
            "--scene",
            "box",
            "--size",
            "64x48",
            "--out",
            out.to_str().unwrap(),
        ],
        &[],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
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
    let o = run(
        &bin("twinray"),
        &[
            "render",
            "--api",
            "vulkan",
            "--scene",
            "spherelist",
            "--size",
            "48x32",
            "--out",
            out.to_str().unwrap(),
        ],
        &[],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let img = twinray_common::reference::image_io::load_png(&out).unwrap();
    assert_eq!(img.dimensions(), (48, 32));
}
