//! Every kind of bad input gets one sentence naming what is wrong and the exit
//! code of the contract (2 bad input, 3 no usable driver) — from both apps, and
//! never a panic.
//!
//! Long file: one table of every malformed input, kept in one place so that a
//! reader sees at a glance which inputs are covered and a new case has one home.

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

/// Each app's knobs are options that can also come from `TWINRAY_*`
/// variables: a bad value names the variable (or the option) it came from, and
/// exits 2 before any work.
#[test]
fn each_knob_names_its_variable_or_option_and_the_bad_value() {
    let vk = bin("twinray-vk");
    let gl = bin("twinray-gl");
    let small = ["--headless", "--size", "16x12"];
    for (exe, variable, option, bad) in [
        (&vk, "TWINRAY_VK_DEVICE", "--vk-device", "no-such-gpu"),
        (&vk, "TWINRAY_VK_MEMORY", "--vk-memory", "vram"),
        (&vk, "TWINRAY_VK_VALIDATION", "--vk-validation", "maybe"),
        (&vk, "TWINRAY_VK_WAIT", "--vk-wait", "spin"),
        (&gl, "TWINRAY_GL_DEVICE", "--gl-device", "x"),
    ] {
        let quoted = format!("'{bad}'");
        expect_one(exe, &small, &[(variable, bad)], 2, &[variable, &quoted]);
        let on_the_command_line = format!("{option}={bad}");
        let mut args = small.to_vec();
        args.push(&on_the_command_line);
        expect_one(exe, &args, &[], 2, &[option, &quoted]);
    }
    // A device index the machine does not have is found only once the devices are listed.
    expect_one(
        &gl,
        &small,
        &[("TWINRAY_GL_DEVICE", "99")],
        2,
        &["TWINRAY_GL_DEVICE", "99"],
    );
    expect_one(
        &vk,
        &small,
        &[("TWINRAY_VK_DEVICE", "99")],
        2,
        &["TWINRAY_VK_DEVICE", "'99'"],
    );

    // The orchestrator's one knob: where the apps are.
    let tw = bin("twinray");
    let render = ["render", "--api", "vulkan", "--size", "16x12"];
    let nowhere = "/no/such/folder";
    expect_one(
        &tw,
        &render,
        &[("TWINRAY_BIN_DIR", nowhere)],
        2,
        &["TWINRAY_BIN_DIR", nowhere],
    );
    let empty = scratch("empty-bin-dir");
    let empty = empty.to_str().unwrap();
    expect_one(
        &tw,
        &render,
        &[("TWINRAY_BIN_DIR", empty)],
        2,
        &["TWINRAY_BIN_DIR", empty, "twinray-vk"],
    );
}

/// A knob belongs to one app: a Vulkan knob set for a whole comparison, even a
/// bad one, does not stop the OpenGL app, and the other way round.
#[test]
fn an_app_ignores_the_other_apps_knobs() {
    let small = ["--headless", "--size", "8x6"];
    let o = twinray_tests::run(&bin("twinray-gl"), &small, &[("TWINRAY_VK_MEMORY", "vram")]);
    assert!(
        o.status.success(),
        "twinray-gl read TWINRAY_VK_MEMORY: {o:?}"
    );
    let o = twinray_tests::run(&bin("twinray-vk"), &small, &[("TWINRAY_GL_DEVICE", "x")]);
    assert!(
        o.status.success(),
        "twinray-vk read TWINRAY_GL_DEVICE: {o:?}"
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

// ------------------------------------------------------------------ the table

/// A small valid scene that each table case breaks in one place.
const BASE: &str = r#"[camera]
eye = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
fov_y = 45.0
[render]
max_depth = 3
epsilon = 1e-4
background = [0.1, 0.1, 0.1]
[[materials]]
name = "m"
diffuse = [0.5, 0.5, 0.5]
shininess = 32.0
ior = 1.5
[[lights]]
position = [0.0, 5.0, 5.0]
color = [1.0, 1.0, 1.0]
[[spheres]]
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "m"
"#;

const CUBE_OBJ: &str =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvn 0 0 1\nf 1//1 2//1 3//1\nf 1//1 2//1 4//1\n";

/// What a case gives the three tools.
enum Input {
    /// `BASE` with `find` replaced by `replace` (each pair), as scene.toml.
    Edit(&'static [(&'static str, &'static str)]),
    /// `BASE` with text appended, as scene.toml.
    Append(&'static str),
    /// `BASE` plus a mesh section naming `mesh.obj` / `mesh.bpt`, with that file's bytes.
    Mesh(&'static str, &'static [u8]),
    /// Raw bytes as scene.toml.
    Raw(&'static [u8]),
    /// No scene file: only options (the built-in box unless they name one).
    Options,
}

struct Case {
    name: &'static str,
    input: Input,
    /// Extra arguments; `{dir}` becomes the case's folder. Without `--out` in
    /// them, `--out {dir}/out.png` is added (and must not appear).
    args: &'static [&'static str],
    /// Words the error line must contain (field, line or option, and value).
    expect: &'static [&'static str],
}

const fn edit(
    name: &'static str,
    pairs: &'static [(&'static str, &'static str)],
    expect: &'static [&'static str],
) -> Case {
    Case {
        name,
        input: Input::Edit(pairs),
        args: &[],
        expect,
    }
}

const fn append(name: &'static str, text: &'static str, expect: &'static [&'static str]) -> Case {
    Case {
        name,
        input: Input::Append(text),
        args: &[],
        expect,
    }
}

const fn mesh(
    name: &'static str,
    section: &'static str,
    bytes: &'static [u8],
    expect: &'static [&'static str],
) -> Case {
    Case {
        name,
        input: Input::Mesh(section, bytes),
        args: &[],
        expect,
    }
}

const fn opts(
    name: &'static str,
    args: &'static [&'static str],
    expect: &'static [&'static str],
) -> Case {
    Case {
        name,
        input: Input::Options,
        args,
        expect,
    }
}

const OBJ: &str = "[[meshes]]\nobj = \"mesh.obj\"\nmaterial = \"m\"\n";
const BPT: &str = "[[meshes]]\nbpt = \"mesh.bpt\"\nmaterial = \"m\"\n";

fn cases() -> Vec<Case> {
    vec![
        // Arrays of the wrong length (serde's fixed arrays used to drop the rest).
        edit("eye-4", &[("eye = [0.0, 0.0, 5.0]", "eye = [0.0, 0.0, 5.0, 1.0]")], &["scene.toml", "line 2", "invalid length 4"]),
        edit("look-at-2", &[("look_at = [0.0, 0.0, 0.0]", "look_at = [0.0, 0.0]")], &["line 3", "invalid length 2"]),
        edit("background-4", &[("background = [0.1, 0.1, 0.1]", "background = [0.1, 0.1, 0.1, 0.1]")], &["line 8", "invalid length 4"]),
        edit("diffuse-4", &[("diffuse = [0.5, 0.5, 0.5]", "diffuse = [0.5, 0.5, 0.5, 0.5]")], &["line 11", "invalid length 4"]),
        edit("light-color-4", &[("color = [1.0, 1.0, 1.0]", "color = [1.0, 1.0, 1.0, 1.0]")], &["line 16", "invalid length 4"]),
        edit("center-2", &[("center = [0.0, 0.0, 0.0]", "center = [0.0, 0.0]")], &["line 18", "invalid length 2"]),
        append("triangle-4-vertices", "[[triangles]]\nvertices = [[0.0,0.0,0.0],[1.0,0.0,0.0],[0.0,1.0,0.0],[1.0,1.0,0.0]]\nmaterial = \"m\"\n", &["line 22", "invalid length 4"]),
        append("triangle-vertex-2", "[[triangles]]\nvertices = [[0.0,0.0],[1.0,0.0,0.0],[0.0,1.0,0.0]]\nmaterial = \"m\"\n", &["line 22", "invalid length 2"]),
        append("quad-5-corners", "[[quads]]\ncorners = [[0.0,0.0,0.0],[1.0,0.0,0.0],[1.0,1.0,0.0],[0.0,1.0,0.0],[0.5,0.5,0.0]]\nmaterial = \"m\"\n", &["line 22", "invalid length 5"]),
        append("normals-2", "[[triangles]]\nvertices = [[0.0,0.0,0.0],[1.0,0.0,0.0],[0.0,1.0,0.0]]\nnormals = [[0.0,0.0,1.0],[0.0,0.0,1.0]]\nmaterial = \"m\"\n", &["line 23", "invalid length 2"]),
        // Values: not finite, out of range, or finite in f64 but not in f32.
        edit("eye-nan", &[("eye = [0.0, 0.0, 5.0]", "eye = [nan, 0.0, 5.0]")], &["camera.eye", "not finite"]),
        edit("eye-far", &[("eye = [0.0, 0.0, 5.0]", "eye = [0.0, 0.0, 1e300]")], &["camera.eye", "coordinate limit"]),
        edit("fov-0", &[("fov_y = 45.0", "fov_y = 0.0")], &["camera.fov_y", "= 0"]),
        edit("fov-180", &[("fov_y = 45.0", "fov_y = 180.0")], &["camera.fov_y", "= 180"]),
        edit("up-parallel", &[("fov_y = 45.0", "fov_y = 45.0\nup = [0.0, 0.0, 1.0]")], &["camera.up", "parallel"]),
        edit("depth-0", &[("max_depth = 3", "max_depth = 0")], &["render.max_depth", "= 0"]),
        edit("depth-17", &[("max_depth = 3", "max_depth = 17")], &["render.max_depth", "= 17"]),
        edit("depth-negative", &[("max_depth = 3", "max_depth = -1")], &["line 6", "-1"]),
        edit("epsilon-0", &[("epsilon = 1e-4", "epsilon = 0.0")], &["render.epsilon", "positive"]),
        edit("epsilon-f32-zero", &[("epsilon = 1e-4", "epsilon = 1e-300")], &["render.epsilon", "1e-300", "f32"]),
        edit("min-weight-negative", &[("epsilon = 1e-4", "epsilon = 1e-4\nmin_weight = -1.0")], &["render.min_weight", "-1"]),
        edit("background-f32-inf", &[("background = [0.1, 0.1, 0.1]", "background = [1e300, 0.1, 0.1]")], &["render.background", "limit"]),
        edit("offset-unknown", &[("epsilon = 1e-4", "epsilon = 1e-4\noffset = \"far\"")], &["render.offset", "'far'"]),
        edit("render-unknown-key", &[("max_depth = 3", "max_depth = 3\nglow = 1")], &["line 7", "glow"]),
        edit("diffuse-f32-inf", &[("diffuse = [0.5, 0.5, 0.5]", "diffuse = [1e300, 0.5, 0.5]")], &["materials[0]", "diffuse", "limit"]),
        edit("diffuse-negative", &[("diffuse = [0.5, 0.5, 0.5]", "diffuse = [-0.5, 0.5, 0.5]")], &["materials[0]", "diffuse", "negative"]),
        edit("ior-f32-zero", &[("ior = 1.5", "ior = 1e-300")], &["materials[0]", "ior", "1e-300"]),
        edit("ior-0", &[("ior = 1.5", "ior = 0.0")], &["materials[0]", "ior", "positive"]),
        edit("ior-huge", &[("ior = 1.5", "ior = 1e300")], &["materials[0]", "ior"]),
        edit("shininess-negative", &[("shininess = 32.0", "shininess = -1.0")], &["materials[0]", "shininess"]),
        edit("shininess-f32-inf", &[("shininess = 32.0", "shininess = 1e300")], &["materials[0]", "shininess", "f32"]),
        edit("reflectivity-2", &[("ior = 1.5", "ior = 1.5\nreflectivity = 2.0")], &["materials[0]", "reflectivity", "= 2"]),
        edit("mirror-plus-glass", &[("ior = 1.5", "ior = 1.5\nreflectivity = 0.6\ntransparency = 0.6")], &["materials[0]", "reflectivity + transparency"]),
        append("material-twice", "[[materials]]\nname = \"m\"\n", &["material 'm'", "twice"]),
        edit("light-color-f32-inf", &[("color = [1.0, 1.0, 1.0]", "color = [1e300, 1.0, 1.0]")], &["lights[0].color", "limit"]),
        edit("light-position-inf", &[("position = [0.0, 5.0, 5.0]", "position = [inf, 5.0, 5.0]")], &["lights[0].position", "not finite"]),
        edit("radius-negative", &[("radius = 1.0", "radius = -2.0")], &["spheres[0].radius", "-2"]),
        edit("radius-f32-zero", &[("radius = 1.0", "radius = 1e-300")], &["spheres[0].radius", "1e-300"]),
        edit("radius-huge", &[("radius = 1.0", "radius = 1e300")], &["spheres[0].radius", "1e300"]),
        edit("material-unknown", &[("material = \"m\"", "material = \"unobtainium\"")], &["spheres[0].material", "'unobtainium'"]),
        append("normal-zero", "[[triangles]]\nvertices = [[0.0,0.0,0.0],[1.0,0.0,0.0],[0.0,1.0,0.0]]\nnormals = [[0.0,0.0,0.0],[0.0,0.0,1.0],[0.0,0.0,1.0]]\nmaterial = \"m\"\n", &["triangles[0].normals[0]", "zero length"]),
        append("quad-corner-far", "[[quads]]\ncorners = [[0.0,0.0,0.0],[1.0,0.0,0.0],[1.0,1.0,0.0],[0.0,1e19,0.0]]\nmaterial = \"m\"\n", &["quads[0].corners[3]", "coordinate limit"]),
        append("extra-spheres-4e9", "[extra_spheres]\ncount = 4000000000\ncenter = [0.0, 0.0, 0.0]\nradius = 0.5\nmaterial = \"m\"\n", &["extra_spheres.count", "4000000000", "limit"]),
        append("extra-spheres-5e9", "[extra_spheres]\ncount = 5000000000\ncenter = [0.0, 0.0, 0.0]\nradius = 0.5\nmaterial = \"m\"\n", &["line 22", "5000000000"]),
        append("unknown-table", "[lighting]\nx = 1\n", &["line 21", "lighting"]),
        append("syntax", "[[spheres]]\ncenter = [0.0, 0.0\n", &["line 22"]),
        edit("no-materials", &[("[[materials]]\nname = \"m\"", "[[nomaterials]]\nname = \"m\"")], &["scene.toml", "nomaterials"]),
        Case { name: "non-utf8-scene", input: Input::Raw(b"[camera]\neye = [0.0, 0.0, 5.0]\nlook_at = [0.0, \xff0.0, 0.0]\n"), args: &[], expect: &["scene.toml", "line 3, column 17", "UTF-8"] },
        // Meshes.
        mesh("obj-missing", "[[meshes]]\nobj = \"absent.obj\"\nmaterial = \"m\"\n", b"", &["meshes[0].obj", "absent.obj", "cannot be read"]),
        mesh("obj-face-index", OBJ, b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n", &["meshes[0].obj", "mesh.obj"]),
        mesh("obj-bad-number", OBJ, b"v 1 2 x\nf 1 1 1\n", &["mesh.obj", "not a valid OBJ"]),
        mesh("obj-vertex-f32-inf", OBJ, b"v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n", &["mesh.obj", "vertex 2"]),
        mesh("obj-normal-zero", OBJ, b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 0\nf 1//1 2//1 3//1\n", &["mesh.obj", "face 1 normal"]),
        mesh("obj-no-faces", OBJ, b"v 0 0 0\nv 1 0 0\n", &["mesh.obj", "no faces"]),
        mesh("obj-non-utf8", OBJ, b"v 0 0 0\nv 1 0 0\nv 0 \xfe1 0\nf 1 2 3\n", &["mesh.obj", "line 3, column 5", "UTF-8"]),
        mesh("obj-scaled-far", "[[meshes]]\nobj = \"mesh.obj\"\nmaterial = \"m\"\nscale = 1e17\ntranslate = [0.0, 0.0, 0.0]\n", b"v 0 0 0\nv 100 0 0\nv 0 1 0\nf 1 2 3\n", &["meshes[0]", "face 1", "coordinate limit"]),
        mesh("mesh-scale-0", "[[meshes]]\nobj = \"mesh.obj\"\nmaterial = \"m\"\nscale = 0.0\n", CUBE_OBJ.as_bytes(), &["meshes[0].scale", "positive"]),
        mesh("mesh-scale-f32-zero", "[[meshes]]\nobj = \"mesh.obj\"\nmaterial = \"m\"\nscale = 1e-300\n", CUBE_OBJ.as_bytes(), &["meshes[0].scale", "1e-300"]),
        mesh("mesh-translate-4", "[[meshes]]\nobj = \"mesh.obj\"\nmaterial = \"m\"\ntranslate = [0.0, 0.0, 0.0, 0.0]\n", CUBE_OBJ.as_bytes(), &["line 24", "invalid length 4"]),
        mesh("mesh-obj-and-bpt", "[[meshes]]\nobj = \"mesh.obj\"\nbpt = \"mesh.obj\"\nmaterial = \"m\"\n", CUBE_OBJ.as_bytes(), &["meshes[0]", "either"]),
        mesh("bpt-malformed", BPT, b"1\n3 3\n0 0 0\n", &["meshes[0].bpt", "mesh.bpt", "not a valid patch file"]),
        mesh("bpt-tessellation-0", "[[meshes]]\nbpt = \"mesh.bpt\"\nmaterial = \"m\"\ntessellation = [0, 5]\n", b"0\n", &["meshes[0].tessellation", "0x5"]),
        mesh("bpt-tessellation-3", "[[meshes]]\nbpt = \"mesh.bpt\"\nmaterial = \"m\"\ntessellation = [4, 4, 4]\n", b"0\n", &["line 24", "invalid length 3"]),
        // Files that are not scene files.
        opts("scene-missing", &["--scene", "{dir}/absent.toml"], &["absent.toml", "does not exist"]),
        opts("scene-unknown-name", &["--scene", "kettle"], &["'kettle'", "built-in"]),
        opts("scene-dev-zero", &["--scene", "/dev/zero"], &["/dev/zero", "not a regular file"]),
        opts("scene-folder", &["--scene", "{dir}/"], &["not a regular file"]),
        Case { name: "scene-too-large", input: Input::Raw(b""), args: &["--grow-scene"], expect: &["scene.toml", "larger than the limit"] },
        // Options.
        opts("size-zero", &["--size", "0x16"], &["--size", "zero"]),
        opts("size-negative", &["--size", "-64x48"], &["--size", "negative"]),
        opts("size-65536-squared", &["--size", "65536x65536"], &["--size", "65536x65536"]),
        opts("size-too-wide", &["--size", "70000x16"], &["--size", "70000x16"]),
        opts("size-not-a-size", &["--size", "big"], &["--size", "'big'"]),
        opts("set-unknown", &["--set", "warp=9"], &["--set warp", "known keys"]),
        opts("set-no-equals", &["--set", "max_depth"], &["--set", "KEY=VALUE"]),
        opts("set-depth-0", &["--set", "max_depth=0"], &["--set max_depth", "= 0"]),
        opts("set-depth-99", &["--set", "max_depth=99"], &["--set max_depth", "= 99"]),
        opts("set-epsilon-f32-zero", &["--set", "epsilon=1e-300"], &["--set epsilon", "1e-300"]),
        opts("set-fov-200", &["--set", "fov_y=200"], &["--set fov_y", "200"]),
        opts("set-min-weight-nan", &["--set", "min_weight=NaN"], &["--set min_weight", "NaN"]),
        opts("set-extra-4e9", &["--scene", "spherelist", "--set", "extra_spheres=4000000000"], &["--set extra_spheres", "4000000000", "limit"]),
        opts("set-extra-overflow", &["--scene", "spherelist", "--set", "extra_spheres=99999999999"], &["--set extra_spheres", "99999999999"]),
        opts("set-extra-no-section", &["--set", "extra_spheres=5"], &["--set extra_spheres", "[extra_spheres]"]),
        opts("set-triangle-unknown", &["--set", "triangle=octagonal"], &["--set triangle", "octagonal"]),
        opts("set-tessellation-0", &["--scene", "teapot", "--set", "tessellation=0x5"], &["--set tessellation", "0x5"]),
        opts("frames-0", &["--frames", "0"], &["--frames", "0"]),
        opts("path-unknown", &["--path", "warp"], &["--path", "warp"]),
        opts("accel-unknown", &["--accel", "fast"], &["--accel", "fast"]),
        opts("workgroup-on-fragment", &["--workgroup", "8x8"], &["--workgroup", "--path compute"]),
        // Output paths: refused before any render.
        opts("out-folder", &["--out", "{dir}"], &["--out", "is a folder"]),
        opts("out-missing-folder", &["--out", "{dir}/no/such/x.png"], &["--out", "does not exist"]),
        opts("out-dev-full", &["--out", "/dev/full"], &["--out", "/dev/full", "not a regular file"]),
        opts("out-unwritable", &["--out", "/proc/twinray.png"], &["--out", "/proc/twinray.png", "not writable"]),
        opts("out-empty", &["--out", ""], &["--out"]),
    ]
}

/// Writes a case's input files into `dir`; returns the --scene argument, if any.
fn write_input(case: &Case, dir: &Path) -> Option<String> {
    let scene = dir.join("scene.toml");
    let text = |s: String| s.into_bytes();
    let bytes = match &case.input {
        Input::Options => return None,
        Input::Edit(pairs) => {
            let mut s = BASE.to_string();
            for (find, replace) in pairs.iter() {
                assert!(
                    s.contains(find),
                    "{}: '{find}' is not in the base scene",
                    case.name
                );
                s = s.replacen(find, replace, 1);
            }
            text(s)
        }
        Input::Append(more) => text(format!("{BASE}{more}")),
        Input::Mesh(section, bytes) => {
            let file = if section.contains("bpt = ") {
                "mesh.bpt"
            } else {
                "mesh.obj"
            };
            if !bytes.is_empty() {
                std::fs::write(dir.join(file), bytes).unwrap();
            }
            text(format!("{BASE}{section}"))
        }
        // 17 MiB of spaces after a valid scene: valid TOML, over the size limit.
        Input::Raw(b) if case.args.contains(&"--grow-scene") => {
            let mut v = BASE.as_bytes().to_vec();
            v.extend_from_slice(b);
            v.resize(17 << 20, b' ');
            v
        }
        Input::Raw(b) => b.to_vec(),
    };
    std::fs::write(&scene, bytes).unwrap();
    Some(scene.to_str().unwrap().to_string())
}

fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|r| {
            r.map(|e| e.unwrap().file_name().to_string_lossy().to_string())
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// One case against one tool: exit 2 (not a signal, not a panic), the error
/// line names what is wrong, no file appears, and all within 10 s.
fn check(case: &Case, tool: &str, dir: &Path) -> Result<(), String> {
    let scene = write_input(case, dir);
    let dir_s = dir.to_str().unwrap();
    let mut args: Vec<String> = vec!["--headless".into()];
    if !case.args.contains(&"--size") {
        args.extend(["--size".into(), "16x16".into()]);
    }
    if let Some(s) = &scene {
        args.extend(["--scene".into(), s.clone()]);
    }
    for a in case.args.iter().filter(|a| **a != "--grow-scene") {
        args.push(a.replace("{dir}", dir_s));
    }
    if !case.args.contains(&"--out") {
        args.extend(["--out".into(), format!("{dir_s}/out.png")]);
    }
    let (exe, mut all) = match tool {
        "reference" => (
            bin("twinray"),
            vec!["render".to_string(), "--api".into(), "reference".into()],
        ),
        app => (bin(app), vec![]),
    };
    all.extend(args);
    let before = listing(dir);
    let start = std::time::Instant::now();
    let o = twinray_tests::run(
        &exe,
        &all.iter().map(String::as_str).collect::<Vec<_>>(),
        &[],
    );
    let secs = start.elapsed().as_secs_f64();
    let stderr = String::from_utf8_lossy(&o.stderr).to_string();
    let at = format!("{} / {tool} {all:?}", case.name);
    let Some(code) = o.status.code() else {
        return Err(format!("{at}: killed by a signal ({}): {stderr}", o.status));
    };
    if stderr.contains("panicked") {
        return Err(format!("{at}: panicked: {stderr}"));
    }
    if code != 2 {
        return Err(format!("{at}: exit code {code}, not 2: {stderr}"));
    }
    if secs > 10.0 {
        return Err(format!("{at}: took {secs:.1} s"));
    }
    let Some(line) = stderr.lines().find(|l| l.contains("error")) else {
        return Err(format!("{at}: no error line in: {stderr}"));
    };
    if let Some(word) = case.expect.iter().find(|w| !line.contains(*w)) {
        return Err(format!("{at}: the error line lacks '{word}': {line}"));
    }
    let after = listing(dir);
    if after != before {
        return Err(format!("{at}: files left behind: {before:?} -> {after:?}"));
    }
    Ok(())
}

#[test]
fn table_of_bad_inputs_for_all_three_tools() {
    let cases = cases();
    assert!(cases.len() >= 60, "{} cases", cases.len());
    let root = scratch("table");
    let tools = ["twinray-vk", "twinray-gl", "reference"];
    let failures: Vec<String> = std::thread::scope(|s| {
        let handles: Vec<_> = tools
            .iter()
            .map(|tool| {
                let (cases, root) = (&cases, &root);
                s.spawn(move || {
                    let mut failures = Vec::new();
                    for case in cases {
                        let dir = root.join(format!("{tool}-{}", case.name));
                        std::fs::create_dir_all(&dir).unwrap();
                        if let Err(e) = check(case, tool, &dir) {
                            failures.push(e);
                        }
                    }
                    failures
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap())
            .collect()
    });
    let _ = std::fs::remove_dir_all(&root);
    assert!(
        failures.is_empty(),
        "{} of {} runs failed:\n{}",
        failures.len(),
        cases.len() * tools.len(),
        failures.join("\n")
    );
}

/// A full disk: the write fails after the render, and must leave no file (not a
/// 0-byte or truncated PNG) and exit 2 naming --out. A 12 KiB tmpfs is the full
/// disk; mounting one needs root (CI runs as root), so elsewhere this says it is
/// skipped rather than pass.
#[test]
fn a_full_disk_leaves_no_file() {
    let dir = scratch("full-disk");
    let mnt = dir.join("full");
    std::fs::create_dir_all(&mnt).unwrap();
    let mounted = std::process::Command::new("mount")
        .args([
            "-t",
            "tmpfs",
            "-o",
            "size=12k",
            "tmpfs",
            mnt.to_str().unwrap(),
        ])
        .output()
        .is_ok_and(|o| o.status.success());
    if !mounted {
        eprintln!("SKIPPED: cannot mount a tmpfs here (needs root)");
        return;
    }
    let out = mnt.join("box.png");
    let out_s = out.to_str().unwrap();
    let args = [
        "--headless",
        "--scene",
        "box",
        "--size",
        "320x240",
        "--out",
        out_s,
    ];
    let mut results = Vec::new();
    for tool in ["twinray-vk", "twinray-gl", "reference"] {
        let (exe, mut all) = match tool {
            "reference" => (bin("twinray"), vec!["render", "--api", "reference"]),
            t => (bin(t), vec![]),
        };
        all.extend(args);
        let (code, stderr) = fail(&exe, &all, &[]);
        results.push((tool, code, stderr, listing(&mnt)));
    }
    let _ = std::process::Command::new("umount").arg(&mnt).status();
    for (tool, code, stderr, left) in results {
        assert_eq!(code, 2, "{tool}: {stderr}");
        assert!(
            stderr.contains("--out") && stderr.contains("No space left"),
            "{tool}: {stderr}"
        );
        assert!(left.is_empty(), "{tool} left {left:?} on the full disk");
    }
}
