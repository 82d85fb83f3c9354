//! The ray stack's size (`Features::ray_stack_entries`, the shader's
//! STACK_SIZE) against room for every ray: the size the shader declares must
//! drop no ray, and a size one smaller must, or the bound is loose.

use super::*;
use crate::scene::hard::SOURCE_DIR;

/// Every pixel of `scene` at `width` × `height` traced with room for
/// `capacity` pending rays (None: the shader's), as `render` frames it.
fn pixels(scene: &Scene, width: u32, height: u32, capacity: Option<usize>) -> Vec<DVec3> {
    let frame = RayFrame::local(scene, &scene.camera, width, height).rounded_to_f32();
    let scene = in_local_frame(scene).rounded_to_f32();
    let tracer = Tracer::new(&scene);
    let capacity = capacity.unwrap_or(tracer.ray_capacity());
    (0..width * height)
        .into_par_iter()
        .map(|i| {
            let dir = frame.dir((i % width) as f64, (i / width) as f64);
            trace_within(
                &tracer,
                frame.eye,
                dir,
                capacity,
                &mut RayKinds::default(),
                &mut |_| {},
            )
        })
        .collect()
}

/// The glass scenes: the box and the hard cases that hold glass, each at
/// its own max_depth and at the deepest a scene may ask for.
fn glass_scenes() -> Vec<(String, Scene)> {
    let mut paths = vec!["box".to_string()];
    for name in ["nested-glass", "inside-glass", "total-internal-reflection"] {
        paths.push(format!("{SOURCE_DIR}/{name}.toml"));
    }
    let mut scenes = Vec::new();
    for p in paths {
        let deepest = [(
            "max_depth".to_string(),
            crate::limits::MAX_DEPTH.to_string(),
        )];
        for set in [&[][..], &deepest[..]] {
            let scene = Scene::load(&p, set).unwrap();
            assert!(scene.features().glass, "{p}: no glass");
            scenes.push((format!("{p} {set:?}"), scene));
        }
    }
    scenes
}

#[test]
fn the_ray_stack_drops_no_ray() {
    for (name, scene) in glass_scenes() {
        let ample = pixels(&scene, 48, 36, Some(4 * crate::limits::MAX_DEPTH as usize));
        let declared = pixels(&scene, 48, 36, None);
        let differ = ample.iter().zip(&declared).filter(|(a, b)| a != b).count();
        assert_eq!(
            differ, 0,
            "{name}: {differ} pixels lose rays on the declared stack"
        );
    }
}

/// With every ray traced (min_weight 0), nested glass fills the stack (a ray
/// through nested spheres meets glass at every level): one entry fewer loses
/// rays, so the bound is tight. (The box's one sphere never fills it.)
#[test]
fn one_entry_fewer_drops_rays_through_nested_glass() {
    let set = [
        ("min_weight".to_string(), "0".to_string()),
        ("max_depth".to_string(), "3".to_string()),
    ];
    let scene = Scene::load(&format!("{SOURCE_DIR}/nested-glass.toml"), &set).unwrap();
    let entries = scene.features().ray_stack_entries(scene.max_depth) as usize;
    assert_eq!(entries, 3);
    let declared = pixels(&scene, 64, 48, None);
    let ample = pixels(&scene, 64, 48, Some(entries + 1));
    assert_eq!(declared, ample, "the declared stack drops rays");
    let short = pixels(&scene, 64, 48, Some(entries - 1));
    let differ = declared.iter().zip(&short).filter(|(a, b)| a != b).count();
    assert!(
        differ > 0,
        "nested glass never fills the ray stack: the bound is loose"
    );
}
