//! A window's scene switches keep the run's choices: `--accel` (none stays
//! brute force, bvh stays a BVH) and every `--set` that applies to the new
//! scene; one that cannot apply is dropped with a line saying so, instead of
//! refusing the switch.

use crate::common::{clean_report, stderr};
use twinray_tests::{scratch, App, Xvfb};

/// Runs `args` in a window, presses `keys` (one per frame) and returns the
/// report and stderr.
fn switched(
    x: &Xvfb,
    app: App,
    args: &[&str],
    keys: &str,
) -> (twinray_common::report::RunReport, String) {
    let dir = scratch("window-switches");
    let mut all = vec!["--size", "32x24", "--frames", "6", "--validate", "--json"];
    all.extend_from_slice(args);
    let o = x.run(&app.exe(), &all, &[("TWINRAY_TEST_KEYS", keys)], &dir);
    (clean_report(app, &o), stderr(&o))
}

#[test]
fn scene_switches_keep_accel_and_the_overrides_that_apply() {
    let x = Xvfb::start();
    for app in App::BOTH {
        // The teapot by brute force, then the box, then the teapot again: still no BVH.
        let (r, err) = switched(&x, app, &["--scene", "teapot", "--accel", "none"], "2,1");
        assert_eq!(r.scene.name, "teapot", "{app:?}: {err}");
        assert!(
            !r.variant.contains("/bvh"),
            "{app:?}: --accel none holds after 2 then 1: {}",
            r.variant
        );
        // The box through a BVH, to the sphere list and back: still a BVH,
        // and the depth override still applies (glass at depth 2: a 2-slot stack).
        let (r, err) = switched(
            &x,
            app,
            &["--scene", "box", "--accel", "bvh", "--set", "max_depth=2"],
            "3,2",
        );
        assert_eq!(r.scene.name, "box", "{app:?}: {err}");
        assert!(r.variant.contains("/bvh"), "{app:?}: {}", r.variant);
        assert!(r.variant.contains("/stack2/"), "{app:?}: {}", r.variant);
        assert_eq!(r.scene.max_depth, 2, "{app:?}");
        // 50 hidden spheres cannot apply to the box: the switch drops them
        // and says so; back on the sphere list they apply again.
        let extra_50 = ["--scene", "spherelist", "--set", "extra_spheres=50"];
        let (r, err) = switched(&x, app, &extra_50, "2");
        assert_eq!(r.scene.name, "box", "{app:?}: the switch happened: {err}");
        assert!(
            err.contains("'box' without it: --set extra_spheres"),
            "{app:?}: the dropped option is named: {err}"
        );
        let (r, err) = switched(&x, app, &extra_50, "2,3");
        assert_eq!(r.scene.name, "spherelist", "{app:?}: {err}");
        assert_eq!(r.scene.spheres, 51, "{app:?}: the override is back: {err}");
    }
}
