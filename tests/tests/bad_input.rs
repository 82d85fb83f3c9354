//! Every kind of bad input gets one sentence naming what is wrong and the exit
//! code of the contract (2 bad input, 3 no usable driver) — from both apps, and
//! never a panic.

use std::path::Path;
use twinray_tests::{bin, fail, scratch, App};

const SCENE_HEAD: &str = r#"
[camera]
eye = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
[[materials]]
name = "m"
diffuse = [0.5, 0.5, 0.5]
[[lights]]
position = [0.0, 5.0, 5.0]
"#;

/// Runs both apps with `args` and checks the exit code and that the one error
/// line contains every word in `expect`.
fn expect_both(args: &[&str], env: &[(&str, &str)], code: i32, expect: &[&str]) {
    for app in App::BOTH {
        expect_one(&app.exe(), args, env, code, expect);
    }
}

fn expect_one(exe: &Path, args: &[&str], env: &[(&str, &str)], code: i32, expect: &[&str]) {
    let (got, stderr) = fail(exe, args, env);
    let name = exe.file_name().unwrap().to_string_lossy().to_string();
    assert_eq!(
        got, code,
        "{name} {args:?}: exit code {got}, stderr: {stderr}"
    );
    let errors: Vec<&str> = stderr.lines().filter(|l| l.contains("error")).collect();
    assert!(
        !errors.is_empty(),
        "{name} {args:?}: no error line in: {stderr}"
    );
    let line = errors[0];
    for word in expect {
        assert!(
            line.contains(word),
            "{name} {args:?}: error line lacks '{word}': {line}"
        );
    }
}

fn scene_file(dir: &Path, name: &str, body: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, format!("{SCENE_HEAD}{body}")).unwrap();
    p.to_str().unwrap().to_string()
}

fn headless(scene: &str) -> Vec<String> {
    ["--headless", "--size", "16x16", "--scene", scene]
        .iter()
        .map(|s| s.to_string())
        .collect()
}

fn strs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

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
fn bad_sizes() {
    // clap prints its own usage error naming the option; the exit code is 2.
    for app in App::BOTH {
        let (code, stderr) = fail(&app.exe(), &["--headless", "--size", "0x10"], &[]);
        assert_eq!(code, 2, "{stderr}");
        assert!(
            stderr.contains("--size") && stderr.contains("zero"),
            "{stderr}"
        );
    }
    expect_both(
        &["--headless", "--size", "20000x16"],
        &[],
        2,
        &["--size 20000x16", "limit"],
    );
}

#[test]
fn too_many_primitives_for_the_storage_buffer_limit() {
    // 5 million 32-byte spheres: 160 MB, above Mesa's 128 MiB limit (and most GPUs' 2^27..2^32).
    expect_both(
        &[
            "--headless",
            "--size",
            "16x16",
            "--scene",
            "spherelist",
            "--set",
            "extra_spheres=5000000",
        ],
        &[],
        2,
        &["spheres", "limit"],
    );
}

#[test]
fn gl_spirv_is_an_opengl_option_and_the_vulkan_knobs_are_checked() {
    expect_one(
        &bin("twinray-vk"),
        &["--headless", "--gl-spirv"],
        &[],
        2,
        &["--gl-spirv", "OpenGL"],
    );
    expect_one(
        &bin("twinray-vk"),
        &["--headless"],
        &[("TWINRAY_VK_MEMORY", "vram")],
        2,
        &["TWINRAY_VK_MEMORY", "'vram'"],
    );
    expect_one(
        &bin("twinray-vk"),
        &["--headless"],
        &[("TWINRAY_VK_WAIT", "spin")],
        2,
        &["TWINRAY_VK_WAIT", "'spin'"],
    );
}

#[test]
fn unknown_override_key() {
    expect_both(&["--headless", "--set", "warp=9"], &[], 2, &["warp"]);
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

#[test]
fn no_vulkan_driver_says_what_to_install() {
    let env = [
        ("VK_DRIVER_FILES", "/nonexistent/icd.json"),
        ("VK_ICD_FILENAMES", "/nonexistent/icd.json"),
    ];
    expect_one(
        &bin("twinray-vk"),
        &["--headless", "--size", "16x16"],
        &env,
        3,
        &["install"],
    );
}

#[test]
fn no_egl_device_says_what_to_install() {
    let env = [("__EGL_VENDOR_LIBRARY_FILENAMES", "/nonexistent/egl.json")];
    expect_one(
        &bin("twinray-gl"),
        &["--headless", "--size", "16x16"],
        &env,
        3,
        &["install"],
    );
}

#[test]
fn orchestrator_diff_and_render_errors() {
    let dir = scratch("diff");
    let a = dir.join("a.png");
    image::RgbImage::new(4, 4).save(&a).unwrap();
    let b = dir.join("b.png");
    image::RgbImage::new(5, 4).save(&b).unwrap();
    let tw = bin("twinray");
    expect_one(
        &tw,
        &["diff", a.to_str().unwrap(), "/no/such.png"],
        &[],
        2,
        &["/no/such.png"],
    );
    expect_one(
        &tw,
        &["diff", a.to_str().unwrap(), b.to_str().unwrap()],
        &[],
        2,
        &["differ in size"],
    );
    expect_one(
        &tw,
        &[
            "render",
            "--api",
            "reference",
            "--scene",
            "kettle",
            "--json",
        ],
        &[],
        2,
        &["'kettle'"],
    );
}

#[test]
fn bad_path_and_workgroup_options() {
    // A workgroup means nothing to the fragment path: said, not ignored.
    expect_both(
        &["--headless", "--size", "16x16", "--workgroup", "8x8"],
        &[],
        2,
        &["--workgroup", "--path compute"],
    );
    for app in App::BOTH {
        for args in [
            ["--path", "warp"],
            ["--workgroup", "0x8"],
            ["--workgroup", "64x64"],
        ] {
            let mut all = vec!["--headless", "--size", "16x16", "--path", "compute"];
            all.extend(args);
            let (code, stderr) = fail(&app.exe(), &all, &[]);
            assert_eq!(code, 2, "{args:?}: {stderr}");
            assert!(stderr.contains(args[0]), "{args:?}: {stderr}");
        }
    }
}
