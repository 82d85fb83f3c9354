//! The compute path in the window: `--path compute`, the live switch `C`
//! (the title says which path runs), a resize storm with scene and path
//! switches, and every screenshot and screen equal to the headless image of
//! its path, under the validation layer's synchronisation validation.

use crate::common::{
    assert_resized, clean_box_run, clean_report, escape_delivered, stderr, xdotool_failed,
    xdotool_retrying, FOCUS,
};
use std::path::Path;
use twinray_common::cli::RenderPath;
use twinray_common::value_name::ValueName;
use twinray_tests::{box_window, render, scratch, App, Xvfb, SYNC_VALIDATION};

fn tag(app: App) -> &'static str {
    match app {
        App::Vulkan => "vk",
        App::OpenGl => "gl",
    }
}

fn load(path: &Path) -> image::RgbImage {
    twinray_common::reference::image_io::load_png(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The headless image of `scene` at 64x48 on `path`.
fn headless(app: App, scene: &str, path: RenderPath, dir: &Path) -> image::RgbImage {
    let out = dir.join(format!("headless-{}-{scene}-{path}.png", tag(app)));
    render(app, scene, "64x48", &["--path", &path.name()], &out).1
}

#[test]
fn compute_path_window_and_live_switch_screenshots_equal_headless() {
    let x = Xvfb::start();
    let dir = scratch("window-compute");
    for app in App::BOTH {
        // --path compute opens a window; --out at exit is the compute image.
        let win = dir.join(format!("{}-compute.png", tag(app)));
        let args = box_window(
            "64x48",
            "4",
            &[
                "--path",
                "compute",
                "--validate",
                "--json",
                "--explain",
                "--out",
                win.to_str().unwrap(),
            ],
        );
        let o = x.run(&app.exe(), &args, &[SYNC_VALIDATION], &dir);
        let r = clean_report(app, &o);
        assert_eq!(r.path, RenderPath::Compute, "{app:?}");
        // The box walks auto's tree: each API's shape for BVH walks.
        let shape = match app {
            App::Vulkan => "8x16",
            App::OpenGl => "4x8",
        };
        assert_eq!(r.workgroup.as_deref(), Some(shape), "{app:?}");
        assert_eq!(r.frames.len(), 4, "{app:?}");
        let err = stderr(&o);
        let blit = match app {
            App::Vulkan => "vkCmdBlitImage",
            App::OpenGl => "glBlitFramebuffer",
        };
        assert!(
            err.contains("Compute path in the window") && err.contains(blit),
            "{app:?}: --explain does not show the compute path's objects:\n{err}"
        );
        let box_compute = headless(app, "box", RenderPath::Compute, &dir);
        assert!(
            load(&win) == box_compute,
            "{app:?}: the compute window's --out differs from --headless --path compute --out"
        );

        // Live: C to compute, P, C back to fragment, P, C, 3 (spherelist on
        // the compute path), P, Esc: one action per frame.
        let keys = "c,p,c,p,c,3,p,esc";
        let env = [("TWINRAY_TEST_KEYS", keys), SYNC_VALIDATION];
        let (r, err) = clean_box_run(&x, app, ("64x48", "100"), &[], &env, &dir);
        assert_eq!(r.frames.len(), 8, "{app:?}: Esc after the 8th frame");
        assert_eq!(r.path, RenderPath::Compute, "{app:?}: the path at exit");
        let switches: Vec<&str> = err.lines().filter(|l| l.contains(": path ")).collect();
        assert_eq!(switches.len(), 3, "{app:?}: {err}");
        assert!(switches[0].ends_with("path compute") && switches[1].ends_with("path fragment"));
        let t = tag(app);
        let shots = [
            ("box-1", box_compute),
            ("box-2", headless(app, "box", RenderPath::Fragment, &dir)),
            (
                "spherelist-3",
                headless(app, "spherelist", RenderPath::Compute, &dir),
            ),
        ];
        for (name, expected) in shots {
            let shot = load(&dir.join(format!("twinray-{t}-{name}.png")));
            assert!(
                shot == expected,
                "{app:?}: screenshot {name} differs from the headless image of its path"
            );
        }
    }
}

#[test]
fn compute_path_survives_a_resize_storm_with_scene_and_path_switches() {
    let x = Xvfb::start();
    let dir = scratch("window-compute-resize");
    // Scene and path switches in the first frames, while the window resizes.
    let keys = "3,c,c,2,c,c";
    for app in App::BOTH {
        let env = [
            ("TWINRAY_TEST_RESIZE", "1"),
            ("TWINRAY_TEST_KEYS", keys),
            SYNC_VALIDATION,
        ];
        let compute = ["--path", "compute"];
        let (r, err) = clean_box_run(&x, app, ("64x48", "70"), &compute, &env, &dir);
        assert_eq!(r.path, RenderPath::Compute, "{app:?}");
        assert_eq!(err.matches(": path ").count(), 4, "{app:?}: {err}");
        assert_resized(app, &err, 25);
    }
}

/// Real keyboard input and what the window really shows: the title names the
/// running path and its FPS, the C key (xdotool through XTEST) switches the
/// path, and on each path the pixels on the X screen equal the headless image.
#[test]
fn c_key_switches_the_path_the_title_follows_and_the_screen_equals_headless() {
    let x = Xvfb::start();
    let dir = scratch("window-c-key");
    for app in App::BOTH {
        let api = match app {
            App::Vulkan => "Vulkan",
            App::OpenGl => "OpenGL",
        };
        // A cap, not the plan: Escape ends the run. It must outlast the
        // steps below on a loaded machine (llvmpipe draws this window at
        // ~100 FPS), yet stay bounded for lavapipe, which leaks per frame.
        let cap = match app {
            App::Vulkan => "1000",
            App::OpenGl => "20000",
        };
        let args = box_window("64x48", cap, &["--path", "compute", "--validate"]);
        let mut child = x.spawn(&app.exe(), &args, &[SYNC_VALIDATION], &dir);
        // xdotool's --name is a regular expression, and --sync waits until a
        // title matches: FPS in the title means frames of that path were shown.
        let mut step = |cmd: &[&str]| {
            let xd = xdotool_retrying(&x, app, cmd);
            if !xd.status.success() {
                xdotool_failed(app, cmd, &xd, &mut child);
            }
            String::from_utf8_lossy(&xd.stdout).into_owned()
        };
        let shown = |geometry: &str| {
            // "Position: X,Y (screen: 0)"
            let pos = geometry
                .split("Position:")
                .nth(1)
                .and_then(|r| r.split_whitespace().next())
                .unwrap_or_else(|| panic!("{app:?}: no position in {geometry}"));
            let (px, py) = pos.split_once(',').unwrap();
            x.screen(px.parse().unwrap(), py.parse().unwrap(), 64, 48)
        };
        // xdotool matches the title in the C locale, where "—" is no character: `.*`.
        let compute = format!("^twinray .* box .* {api} compute .* [0-9.]+ FPS");
        let fragment = format!("^twinray .* box .* {api} fragment .* [0-9.]+ FPS");
        let on_compute = shown(&step(&[
            "search",
            "--sync",
            "--name",
            &compute,
            "getwindowgeometry",
            "%1",
        ]));
        step(&[
            "search",
            "--sync",
            "--name",
            &compute,
            "windowfocus",
            "--sync",
            "%1",
            "key",
            "c",
        ]);
        let on_fragment = shown(&step(&[
            "search",
            "--sync",
            "--name",
            &fragment,
            "getwindowgeometry",
            "%1",
        ]));
        let escape = [&FOCUS[..], &["key", "Escape"]].concat();
        let xd = xdotool_retrying(&x, app, &escape);
        if !escape_delivered(&xd) {
            xdotool_failed(app, &escape, &xd, &mut child);
        }
        let o = child.wait_with_output().unwrap();
        assert!(o.status.success(), "{app:?}: {}", stderr(&o));
        assert!(
            on_compute == headless(app, "box", RenderPath::Compute, &dir),
            "{app:?}: the compute window shows other pixels than --headless --path compute"
        );
        assert!(
            on_fragment == headless(app, "box", RenderPath::Fragment, &dir),
            "{app:?}: after C the window shows other pixels than --headless --path fragment"
        );
    }
}
