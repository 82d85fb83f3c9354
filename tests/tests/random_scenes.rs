//! Differential test on seeded random scenes (common/src/scene/random.rs:
//! spheres, triangles, a mesh, diffuse, mirror and glass with glass inside
//! glass, 1–4 lights, random cameras): Vulkan, OpenGL and the f64 reference
//! render each scene with the same numerics, and every pair must agree within
//! `random::MAX_OFF_SHARE` (pixels off by more than 8/255) and
//! `MIN_WITHIN_1` (pixels within 1/255). A failing seed prints the commands
//! that reproduce it. The apps run the generic shader (`--generic`): random
//! depths and features would otherwise make ~20 variants for the software
//! drivers to compile, and each variant's agreement with the generic shader is
//! tested on its own (tests/tests/accel.rs); `twinray accuracy --random` runs
//! each scene's own variant. Seed 6 is also held, at that run's size, to
//! 8/255 at every pixel f32 can settle (`reference::unsettled`).

use twinray_common::reference;
use twinray_common::reference::metrics;
use twinray_common::scene::random;
use twinray_common::scene::Scene;
use twinray_tests::{assert_none, render, scratch, App};

const SEEDS: std::ops::Range<u64> = 0..20;
const W: u32 = 48;
const H: u32 = 36;

#[test]
fn vulkan_opengl_and_the_reference_agree_on_random_scenes() {
    let dir = scratch("random-scenes");
    let size = format!("{W}x{H}");
    let mut failures = Vec::new();
    let mut worst = (0.0f64, String::new());
    for seed in SEEDS {
        let name = format!("{}{seed}", random::PREFIX);
        let scene = Scene::load(&name, &[]).unwrap();
        let reference = reference::render(&scene, W, H);
        assert_eq!(
            reference.nonfinite_pixels(),
            0,
            "{name}: NaN in the reference"
        );
        let reference = reference.to_rgb8();
        let mut imgs = Vec::new();
        for app in App::BOTH {
            let (report, img) = render(app, &name, &size, &["--generic"], &dir.join("r.png"));
            assert_eq!(
                report.validation_messages, 0,
                "{name} {app:?}: validation messages"
            );
            let mut m = metrics::compare(&img, &reference).unwrap();
            m.nan_pixels = report.nonfinite_pixels;
            imgs.push((format!("{app:?} vs reference"), m, img));
        }
        let pair = metrics::compare(&imgs[0].2, &imgs[1].2).unwrap();
        let mut rows: Vec<(String, metrics::Metrics)> =
            imgs.into_iter().map(|(l, m, _)| (l, m)).collect();
        rows.push(("Vulkan vs OpenGL".into(), pair));
        for (label, m) in rows {
            println!(
                "{name} {label}: {:.3}% off by >8/255, {:.3}% within 1/255, max {}/255",
                100.0 * m.above_8,
                100.0 * m.within_1(),
                m.max_abs
            );
            if m.above_8 > worst.0 {
                worst = (m.above_8, format!("{name} {label}"));
            }
            if let Some(why) = random::disagreement(&m) {
                failures.push(format!(
                    "{name} {label}: {why}\n  reproduce: {}",
                    random::reproduce(seed, W, H, "--generic")
                ));
            }
        }
    }
    println!("worst: {} ({:.3}% off by >8/255)", worst.1, 100.0 * worst.0);
    assert_none("disagreements", &failures);
    std::fs::remove_dir_all(dir).ok();
}

/// Random scene 6 at the size `twinray accuracy --random` renders it: each
/// app agrees with the f64 reference within 8/255 at every pixel f32 can
/// settle. Its one pixel off on lavapipe and llvmpipe, (81, 108) at 30/255,
/// is a ray that bounces six times inside the mirror teapot, where rounding
/// the primary direction to f32 alone changes the colour: the reference's
/// mask of unsettled pixels names it (comparison/investigations/accuracy/README.md).
#[test]
fn seed_6_agrees_with_the_reference_where_f32_can_settle_it() {
    let dir = scratch("random-seed-6");
    let (w, h) = (160, 120);
    let scene = Scene::load("random:6", &[]).unwrap();
    let reference = reference::render(&scene, w, h).to_rgb8();
    let unsettled = reference::unsettled::unsettled(&scene, w, h);
    for app in App::BOTH {
        let (_, img) = render(app, "random:6", "160x120", &[], &dir.join("r.png"));
        let m = metrics::compare_outside(&img, &reference, &unsettled).unwrap();
        assert_eq!(
            m.above_8,
            0.0,
            "random:6 {app:?}: pixels off by more than 8/255 outside the {} unsettled (max {}/255)",
            unsettled.iter().filter(|&&u| u).count(),
            m.max_abs
        );
    }
    std::fs::remove_dir_all(dir).ok();
}
