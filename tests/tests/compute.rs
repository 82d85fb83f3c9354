//! The compute path draws the fragment path's image: for every standard scene
//! and both APIs, ≥ 99.99 % of pixels within 1/255 of the fragment image, no
//! NaN, zero validation messages / GL debug errors; every measured workgroup
//! size, and image sizes that are not a multiple of the workgroup, included.

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
