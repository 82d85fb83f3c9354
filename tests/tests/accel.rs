//! Model only what a scene needs: the BVH, its collapse and the per-scene
//! shader variants change the speed, never the picture. BVH (of each width) vs brute force, variant vs
//! `--generic` and variant vs `--specialize` agree on ≥ 99.99 % of pixels
//! within 1/255, in both APIs; the optimal collapse renders the greedy one's
//! image, and OpenGL's light-first shading the lights' loop's, byte for byte.

use twinray_common::reference::metrics::compare;
use twinray_tests::{assert_identical, assert_within_1, orchestrator_render, render, scratch, App};

const SCENES: [(&str, &str, &[&str]); 3] = [
    ("box", "96x72", &[]),
    ("teapot", "64x48", &[]),
    ("spherelist", "96x72", &["--set", "extra_spheres=500"]),
];

/// On every scene and both APIs, the runs with the scene's arguments and
/// then `a`, and with them and then `b`, use different shaders and render the
/// same image.
fn agree(a: &[&str], b: &[&str], what: &str) {
    for app in App::BOTH {
        for (scene, size, set) in SCENES {
            let dir = scratch(&format!("accel-{scene}-{what}"));
            let (ra, ia) = render(app, scene, size, &[set, a].concat(), &dir.join("a.png"));
            let (rb, ib) = render(app, scene, size, &[set, b].concat(), &dir.join("b.png"));
            assert_ne!(
                ra.variant, rb.variant,
                "{what}: the two runs must use different shaders"
            );
            assert_within_1(
                &ia,
                &ib,
                0.9999,
                &format!("{app:?} {scene} {what} ({} vs {})", ra.variant, rb.variant),
            );
            std::fs::remove_dir_all(dir).ok();
        }
    }
}

#[test]
fn bvh_and_brute_force_give_the_same_image() {
    agree(&["--accel", "none"], &["--accel", "bvh"], "bvh");
}

/// The 4- and 8-wide trees (`--accel bvh4`, `bvh8`) on both paths: the same
/// image as brute force, and the variant and the JSON say which width ran.
#[test]
fn wide_bvhs_and_brute_force_give_the_same_image() {
    for app in App::BOTH {
        for (scene, size, set) in SCENES {
            let dir = scratch(&format!("accel-wide-{scene}"));
            let none = [set, &["--accel", "none"]].concat();
            let (rn, brute) = render(app, scene, size, &none, &dir.join("none.png"));
            for (accel, width) in [("bvh4", 4), ("bvh8", 8)] {
                for path in ["fragment", "compute"] {
                    let args = [set, &["--accel", accel, "--path", path]].concat();
                    let (r, img) = render(app, scene, size, &args, &dir.join("w.png"));
                    let what = format!("{app:?} {scene} {accel} {path} ({})", r.variant);
                    assert!(r.variant.contains(&format!("/wide{width}/bvh")), "{what}");
                    assert_eq!(r.bvh_width, Some(width), "{what}: the JSON's width");
                    assert_ne!(r.variant, rn.variant);
                    assert_within_1(&brute, &img, 0.9999, &format!("{what} vs brute force"));
                }
            }
            std::fs::remove_dir_all(dir).ok();
        }
    }
}

/// `--experiment greedy-collapse` (the collapse the optimal one replaced,
/// over the same leaves in the same order) on both paths of both apps at
/// both widths: the default tree no costlier by the JSON's SAH cost, and the
/// greedy tree's image byte for byte. Only the order the walk meets the
/// leaves in changes, which could change a pixel only where two primitives
/// are hit at exactly the same distance.
#[test]
fn the_optimal_collapse_renders_the_greedy_trees_image() {
    for app in App::BOTH {
        for (scene, size, set) in SCENES {
            let dir = scratch(&format!("accel-optimal-{scene}"));
            for accel in ["bvh4", "bvh8"] {
                for path in ["fragment", "compute"] {
                    let args = [set, &["--accel", accel, "--path", path]].concat();
                    let (ro, optimal) = render(app, scene, size, &args, &dir.join("optimal.png"));
                    let args = [&args[..], &["--experiment", "greedy-collapse"]].concat();
                    let (rg, greedy) = render(app, scene, size, &args, &dir.join("greedy.png"));
                    let what = format!("{app:?} {scene} {accel} {path} ({})", rg.variant);
                    assert!(rg.variant.ends_with("/greedy-collapse"), "{what}");
                    assert_eq!(rg.validation_messages, 0, "{what}: validation messages");
                    let (g, o) = (rg.bvh_sah_cost.unwrap(), ro.bvh_sah_cost.unwrap());
                    assert!(o <= g * (1.0 + 1e-9), "{what}: SAH cost {o}, greedy {g}");
                    assert_identical(
                        &optimal,
                        &greedy,
                        &format!("{what}, against the greedy tree"),
                    );
                }
            }
            std::fs::remove_dir_all(dir).ok();
        }
    }
}

/// OpenGL's BVH walks on the compute path shade a scene's one light before
/// its shadow walk (`/light-first`, Api::light_before_walk); Vulkan, brute
/// force, the fragment path and scenes of several lights keep the loop. The
/// same operations in the same order: `--experiment walk-then-shade`, which
/// puts the loop back, renders the same image byte for byte.
#[test]
fn the_light_first_shading_renders_the_loops_image() {
    let cases: [(&str, &str, &[&str], bool); 4] = [
        ("spherelist", "96x72", &["--set", "extra_spheres=500"], true),
        ("box", "96x72", &["--accel", "bvh4"], true),
        ("box", "96x72", &["--accel", "none"], false),
        ("teapot", "64x48", &[], false),
    ];
    for app in App::BOTH {
        for (scene, size, set, one_light_bvh) in cases {
            let dir = scratch(&format!("accel-light-first-{scene}"));
            for path in ["fragment", "compute"] {
                let args = [set, &["--path", path]].concat();
                let (rd, default) = render(app, scene, size, &args, &dir.join("default.png"));
                let loop_args = [&args[..], &["--experiment", "walk-then-shade"]].concat();
                let (rl, looped) = render(app, scene, size, &loop_args, &dir.join("loop.png"));
                let what = format!("{app:?} {scene} {args:?} ({})", rd.variant);
                let expected = matches!(app, App::OpenGl) && path == "compute" && one_light_bvh;
                assert_eq!(rd.variant.contains("/light-first"), expected, "{what}");
                assert!(
                    !rl.variant.contains("/light-first"),
                    "{what}: with the loop"
                );
                assert_identical(&looped, &default, &format!("{what}, against the loop"));
            }
            std::fs::remove_dir_all(dir).ok();
        }
    }
}

#[test]
fn every_scene_variant_agrees_with_the_generic_shader() {
    agree(
        &["--accel", "none"],
        &["--accel", "none", "--generic"],
        "generic",
    );
}

#[test]
fn specialization_constants_render_what_the_scene_variant_renders() {
    // --specialize: one source whose feature switches are constant_id overrides
    // set per scene (naga's process_overrides), in both APIs, with and without
    // the BVH.
    agree(&[], &["--specialize"], "specialize");
}

/// `auto` switches at AUTO_BVH_MIN_PRIMITIVES (16): the sphere list with its
/// one hidden sphere (8 primitives) stays brute force, the box (32) and the
/// teapot take the tree.
#[test]
fn auto_uses_the_bvh_from_sixteen_primitives() {
    let dir = scratch("accel-auto");
    let (small, _) = render(App::Vulkan, "spherelist", "16x16", &[], &dir.join("a.png"));
    assert!(
        !small.variant.contains("/bvh"),
        "spherelist (8 primitives): {}",
        small.variant
    );
    for (scene, primitives) in [("box", 32), ("teapot", 19_201)] {
        let (large, _) = render(App::Vulkan, scene, "16x16", &[], &dir.join("b.png"));
        assert!(
            large.variant.contains("/bvh"),
            "{scene} ({primitives} primitives): {}",
            large.variant
        );
    }
}

/// A frame of odd width: its middle column's primary rays have a zero x
/// component. Through each tree, in both apps and on both paths, the box
/// matches brute force but for the rays that run exactly along a seam of its
/// floor tiles, where each takes one of two hits at the same point (2 pixels
/// of 2,257). The inverse direction once read a denormal as 0 and the whole
/// column missed every box: 37 black pixels, 98.4 %.
#[test]
fn a_zero_direction_component_still_enters_the_tree() {
    let dir = scratch("accel-zero-component");
    for app in App::BOTH {
        for path in ["fragment", "compute"] {
            let args = ["--path", path, "--accel", "none"];
            let (_, brute) = render(app, "box", "61x37", &args, &dir.join("n.png"));
            for accel in ["bvh", "bvh4", "bvh8"] {
                let args = ["--path", path, "--accel", accel];
                let (_, tree) = render(app, "box", "61x37", &args, &dir.join("t.png"));
                assert_within_1(&tree, &brute, 0.998, &format!("{app:?} {path} {accel}"));
            }
        }
    }
}

/// A scene whose BVH is deeper than the small fixed stacks that were measured
/// as cheaper defaults (8, 16 or 24 entries): spheres along the view axis, each
/// 1.3 times larger and farther than the last, so that the binned SAH peels a
/// few off the row at each level. A ray that passes by the small spheres keeps
/// one far child per level on its stack; a fixed stack smaller than that
/// dropped pushes and lost whole subtrees (visible as missing spheres). The
/// traversal stack is now as deep as the tree built. (Binned SAH over f32
/// geometry cannot be driven past ~64 levels: each level must shrink the
/// centroid range by the bin count, so the old fixed 64 was never exceeded.)
fn deep_bvh_scene(dir: &std::path::Path) -> std::path::PathBuf {
    let mut toml = String::from(
        "description = \"160 spheres in a geometric row: a deep BVH\"\n\
         [camera]\neye = [-0.5, 0.6, 0.7]\nlook_at = [60.0, 0.0, 0.0]\nup = [0.0, 0.0, 1.0]\nfov_y = 60.0\n\
         [[materials]]\nname = \"m\"\ndiffuse = [0.8, 0.6, 0.4]\nambient = [0.1, 0.1, 0.1]\n\
         [[lights]]\nposition = [-2.0, 3.0, 4.0]\ncolor = [1.0, 1.0, 1.0]\n",
    );
    for k in 0..160 {
        let x = 1.3f64.powi(k);
        toml += &format!(
            "[[spheres]]\ncenter = [{x}, 0.0, 0.0]\nradius = {}\nmaterial = \"m\"\n",
            0.2 * x
        );
    }
    let path = dir.join("deep-bvh.toml");
    std::fs::write(&path, toml).unwrap();
    path
}

#[test]
fn a_bvh_deeper_than_the_small_fixed_stacks_renders_every_primitive() {
    let dir = scratch("accel-deep");
    let scene = deep_bvh_scene(&dir);
    let scene = scene.to_str().unwrap();
    let reference = dir.join("ref.png");
    let truth = orchestrator_render(
        "reference",
        scene,
        "64x48",
        &["--accel", "none"],
        &reference,
    );
    for app in App::BOTH {
        for path in ["fragment", "compute"] {
            let (report, img) = render(
                app,
                scene,
                "64x48",
                &["--accel", "bvh", "--path", path],
                &dir.join(format!("{app:?}-{path}.png")),
            );
            let stack: u32 = report
                .variant
                .rsplit_once("/bvh")
                .and_then(|(_, n)| n.split('/').next()?.parse().ok())
                .unwrap_or_else(|| panic!("no BVH stack in {}", report.variant));
            assert!(
                stack > 24,
                "the test needs a tree deeper than 24 levels: {}",
                report.variant
            );
            let m = compare(&img, &truth).unwrap();
            assert!(
                m.above_8 <= 0.001,
                "{app:?} {path} ({}): {:.3}% of pixels off the reference by more than 8/255 (at most 0.1% allowed)",
                report.variant,
                100.0 * m.above_8
            );
        }
    }
    std::fs::remove_dir_all(dir).ok();
}

/// `--accel auto` runs the width its rule picks, in both apps: the 4-wide
/// tree, on a sphere list and on the teapot; `--accel bvh` the binary one.
#[test]
fn auto_runs_the_width_it_picks() {
    for app in App::BOTH {
        let dir = scratch("accel-auto-width");
        for (scene, set, width) in [
            ("spherelist", &["--set", "extra_spheres=1000"][..], 4),
            ("teapot", &[][..], 4),
            ("teapot", &["--accel", "bvh"][..], 2),
        ] {
            let (r, _) = render(app, scene, "64x64", set, &dir.join("a.png"));
            assert_eq!(r.bvh_width, Some(width), "{app:?} {scene}: auto's width");
        }
        std::fs::remove_dir_all(dir).ok();
    }
}
