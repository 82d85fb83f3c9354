//! Scene loading: the built-in scenes have the study's counts, and every kind of
//! bad scene input is refused with one sentence that names the culprit (exit 2).

use twinray_common::error::exit_code_of;
use twinray_common::scene::camera::{Frustum, RayFrame};
use twinray_common::scene::Scene;

fn set(kv: &[(&str, &str)]) -> Vec<(String, String)> {
    kv.iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect()
}

/// Triangles, spheres and lights.
fn counts(s: &Scene) -> (usize, usize, usize) {
    (s.triangles.len(), s.spheres.len(), s.lights.len())
}

#[test]
fn teapot_has_the_study_counts_and_its_sphere_is_out_of_view() {
    let s = Scene::load("teapot", &[]).unwrap();
    assert_eq!(counts(&s), (19_200, 1, 3));
    let f = Frustum::new(&RayFrame::new(&s.camera, 800, 600), 800, 600);
    let sp = &s.spheres[0];
    assert!(
        !f.sees_sphere(sp.center, sp.radius),
        "the teapot scene's sphere must be outside the view"
    );
}

#[test]
fn box_has_30_triangles_a_mirror_and_a_glass_sphere_and_one_light() {
    let s = Scene::load("box", &[]).unwrap();
    assert_eq!(counts(&s), (30, 2, 1));
    let mats: Vec<_> = s
        .spheres
        .iter()
        .map(|sp| &s.materials[sp.material as usize])
        .collect();
    assert!(
        mats.iter()
            .any(|m| m.reflectivity > 0.5 && m.transparency == 0.0),
        "a mirror sphere"
    );
    assert!(mats.iter().any(|m| m.transparency > 0.5), "a glass sphere");
}

#[test]
fn spherelist_has_6_triangles_one_visible_sphere_and_n_hidden_ones() {
    for n in [1u32, 10, 50, 100, 500, 1000, 2500, 5000, 10000] {
        let s = Scene::load("spherelist", &set(&[("extra_spheres", &n.to_string())])).unwrap();
        assert_eq!(s.triangles.len(), 6);
        assert_eq!(s.spheres.len(), 1 + n as usize);
        let visible = &s.spheres[0];
        for hidden in &s.spheres[1..] {
            let inside = (hidden.center - visible.center).length() + hidden.radius < visible.radius;
            assert!(inside, "extra spheres are hidden inside the visible one");
        }
    }
}

fn err_of(text: &str) -> (i32, String) {
    let dir = std::env::temp_dir();
    let e = Scene::from_toml("bad", text, &dir, &[]).unwrap_err();
    (exit_code_of(&e), format!("{e}"))
}

/// A scene that loads, which each bad input completes (shared with the apps'
/// bad-input tests).
const OK: &str = include_str!("../../tests/data/scene_head.toml");

#[test]
fn a_minimal_scene_loads() {
    let s = Scene::from_toml(
        "ok",
        &format!("{OK}[[spheres]]\ncenter=[0.0,0.0,0.0]\nradius=1.0\nmaterial=\"m\"\n"),
        std::path::Path::new("."),
        &[],
    )
    .unwrap();
    assert_eq!(s.spheres.len(), 1);
}

#[test]
fn malformed_toml_names_line_and_column() {
    let (code, msg) = err_of("[camera]\neye = [0.0, 0.0\n");
    assert_eq!(code, 2);
    assert!(msg.contains("line 2, column"), "{msg}");
}

/// Scene text with one fault each, and the words its refusal (exit 2) must say.
const BAD_SCENES: [(&str, &[&str]); 5] = [
    (
        "[[spheres]]\ncenter=[0.0,0.0,0.0]\nradius=1.0\nmaterial=\"m\"\ncolour=1\n",
        &["colour", "line 14"],
    ),
    (
        "[[spheres]]\ncenter=[nan,0.0,0.0]\nradius=1.0\nmaterial=\"m\"\n",
        &["spheres[0].center", "not finite"],
    ),
    (
        "[[spheres]]\ncenter=[0.0,0.0,0.0]\nradius=-1.0\nmaterial=\"m\"\n",
        &["spheres[0].radius = -1", "positive"],
    ),
    (
        "[[triangles]]\nvertices=[[0.0,0.0,0.0],[1.0,0.0,0.0],[0.0,1.0,0.0]]\nnormals=[[0.0,0.0,1.0],[0.0,0.0,0.0],[0.0,0.0,1.0]]\nmaterial=\"m\"\n",
        &["triangles[0].normals[1]", "zero length"],
    ),
    (
        "[[spheres]]\ncenter=[0.0,0.0,0.0]\nradius=1.0\nmaterial=\"gold\"\n",
        &["'gold'", "not a defined material"],
    ),
];

/// An unknown key (with its line), a NaN, a negative radius, a zero-length
/// normal and an unknown material are each refused, naming what is wrong.
#[test]
fn bad_scene_text_is_refused_naming_the_fault() {
    for (body, words) in BAD_SCENES {
        let (code, msg) = err_of(&format!("{OK}{body}"));
        assert_eq!(code, 2, "{body}: {msg}");
        assert!(words.iter().all(|w| msg.contains(w)), "{body}: {msg}");
    }
}

#[test]
fn missing_and_broken_obj_files_are_named() {
    let dir = std::env::temp_dir().join(format!("twinray-obj-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let text = format!("{OK}[[meshes]]\nobj=\"thing.obj\"\nmaterial=\"m\"\n");
    let e = Scene::from_toml("s", &text, &dir, &[]).unwrap_err();
    assert_eq!(exit_code_of(&e), 2);
    assert!(
        format!("{e}").contains("thing.obj") && format!("{e}").contains("cannot be read"),
        "{e}"
    );

    std::fs::write(
        dir.join("thing.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
    )
    .unwrap();
    let e = Scene::from_toml("s", &text, &dir, &[]).unwrap_err();
    assert_eq!(exit_code_of(&e), 2);
    assert!(format!("{e}").contains("thing.obj"), "{e}");

    std::fs::write(dir.join("thing.obj"), "v 0 0 zero\nf 1 1 1\n").unwrap();
    let e = Scene::from_toml("s", &text, &dir, &[]).unwrap_err();
    assert!(format!("{e}").contains("not a valid OBJ"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn unknown_scene_name_and_missing_file() {
    let e = Scene::load("kettle", &[]).unwrap_err();
    assert_eq!(exit_code_of(&e), 2);
    assert!(
        format!("{e}").contains("'kettle'") && format!("{e}").contains("teapot, box, spherelist"),
        "{e}"
    );
    let e = Scene::load("nowhere/scene.toml", &[]).unwrap_err();
    assert!(format!("{e}").contains("does not exist"), "{e}");
}

#[test]
fn overrides_are_checked() {
    let e = Scene::load("box", &set(&[("speed", "3")])).unwrap_err();
    assert_eq!(exit_code_of(&e), 2);
    assert!(format!("{e}").contains("unknown key 'speed'"), "{e}");
    let e = Scene::load("box", &set(&[("max_depth", "-2")])).unwrap_err();
    assert!(format!("{e}").contains("max_depth"), "{e}");
    let e = Scene::load("box", &set(&[("extra_spheres", "5")])).unwrap_err();
    assert!(format!("{e}").contains("no [extra_spheres]"), "{e}");
    let s = Scene::load("box", &set(&[("max_depth", "2")])).unwrap();
    assert_eq!(s.max_depth, 2);
}

#[test]
fn teapot_tessellation_override_scales_the_triangle_count() {
    for (t, n) in [("40x30", 76_800), ("80x60", 307_200)] {
        let s = Scene::load("teapot", &set(&[("tessellation", t)])).unwrap();
        assert_eq!(s.triangles.len(), n, "tessellation {t}");
    }
    let e = Scene::load("teapot", &set(&[("tessellation", "0x5")])).unwrap_err();
    assert_eq!(exit_code_of(&e), 2);
    assert!(format!("{e}").contains("tessellation"), "{e}");
    let e = Scene::load("box", &set(&[("tessellation", "40x30")])).unwrap_err();
    assert!(format!("{e}").contains("no Bezier-patch mesh"), "{e}");
}

#[test]
fn the_generators_obj_is_the_built_in_teapot() {
    // The scene tessellates teapot.bpt at load; twinray-gen-teapot writes the
    // same tessellation as OBJ with 6 decimals: the same triangles, to rounding.
    use twinray_common::scene::teapot::{
        parse_bpt, tessellate, to_obj, HEADER, STUDY_NU, STUDY_NV,
    };
    let bpt = include_str!("../../scenes/teapot.bpt");
    let mesh = tessellate(&parse_bpt(bpt).unwrap(), STUDY_NU, STUDY_NV);
    let dir = std::env::temp_dir().join(format!("twinray-teapot-obj-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("teapot.obj"), to_obj(&mesh, HEADER)).unwrap();
    let from_obj = Scene::from_toml(
        "obj",
        &format!("{}[[meshes]]\nobj = \"teapot.obj\"\nmaterial = \"m\"\n", OK),
        &dir,
        &[],
    )
    .unwrap();
    let built_in = Scene::load("teapot", &[]).unwrap();
    assert_eq!(from_obj.triangles.len(), built_in.triangles.len());
    for (a, b) in from_obj.triangles.iter().zip(&built_in.triangles) {
        for k in 0..3 {
            assert!((a.p[k] - b.p[k]).length() < 1e-5, "positions differ");
        }
    }
}
