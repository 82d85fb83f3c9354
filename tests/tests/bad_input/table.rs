//! The table of every malformed input — scene files, meshes, files that are
//! not scene files, options, output paths — each run against all three tools
//! (both apps and the f64 reference): exit 2, one error line naming what is
//! wrong, no file left behind, all within 10 s.

use crate::common::listing;
use std::path::Path;
use twinray_tests::{bin, scratch};

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
        mesh("obj-face-index", OBJ, b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n", &["meshes[0].obj", "mesh.obj", "line 4", "vertex 7"]),
        mesh("obj-index-0", OBJ, b"v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 0 1 2\n", &["mesh.obj", "line 5", "start at 1"]),
        mesh("obj-relative-too-far", OBJ, b"v 0 0 0\nv 1 0 0\nf -1 -2 -3\n", &["mesh.obj", "line 3", "counts back"]),
        mesh("obj-bad-number", OBJ, b"v 1 2 x\nf 1 1 1\n", &["mesh.obj", "line 1", "not a valid OBJ"]),
        mesh("obj-bad-normal", OBJ, b"v 0 0 0\nvn 0 0\n", &["mesh.obj", "line 2", "`vn` needs three numbers"]),
        mesh("obj-vertex-f32-inf", OBJ, b"v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n", &["mesh.obj", "line 2", "vertex 2"]),
        mesh("obj-normal-zero", OBJ, b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 0\nf 1//1 2//1 3//1\n", &["mesh.obj", "line 5", "normal 1 has zero length"]),
        mesh("obj-face-1", OBJ, b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1\n", &["mesh.obj", "line 5", "one vertex"]),
        mesh("obj-face-2", OBJ, b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\nf 1 2 3\n", &["mesh.obj", "line 4", "two vertices"]),
        mesh("obj-line-element", OBJ, b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nl 1 2\n", &["mesh.obj", "line 5", "line element"]),
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
        opts("frames-0", &["--frames", "0"], &["--frames", "'0'", "from 1 to 100000"]),
        opts("frames-negative", &["--frames", "-1"], &["--frames", "'-1'", "from 1 to 100000"]),
        opts("path-unknown", &["--path", "warp"], &["--path", "warp"]),
        opts("accel-unknown", &["--accel", "fast"], &["--accel", "fast"]),
        opts("workgroup-on-fragment", &["--workgroup", "8x8"], &["--workgroup", "--path compute"]),
        opts("ulp-op-unknown", &["--experiment", "ulp", "--ulp-op", "tan"], &["--ulp-op", "tan"]),
        opts("ulp-op-without-probe", &["--ulp-op", "div"], &["--ulp-op"]),
        // Output paths: refused before any render.
        opts("out-folder", &["--out", "{dir}"], &["--out", "is a folder"]),
        opts("out-missing-folder", &["--out", "{dir}/no/such/x.png"], &["--out", "does not exist"]),
        opts("out-dev-full", &["--out", "/dev/full"], &["--out", "/dev/full", "not a regular file"]),
        opts("out-unwritable", &["--out", "/proc/twinray.png"], &["--out", "/proc/twinray.png", "not writable"]),
        opts("out-empty", &["--out", ""], &["--out"]),
        opts("out-trailing-slash", &["--out", "{dir}/new/"], &["--out", "new/", "ends with '/'"]),
        // An output that names an input would replace it.
        Case { name: "out-is-the-scene", input: Input::Edit(&[]), args: &["--out", "{dir}/scene.toml"], expect: &["--out", "is the scene file", "scene.toml"] },
        Case { name: "out-is-the-mesh", input: Input::Mesh(OBJ, CUBE_OBJ.as_bytes()), args: &["--out", "{dir}/mesh.obj"], expect: &["--out", "meshes[0]", "mesh.obj"] },
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
