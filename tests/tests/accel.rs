//! Model only what a scene needs: the BVH and the per-scene shader variants
//! change the speed, never the picture. BVH vs brute force, variant vs
//! `--generic` and variant vs `--specialize` agree on ≥ 99.99 % of pixels
//! within 1/255, in both APIs.

use twinray_common::metrics::compare;
use twinray_tests::{render, scratch, App};

const SCENES: [(&str, &str, &[&str]); 3] = [
    ("box", "96x72", &[]),
    ("teapot", "64x48", &[]),
    ("spherelist", "96x72", &["--set", "extra_spheres=500"]),
];

fn agree(app: App, scene: &str, size: &str, a: &[&str], b: &[&str], what: &str) {
    let dir = scratch(&format!("accel-{scene}-{what}"));
    let (ra, ia) = render(app, scene, size, a, &dir.join("a.png"));
    let (rb, ib) = render(app, scene, size, b, &dir.join("b.png"));
    assert_ne!(
        ra.variant, rb.variant,
        "{what}: the two runs must use different shaders"
    );
    let m = compare(&ia, &ib).unwrap();
    assert!(
        m.within_1() >= 0.9999,
        "{app:?} {scene} {what} ({} vs {}): {:.4}% within 1/255",
        ra.variant,
        rb.variant,
        100.0 * m.within_1()
    );
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn bvh_and_brute_force_give_the_same_image() {
    for app in App::BOTH {
        for (scene, size, set) in SCENES {
            let none: Vec<&str> = set.iter().copied().chain(["--accel", "none"]).collect();
            let bvh: Vec<&str> = set.iter().copied().chain(["--accel", "bvh"]).collect();
            agree(app, scene, size, &none, &bvh, "bvh");
        }
    }
}

#[test]
fn every_scene_variant_agrees_with_the_generic_shader() {
    for app in App::BOTH {
        for (scene, size, set) in SCENES {
            let variant: Vec<&str> = set.iter().copied().chain(["--accel", "none"]).collect();
            let generic: Vec<&str> = set
                .iter()
                .copied()
                .chain(["--accel", "none", "--generic"])
                .collect();
            agree(app, scene, size, &variant, &generic, "generic");
        }
    }
}

#[test]
fn specialization_constants_render_what_the_scene_variant_renders() {
    // --specialize: one source whose feature switches are constant_id overrides
    // set per scene (naga's process_overrides), in both APIs, with and without
    // the BVH.
    for app in App::BOTH {
        for (scene, size, set) in SCENES {
            let variant: Vec<&str> = set.iter().copied().collect();
            let spec: Vec<&str> = set.iter().copied().chain(["--specialize"]).collect();
            agree(app, scene, size, &variant, &spec, "specialize");
        }
    }
}

#[test]
fn auto_uses_the_bvh_only_for_large_scenes() {
    let dir = scratch("accel-auto");
    let (small, _) = render(App::Vulkan, "box", "16x16", &[], &dir.join("a.png"));
    assert!(
        !small.variant.ends_with("/bvh"),
        "box (32 primitives): {}",
        small.variant
    );
    let (large, _) = render(App::Vulkan, "teapot", "16x16", &[], &dir.join("b.png"));
    assert!(
        large.variant.ends_with("/bvh"),
        "teapot (19,201 primitives): {}",
        large.variant
    );
}
