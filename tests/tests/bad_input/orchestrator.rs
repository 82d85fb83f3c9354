//! The orchestrator's own bad input: `twinray diff` of images that cannot be
//! compared, and `twinray render` of an unknown scene.

use crate::common::expect_one;
use twinray_tests::{bin, scratch};

#[test]
fn orchestrator_diff_and_render_errors() {
    let dir = scratch("diff");
    let a = dir.join("a.png");
    image::RgbImage::new(4, 4).save(&a).unwrap();
    let b = dir.join("b.png");
    image::RgbImage::new(5, 4).save(&b).unwrap();
    let tw = bin("twinray");
    expect_one(
        &tw,
        &["diff", a.to_str().unwrap(), "/no/such.png"],
        &[],
        2,
        &["/no/such.png"],
    );
    expect_one(
        &tw,
        &["diff", a.to_str().unwrap(), b.to_str().unwrap()],
        &[],
        2,
        &["differ in size"],
    );
    expect_one(
        &tw,
        &[
            "render",
            "--api",
            "reference",
            "--scene",
            "kettle",
            "--json",
        ],
        &[],
        2,
        &["'kettle'"],
    );
    // What the reference cannot honour is refused, not ignored.
    for (option, value) in [
        ("--gl-spirv", None),
        ("--experiment", Some("naga-zero-init")),
        ("--dump-shaders", Some("shaders")),
        ("--path", Some("compute")),
    ] {
        let mut args = vec!["render", "--api", "reference", "--scene", "box", "--json"];
        args.push(option);
        args.extend(value);
        expect_one(&tw, &args, &[], 2, &["--api reference", option]);
    }
    // Neither may the heatmap replace an image it compares.
    let c = dir.join("c.png");
    image::RgbImage::new(4, 4).save(&c).unwrap();
    for input in [&a, &c] {
        let args = [
            "diff",
            a.to_str().unwrap(),
            c.to_str().unwrap(),
            "--heatmap",
            input.to_str().unwrap(),
        ];
        expect_one(&tw, &args, &[], 2, &["--heatmap", "input image"]);
    }
}
