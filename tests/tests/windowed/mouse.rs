//! Real mouse input (xdotool through XTEST): a drag orbits the camera, the
//! wheel zooms, and R restores the initial view.

use crate::common::{escape_delivered, stderr, xdotool_failed, xdotool_retrying, FOCUS};
use twinray_common::reference::metrics::compare;
use twinray_tests::{box_window, render, scratch, App, Xvfb};

/// Opens a 96x72 box window, waits for it, performs `gesture` (xdotool
/// commands, the window as %1), presses `keys` and Escape, and returns the
/// view saved at exit.
fn after_gesture(
    x: &Xvfb,
    app: App,
    dir: &std::path::Path,
    gesture: &[&str],
    keys: &[&str],
) -> image::RgbImage {
    let out = dir.join("gesture.png");
    let _ = std::fs::remove_file(&out);
    // A cap, not the plan: Escape ends the run after about 150 frames.
    // (lavapipe leaks about 3 MB per frame, see README, so no open end.)
    let args = box_window(
        "96x72",
        "1000",
        &["--validate", "--out", out.to_str().unwrap()],
    );
    let mut child = x.spawn(&app.exe(), &args, &[], dir);
    let mut cmd = FOCUS.to_vec();
    // Pauses let frames render between the steps: the saved view is the last
    // one drawn, and Escape would otherwise land before the gesture is drawn.
    cmd.extend_from_slice(gesture);
    for k in keys {
        cmd.extend(["sleep", "0.5", "key", k]);
    }
    cmd.extend(["sleep", "0.5", "key", "Escape"]);
    let xd = xdotool_retrying(x, app, &cmd);
    if !escape_delivered(&xd) {
        xdotool_failed(app, &cmd, &xd, &mut child);
    }
    let o = child.wait_with_output().unwrap();
    assert!(o.status.success(), "{app:?}: {}", stderr(&o));
    twinray_common::reference::image_io::load_png(&out)
        .unwrap_or_else(|e| panic!("{app:?}: no --out at exit: {e}"))
}

#[test]
fn mouse_drag_orbits_wheel_zooms_and_r_resets() {
    let x = Xvfb::start();
    let dir = scratch("window-mouse");
    let drag = [
        "mousemove",
        "--window",
        "%1",
        "30",
        "36",
        "mousedown",
        "1",
        "mousemove",
        "--window",
        "%1",
        "60",
        "40",
        "mouseup",
        "1",
    ];
    let wheel = [
        "mousemove",
        "--window",
        "%1",
        "48",
        "36",
        "click",
        "4",
        "click",
        "4",
        "click",
        "4",
    ];
    for app in App::BOTH {
        let (_, still) = render(app, "box", "96x72", &[], &dir.join("still.png"));
        let changed = |img: &image::RgbImage| 1.0 - compare(img, &still).unwrap().within_1();
        let dragged = after_gesture(&x, app, &dir, &drag, &[]);
        assert!(
            changed(&dragged) > 0.05,
            "{app:?}: a drag left the view as it was"
        );
        let zoomed = after_gesture(&x, app, &dir, &wheel, &[]);
        assert!(
            changed(&zoomed) > 0.05,
            "{app:?}: the wheel left the view as it was"
        );
        assert!(
            compare(&dragged, &zoomed).unwrap().within_1() < 0.95,
            "{app:?}: orbit and zoom gave the same view"
        );
        let reset = after_gesture(&x, app, &dir, &drag, &["r"]);
        assert!(
            reset == still,
            "{app:?}: R after a drag does not restore the initial view"
        );
    }
}
