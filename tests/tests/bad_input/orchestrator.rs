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
}
