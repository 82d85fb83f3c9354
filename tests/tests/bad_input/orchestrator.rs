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
        ("--experiment", Some("naga-loop-bounding")),
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
        expect_one(&tw, &args, &[], 2, &["--heatmap", "replace an input"]);
    }
    // A mask that leaves out every pixel leaves nothing to compare: it once
    // gave a perfect match (rmse 0, exit 0) of no pixels.
    let white = dir.join("white.png");
    image::RgbImage::from_pixel(4, 4, image::Rgb([255, 255, 255]))
        .save(&white)
        .unwrap();
    let (a_s, c_s) = (a.to_str().unwrap(), c.to_str().unwrap());
    let args = ["diff", a_s, c_s, "--exclude", white.to_str().unwrap()];
    expect_one(
        &tw,
        &args,
        &[],
        2,
        &["--exclude", "white.png", "every pixel"],
    );
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

/// An output that names an input, through any spelling of its path, is
/// refused before any work and leaves the input as it was: the mask over the
/// scene, the heatmap over the mask (each once wrote over the other, exit 0).
#[test]
fn an_output_never_replaces_an_input() {
    let dir = scratch("output-over-input");
    let tw = bin("twinray");
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, crate::common::SCENE_HEAD).unwrap();
    let mask = dir.join("mask.png");
    image::RgbImage::new(4, 4).save(&mask).unwrap();
    let a = dir.join("a.png");
    image::RgbImage::new(4, 4).save(&a).unwrap();
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    let spell = |file: &std::path::Path, n: usize| -> Vec<String> {
        let (hard, sym) = (dir.join(format!("hard{n}")), dir.join(format!("sym{n}")));
        std::fs::hard_link(file, &hard).unwrap();
        std::os::unix::fs::symlink(file, &sym).unwrap();
        let up = dir.join("sub/..").join(file.file_name().unwrap());
        [file.to_path_buf(), hard, sym, up]
            .iter()
            .map(|p| p.to_str().unwrap().to_string())
            .collect()
    };
    let before = (
        std::fs::read(&scene).unwrap(),
        std::fs::read(&mask).unwrap(),
    );
    let (s, m, a_s) = (
        scene.to_str().unwrap(),
        mask.to_str().unwrap(),
        a.to_str().unwrap(),
    );
    for out in spell(&scene, 0) {
        let args = [
            "render",
            "--api",
            "reference",
            "--scene",
            s,
            "--size",
            "8x8",
            "--unsettled",
            &out,
        ];
        expect_one(
            &tw,
            &args,
            &[],
            2,
            &["--unsettled", "the scene file", "replace an input"],
        );
    }
    for out in spell(&mask, 1) {
        let args = ["diff", a_s, a_s, "--exclude", m, "--heatmap", &out];
        expect_one(
            &tw,
            &args,
            &[],
            2,
            &["--heatmap", "--exclude", "replace an input"],
        );
    }
    assert_eq!(
        before,
        (
            std::fs::read(&scene).unwrap(),
            std::fs::read(&mask).unwrap()
        )
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
    // What no app accepts is refused up front, not in every run (it was
    // accepted: "about NaN s per app per point", then each app refused 200000).
    for (option, value) in [
        ("--frames", "200000"),
        ("--seconds-per-point", "nan"),
        ("--seconds-per-point", "inf"),
        ("--seconds-per-point", "0"),
        ("--seconds-per-point", "-1"),
        ("--seconds-per-point", "1e300"),
    ] {
        let quoted = format!("'{value}'");
        expect_one(
            &tw,
            &["compare", "--quick", option, value, "--out", out_s],
            &[],
            2,
            &[option, &quoted],
        );
    }
    // A probe image no driver renders (2048x46875 for cross) is refused before any run.
    expect_one(
        &tw,
        &[
            "ulp", "--inputs", "16000000", "--ops", "cross", "--out", out_s,
        ],
        &[],
        2,
        &[
            "--inputs 16000000",
            "cross",
            "2048x46875",
            "at most 5592405",
        ],
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
