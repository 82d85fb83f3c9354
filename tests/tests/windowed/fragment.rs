//! The window on the fragment path: it opens and renders, survives resizes
//! and minimize/restore, runs every key's action, and its `--out` at exit
//! equals the headless image.

use crate::common::{assert_resized, clean_box_run, stderr};
use twinray_tests::{box_window, render, scratch, App, Xvfb};

#[test]
fn both_apps_open_a_window_render_30_frames_and_exit_cleanly() {
    let x = Xvfb::start();
    let dir = scratch("window-30");
    for app in App::BOTH {
        let (r, _) = clean_box_run(&x, app, ("128x96", "30"), &[], &[], &dir);
        assert_eq!(r.frames.len(), 30, "{app:?}");
        assert_eq!((r.width, r.height), (128, 96), "{app:?}");
    }
}

#[test]
fn fifty_resizes_and_minimize_restore_cause_no_crash_and_no_message() {
    let x = Xvfb::start();
    let dir = scratch("window-resize");
    for app in App::BOTH {
        let env = [("TWINRAY_TEST_RESIZE", "1")];
        let (_, err) = clean_box_run(&x, app, ("120x90", "150"), &[], &env, &dir);
        assert_resized(app, &err, 50);
    }
}

#[test]
fn every_key_action_works_with_zero_messages() {
    let x = Xvfb::start();
    let dir = scratch("window-keys");
    // Scene switches (spherelist, back to box: the teapot is too slow for
    // lavapipe at test speed), depth up past the stack (new variants) and down
    // to 1 (same shader), reset, screenshot, and Esc last.
    let keys = "3,2,+,+,-,-,-,-,-,-,r,p,esc";
    for app in App::BOTH {
        let env = [("TWINRAY_TEST_KEYS", keys)];
        let (r, err) = clean_box_run(&x, app, ("96x72", "100"), &[], &env, &dir);
        assert_eq!(
            r.frames.len(),
            13,
            "{app:?}: Esc after the 13th frame ends the run"
        );
        assert!(
            err.contains("max depth 7 (new shader variant"),
            "{app:?}: a deeper stack needs a new variant: {err}"
        );
        assert!(
            err.contains("max depth 1 (same shader"),
            "{app:?}: shallower depths keep the shader: {err}"
        );
        let tag = if matches!(app, App::Vulkan) {
            "vk"
        } else {
            "gl"
        };
        let shot = dir.join(format!("twinray-{tag}-box-1.png"));
        let img = twinray_common::reference::image_io::load_png(&shot)
            .unwrap_or_else(|e| panic!("{app:?}: P saved nothing: {e}"));
        assert_eq!(img.dimensions(), (96, 72));
    }
}

#[test]
fn windowed_out_equals_the_headless_image() {
    let x = Xvfb::start();
    let dir = scratch("window-out");
    for app in App::BOTH {
        let win = dir.join("window.png");
        let args = box_window(
            "100x80",
            "3",
            &["--validate", "--out", win.to_str().unwrap()],
        );
        let o = x.run(&app.exe(), &args, &[], &dir);
        assert!(o.status.success(), "{app:?}: {}", stderr(&o));
        let (_, headless) = render(app, "box", "100x80", &[], &dir.join("headless.png"));
        let windowed = twinray_common::reference::image_io::load_png(&win).unwrap();
        assert!(
            windowed == headless,
            "{app:?}: the windowed --out differs from --headless --out"
        );
    }
}
