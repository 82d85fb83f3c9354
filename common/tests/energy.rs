//! Energy: no ray the f64 reference traces carries more weight than the ray it
//! came from. The shader and the reference share their shading model, so a
//! model that makes light (a Fresnel term above 1) renders the same wrong image
//! in all three and no comparison between them can see it; this walks the
//! reference's ray trees (`reference::worst_split`) instead, over every
//! built-in and hard scene and random scenes whose triangles are glass with
//! tilted vertex normals.

use glam::DVec3;
use std::path::Path;
use twinray_common::reference::worst_split;
use twinray_common::scene::hard;
use twinray_common::scene::Scene;

/// f64 rounding of weights near 1; a Fresnel term above 1 overshoots by far more.
const SLACK: f64 = 1e-9;

fn assert_no_gain(scene: &Scene, width: u32, height: u32) {
    if let Some((x, y, s)) = worst_split(scene, width, height) {
        assert!(
            s.gain() <= 1.0 + SLACK && s.reflected >= 0.0 && s.refracted >= 0.0,
            "{}: at pixel ({x}, {y}) of {width}x{height} a ray of weight {} sends on {} reflected \
             and {} refracted ({}x what arrived)",
            scene.name,
            s.incoming,
            s.reflected,
            s.refracted,
            s.gain()
        );
    }
}

/// A glass triangle seen at 45 degrees whose vertex normals lean 72 degrees
/// the same way: at the centre pixel the interpolated normal faces away from
/// the ray, where the old model gave Fresnel terms far above 1.
const TILTED_GLASS: &str = r#"
[camera]
eye = [-3.0, 0.0, 3.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 30.0

[render]
max_depth = 4

[[materials]]
name = "glass"
transparency = 0.9
ior = 1.5

[[lights]]
position = [0.0, 4.0, 4.0]

[[triangles]]
vertices = [[-2.0, -2.0, 0.0], [2.0, -2.0, 0.0], [0.0, 2.0, 0.0]]
normals = [[0.95, 0.0, 0.3], [0.95, 0.0, 0.3], [0.95, 0.0, 0.3]]
material = "glass"
"#;

#[test]
fn a_tilted_normal_on_glass_makes_no_light() {
    let scene = Scene::from_toml("tilted-glass", TILTED_GLASS, Path::new("."), &[]).unwrap();
    assert!(
        worst_split(&scene, 33, 33).is_some(),
        "the glass is in view"
    );
    assert_no_gain(&scene, 33, 33);
}

#[test]
fn built_in_and_hard_scenes_make_no_light() {
    for name in ["box", "spherelist", "teapot"] {
        assert_no_gain(&Scene::load(name, &[]).unwrap(), 40, 30);
    }
    for case in hard::list(Path::new(hard::SOURCE_DIR)).unwrap() {
        assert_no_gain(
            &Scene::load(case.path.to_str().unwrap(), &[]).unwrap(),
            32,
            32,
        );
    }
}

/// SplitMix64: the random scenes' own generator is private, and any
/// reproducible stream will do for tilting normals.
fn next(state: &mut u64) -> f64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
}

#[test]
fn random_scenes_with_tilted_glass_normals_make_no_light() {
    let mut glass_hits = 0;
    for seed in 0..24u64 {
        let mut scene = Scene::load(&format!("random:{seed}"), &[]).unwrap();
        let glass = scene
            .materials
            .iter()
            .position(|m| m.transparency > 0.0)
            .expect("random scenes hold glass") as u32;
        let mut state = seed;
        for tri in &mut scene.triangles {
            // Half the triangles become glass; every vertex normal leans up
            // to about 60 degrees off the face, in a random direction.
            if next(&mut state) < 0.5 {
                tri.material = glass;
            }
            let face = (tri.p[1] - tri.p[0]).cross(tri.p[2] - tri.p[0]).normalize();
            for n in &mut tri.n {
                let lean = DVec3::new(next(&mut state), next(&mut state), next(&mut state));
                *n = (face + 3.0 * (lean - 0.5)).normalize();
            }
        }
        glass_hits += usize::from(worst_split(&scene, 32, 24).is_some());
        assert_no_gain(&scene, 32, 24);
    }
    assert!(
        glass_hits > 0,
        "no random scene's rays reached glass or a mirror"
    );
}
