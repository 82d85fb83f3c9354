//! The orchestrator's own bad input: `twinray diff` of images that cannot be
//! compared, `twinray render` of an unknown scene, and the options of
//! `compare` and `accuracy` that must be refused before any render and
//! before their output folder is created.

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
    // The hidden --truth is the reference's alone, and renders the truth only
    // as the hard-case tests take it: no tree, no ray counts.
    for (api, extra) in [
        ("vulkan", None),
        ("opengl", None),
        ("reference", Some("--accel")),
        ("reference", Some("--count-rays")),
    ] {
        let mut args = vec![
            "render", "--truth", "--api", api, "--scene", "box", "--json",
        ];
        let named = match extra {
            Some("--accel") => {
                args.extend(["--accel", "bvh"]);
                "--accel"
            }
            Some(option) => {
                args.push(option);
                option
            }
            None => api,
        };
        expect_one(&tw, &args, &[], 2, &["--truth", named]);
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
    // A mask of another size cannot say which pixels to leave out.
    expect_one(
        &tw,
        &[
            "diff",
            a.to_str().unwrap(),
            c.to_str().unwrap(),
            "--exclude",
            b.to_str().unwrap(),
        ],
        &[],
        2,
        &["--exclude", "5x4"],
    );
}

/// Only the f64 reference names unsettled pixels, and never over its image.
#[test]
fn unsettled_masks_are_the_references_alone() {
    let dir = scratch("unsettled");
    let tw = bin("twinray");
    let mask = dir.join("mask.png");
    let mask_s = mask.to_str().unwrap();
    for (api, out, why) in [
        ("vulkan", "x.png", "--api reference"),
        ("reference", mask_s, "--out"),
    ] {
        let args = [
            "render",
            "--api",
            api,
            "--scene",
            "box",
            "--size",
            "8x8",
            "--out",
            out,
            "--unsettled",
            mask_s,
        ];
        expect_one(&tw, &args, &[], 2, &["--unsettled", why]);
    }
    assert!(!mask.exists(), "a refused --unsettled wrote its mask");
}

/// A folder that exists but lacks the apps is refused the same way from the
/// option and from the variable, each naming itself and the folder, before
/// anything runs: no run of a sweep may fail on it and be counted as done.
#[test]
fn a_bin_folder_without_the_apps_is_refused_from_option_and_variable() {
    let dir = scratch("bin-dir");
    let empty = dir.join("no-apps");
    std::fs::create_dir_all(&empty).unwrap();
    let empty_s = empty.to_str().unwrap();
    let out = dir.join("out");
    let out_s = out.to_str().unwrap();
    let tw = bin("twinray");
    let compare = ["compare", "--quick", "--out", out_s];
    expect_one(
        &tw,
        &compare,
        &[("TWINRAY_BIN_DIR", empty_s)],
        2,
        &["TWINRAY_BIN_DIR", empty_s, "twinray-vk"],
    );
    let with_option = [&["--bin-dir", empty_s][..], &compare[..]].concat();
    expect_one(
        &tw,
        &with_option,
        &[],
        2,
        &["--bin-dir", empty_s, "twinray-vk"],
    );
    let accuracy = ["accuracy", "--quick", "--out", out_s];
    expect_one(
        &tw,
        &accuracy,
        &[("TWINRAY_BIN_DIR", empty_s)],
        2,
        &["TWINRAY_BIN_DIR", empty_s],
    );
    assert!(!out.exists(), "a refused run created {out_s}");
}

/// Refusing an option creates nothing and costs no render: `--frames 0`,
/// an unknown `--only`, a missing `--hard` folder.
#[test]
fn compare_and_accuracy_refuse_before_creating_or_rendering() {
    let dir = scratch("refuse-first");
    let out = dir.join("out");
    let out_s = out.to_str().unwrap();
    let tw = bin("twinray");
    expect_one(
        &tw,
        &["compare", "--quick", "--frames", "0", "--out", out_s],
        &[],
        2,
        &["--frames", "'0'"],
    );
    expect_one(
        &tw,
        &["compare", "--quick", "--only", "bogus", "--out", out_s],
        &[],
        2,
        &["--only", "'bogus'"],
    );
    let started = std::time::Instant::now();
    expect_one(
        &tw,
        &[
            "accuracy",
            "--quick",
            "--hard",
            "/nonexistent",
            "--out",
            out_s,
        ],
        &[],
        2,
        &["/nonexistent"],
    );
    // Before the first sweep, which takes minutes on a software driver.
    assert!(
        started.elapsed().as_secs() < 10,
        "--hard /nonexistent was refused after {:?}",
        started.elapsed()
    );
    assert!(!out.exists(), "a refused option created {out_s}");
}
