//! Scene files that cannot be used: missing, malformed TOML, unknown keys,
//! bad values and meshes, each named by file, line or field.

use crate::common::{expect_both, headless, scene_file, strs};
use twinray_tests::scratch;

#[test]
fn missing_and_unknown_scenes() {
    expect_both(
        &["--headless", "--scene", "/no/such/scene.toml"],
        &[],
        2,
        &["/no/such/scene.toml", "does not exist"],
    );
    expect_both(
        &["--headless", "--scene", "kettle"],
        &[],
        2,
        &["'kettle'", "built-in"],
    );
}

#[test]
fn malformed_scene_names_line_and_column() {
    let dir = scratch("malformed");
    let p = scene_file(
        &dir,
        "bad.toml",
        "[[spheres]]\ncenter = [0.0, 0.0\nradius = 1.0\n",
    );
    expect_both(
        &strs(&headless(&p)),
        &[],
        2,
        &["bad.toml", "line 12, column"],
    );
}

#[test]
fn unknown_key_is_named() {
    let dir = scratch("unknown-key");
    let p = scene_file(
        &dir,
        "k.toml",
        "[[spheres]]\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\nmaterial = \"m\"\nglow = 2.0\n",
    );
    expect_both(&strs(&headless(&p)), &[], 2, &["k.toml", "glow", "line 14"]);
}

#[test]
fn bad_values_are_named() {
    let dir = scratch("bad-values");
    let cases = [
        ("nan.toml", "[[spheres]]\ncenter = [nan, 0.0, 0.0]\nradius = 1.0\nmaterial = \"m\"\n", "spheres[0].center"),
        ("neg.toml", "[[spheres]]\ncenter = [0.0, 0.0, 0.0]\nradius = -2.0\nmaterial = \"m\"\n", "spheres[0].radius = -2"),
        (
            "normal.toml",
            "[[triangles]]\nvertices = [[0.0,0.0,0.0],[1.0,0.0,0.0],[0.0,1.0,0.0]]\nnormals = [[0.0,0.0,0.0],[0.0,0.0,1.0],[0.0,0.0,1.0]]\nmaterial = \"m\"\n",
            "triangles[0].normals[0]",
        ),
        ("mat.toml", "[[spheres]]\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\nmaterial = \"unobtainium\"\n", "'unobtainium'"),
    ];
    for (file, body, what) in cases {
        let p = scene_file(&dir, file, body);
        expect_both(&strs(&headless(&p)), &[], 2, &[file, what]);
    }
}

#[test]
fn missing_and_broken_obj() {
    let dir = scratch("obj");
    let p = scene_file(
        &dir,
        "mesh.toml",
        "[[meshes]]\nobj = \"pot.obj\"\nmaterial = \"m\"\n",
    );
    expect_both(&strs(&headless(&p)), &[], 2, &["pot.obj", "cannot be read"]);
    std::fs::write(dir.join("pot.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n").unwrap();
    expect_both(&strs(&headless(&p)), &[], 2, &["pot.obj"]);
    std::fs::write(dir.join("pot.obj"), "v 1 2 x\nf 1 1 1\n").unwrap();
    expect_both(
        &strs(&headless(&p)),
        &[],
        2,
        &["pot.obj", "not a valid OBJ"],
    );
}

#[test]
fn unknown_numerics_value() {
    expect_both(
        &["--headless", "--set", "triangle=octagonal"],
        &[],
        2,
        &["--set triangle", "octagonal", "watertight"],
    );
    let dir = scratch("numerics-file");
    let p = scene_file(&dir, "n.toml", "[render]\noffset = \"far\"\n");
    expect_both(
        &strs(&headless(&p)),
        &[],
        2,
        &["n.toml", "render.offset", "'far'"],
    );
}
