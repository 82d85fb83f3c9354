//! The two apps and the f64 reference render the same image: Vulkan vs OpenGL
//! ≥ 99.9 % of pixels within 1/255, each API vs the reference ≥ 99.5 %, no NaN,
//! and zero validation messages / GL debug errors in every render.

use twinray_common::gpu::layout::GpuTriangle;
use twinray_common::gpu::upload::UPLOAD_CHUNK_BYTES;
use twinray_common::reference;
use twinray_common::scene::Scene;
use twinray_tests::{
    assert_clean, assert_within_1, render, scratch, set_args, App, STANDARD_SCENES,
};

fn check(scene: &str, size: &str, set: &[(&str, &str)]) {
    let args = set_args(set);
    // Named by the overrides too: tests of one scene run in parallel.
    let dir = scratch(&format!("agree-{scene}{}", args.concat()));
    let extra: Vec<&str> = args.iter().map(String::as_str).collect();
    let sz = twinray_common::cli::parse_size(size).unwrap();
    let overrides: Vec<(String, String)> = set
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    let sc = Scene::load(scene, &overrides).unwrap();
    let reference = reference::render(&sc, sz.width, sz.height);
    assert_eq!(reference.nonfinite_pixels(), 0, "{scene}: reference NaN");
    let reference = reference.to_rgb8();

    let mut images = Vec::new();
    for app in App::BOTH {
        let (report, img) = render(app, scene, size, &extra, &dir.join(format!("{app:?}.png")));
        assert_clean(&report, &format!("{scene} {app:?}"));
        assert_eq!((report.width, report.height), (sz.width, sz.height));
        assert_eq!(report.scene.triangles, sc.triangles.len());
        assert_eq!(report.scene.spheres, sc.spheres.len());
        assert_within_1(
            &img,
            &reference,
            0.995,
            &format!("{scene} {app:?} vs reference"),
        );
        images.push(img);
    }
    assert_within_1(
        &images[0],
        &images[1],
        0.999,
        &format!("{scene} Vulkan vs OpenGL"),
    );
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn the_standard_scenes_agree() {
    for (scene, size, set) in STANDARD_SCENES {
        check(scene, size, set);
    }
}

/// A teapot whose triangle buffer is larger than one upload chunk: each app
/// fills it through its staging buffer in pieces, and a piece copied to the
/// wrong place moves triangles.
#[test]
fn teapot_larger_than_one_upload_chunk_agrees() {
    let set = [("tessellation", "100x90")];
    let overrides = [("tessellation".to_string(), "100x90".to_string())];
    let triangles = Scene::load("teapot", &overrides).unwrap().triangles.len();
    assert!(
        triangles * size_of::<GpuTriangle>() > UPLOAD_CHUNK_BYTES,
        "{triangles} triangles fit in one upload chunk"
    );
    check("teapot", "64x48", &set);
}

#[test]
fn generic_shader_renders_the_same_as_the_variant() {
    let dir = scratch("generic");
    for app in App::BOTH {
        let (_, variant) = render(app, "box", "96x72", &[], &dir.join("v.png"));
        let (report, generic) = render(app, "box", "96x72", &["--generic"], &dir.join("g.png"));
        // The deepest ray stack: MAX_DEPTH entries, as the box walks auto's tree.
        assert!(report.variant.contains("/stack16/"), "{}", report.variant);
        assert_within_1(
            &variant,
            &generic,
            0.9999,
            &format!("{app:?}: generic vs variant"),
        );
    }
}

#[test]
fn opengl_running_naga_spirv_matches_its_glsl() {
    // --gl-spirv loads the very SPIR-V Vulkan runs (GL_ARB_gl_spirv); the image must not change.
    let dir = scratch("gl-spirv");
    for scene in ["box", "spherelist"] {
        let (_, glsl) = render(App::OpenGl, scene, "96x72", &[], &dir.join("glsl.png"));
        let (report, spirv) = render(
            App::OpenGl,
            scene,
            "96x72",
            &["--gl-spirv"],
            &dir.join("spirv.png"),
        );
        assert!(report.variant.ends_with("(SPIR-V)"), "{}", report.variant);
        assert_within_1(&glsl, &spirv, 0.9999, &format!("{scene}: SPIR-V vs GLSL"));
    }
}
