//! The compute path draws the fragment path's image: for every standard scene
//! and both APIs, ≥ 99.99 % of pixels within 1/255 of the fragment image, no
//! NaN, zero validation messages / GL debug errors; every measured workgroup
//! size, and image sizes that are not a multiple of the workgroup, included;
//! and where the frame's barrier sits changes no pixel.

use twinray_common::value_name::ValueName;
use twinray_tests::{
    assert_clean, assert_within_1, render, scratch, set_args, App, STANDARD_SCENES,
};

fn check(scene: &str, size: &str, extra: &[&str]) {
    let dir = scratch(&format!("compute-{scene}"));
    for app in App::BOTH {
        let (frag_report, fragment) = render(app, scene, size, extra, &dir.join("fragment.png"));
        let mut args = extra.to_vec();
        args.extend(["--path", "compute"]);
        let (report, compute) = render(app, scene, size, &args, &dir.join("compute.png"));
        assert_eq!(frag_report.path.name(), "fragment");
        assert_eq!(
            report.path.name(),
            "compute",
            "{app:?}: the report names the path"
        );
        assert!(
            report.workgroup.is_some(),
            "{app:?}: the report names the workgroup"
        );
        assert_clean(&report, &format!("{scene} {app:?} compute"));
        assert_within_1(
            &compute,
            &fragment,
            0.9999,
            &format!("{scene} {app:?}: compute vs fragment"),
        );
    }
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn the_standard_scenes_compute_matches_fragment() {
    for (scene, size, set) in STANDARD_SCENES {
        let args = set_args(set);
        check(
            scene,
            size,
            &args.iter().map(String::as_str).collect::<Vec<_>>(),
        );
    }
}

#[test]
fn every_measured_workgroup_covers_an_odd_sized_image() {
    // 61x37 is a multiple of none of them: the edge groups must skip, not wrap or drop pixels.
    let dir = scratch("compute-workgroups");
    for app in App::BOTH {
        let (_, fragment) = render(app, "box", "61x37", &[], &dir.join("f.png"));
        for wg in ["8x4", "4x8", "8x8", "8x16", "16x8", "16x16"] {
            let (report, img) = render(
                app,
                "box",
                "61x37",
                &["--path", "compute", "--workgroup", wg],
                &dir.join("c.png"),
            );
            assert_eq!(report.workgroup.as_deref(), Some(wg));
            assert_eq!(report.validation_messages, 0);
            assert_within_1(&img, &fragment, 0.9999, &format!("{app:?} {wg}"));
        }
    }
}

/// What a frame's timed span holds is a matter of timing only: with
/// `--experiment timed-barrier` (the barrier inside the timed span, in both
/// APIs; by default Vulkan records it before its first timestamp and OpenGL's
/// headless frames, each ended by glFinish, have none) or `back-to-back` (two
/// dispatches a frame, with no barrier between them) every frame of a
/// several-frame run draws the default's image byte for byte, with no
/// validation message, and the label says which span was timed.
#[test]
fn the_frames_span_moves_the_timing_not_the_image() {
    for app in App::BOTH {
        for (scene, set) in [
            ("box", &[][..]),
            ("spherelist", &["--set", "extra_spheres=200"][..]),
        ] {
            let dir = scratch(&format!("compute-span-{scene}"));
            let args = [set, &["--path", "compute", "--frames", "4"]].concat();
            let (rd, default) = render(app, scene, "72x40", &args, &dir.join("default.png"));
            for experiment in ["timed-barrier", "back-to-back"] {
                let timed_args = [&args[..], &["--experiment", experiment]].concat();
                let png = dir.join(format!("{experiment}.png"));
                let (rt, timed) = render(app, scene, "72x40", &timed_args, &png);
                let what = format!("{app:?} {scene} ({})", rt.variant);
                assert!(rt.variant.ends_with(&format!("/{experiment}")), "{what}");
                assert!(!rd.variant.contains(experiment), "{what}");
                assert_eq!(rt.frames.len(), rd.frames.len(), "{what}: frames");
                assert_clean(&rt, &what);
                twinray_tests::assert_identical(&default, &timed, &what);
            }
        }
    }
}

/// The compute path hands a frame's tiles out costliest first once it has
/// 4096 of them (`plan::launch`); `--experiment row-order` hands them out in
/// rows. A tile taken twice or never would show: each app draws the same
/// image either way, byte for byte, with no validation message.
#[test]
fn the_launch_order_moves_the_timing_not_the_image() {
    for app in App::BOTH {
        for scene in ["teapot", "box"] {
            let dir = scratch(&format!("compute-launch-{scene}"));
            // 64 × 64 tiles of 4×4: just enough for an order.
            let args = ["--path", "compute", "--workgroup", "4x4"];
            let (rd, ordered) = render(app, scene, "256x256", &args, &dir.join("ordered.png"));
            let rows_args = [&args[..], &["--experiment", "row-order"]].concat();
            let (rr, rows) = render(app, scene, "256x256", &rows_args, &dir.join("rows.png"));
            let what = format!("{app:?} {scene} ({})", rr.variant);
            assert!(rr.variant.ends_with("/row-order"), "{what}");
            assert_clean(&rd, &what);
            assert_clean(&rr, &what);
            twinray_tests::assert_identical(&ordered, &rows, &what);
        }
    }
}

/// OpenGL's walks read the wide tree's nodes through a buffer texture;
/// `--experiment storage-nodes` reads them from their storage block, as
/// Vulkan does. On both paths, through every wide tree (the 4-wide one at two
/// depths, the 8-wide one) and with spheres in the leaves, the two forms give
/// the same bytes, and the label says which form ran.
#[test]
fn opengl_reads_the_nodes_through_a_texture_to_the_same_image() {
    let cases: [(&str, &[&str]); 4] = [
        ("teapot", &[]),
        ("teapot", &["--set", "tessellation=40x30"]),
        ("teapot", &["--accel", "bvh8"]),
        ("spherelist", &["--set", "extra_spheres=1000"]),
    ];
    for (scene, extra) in cases {
        let dir = scratch(&format!("compute-texels-{scene}"));
        for path in ["fragment", "compute"] {
            let args = [extra, &["--path", path]].concat();
            let (rt, texels) = render(App::OpenGl, scene, "64x48", &args, &dir.join("texels.png"));
            let storage_args = [&args[..], &["--experiment", "storage-nodes"]].concat();
            let (rs, storage) = render(
                App::OpenGl,
                scene,
                "64x48",
                &storage_args,
                &dir.join("storage.png"),
            );
            let what = format!("{scene} {args:?} ({} against {})", rt.variant, rs.variant);
            assert!(rt.variant.contains("/node-texels"), "{what}");
            assert!(!rs.variant.contains("/node-texels"), "{what}");
            assert_clean(&rt, &what);
            assert_clean(&rs, &what);
            twinray_tests::assert_identical(&texels, &storage, &what);
        }
        std::fs::remove_dir_all(dir).ok();
    }
}
