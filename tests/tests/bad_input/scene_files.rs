//! Scene files that cannot be used: missing, malformed TOML, unknown keys,
//! bad values and meshes, each named by file, line or field.

use crate::common::{expect_both, headless, scene_file, strs};
use twinray_tests::{bin, fail, scratch};

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

/// Scene files with one fault each, and what the refusal (exit 2) must name:
/// the file, then the line and column, the key, or the field.
const BAD_FILES: [(&str, &str, &[&str]); 6] = [
    ("bad.toml", "[[spheres]]\ncenter = [0.0, 0.0\nradius = 1.0\n", &["line 12, column"]),
    ("k.toml", "[[spheres]]\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\nmaterial = \"m\"\nglow = 2.0\n", &["glow", "line 14"]),
    ("nan.toml", "[[spheres]]\ncenter = [nan, 0.0, 0.0]\nradius = 1.0\nmaterial = \"m\"\n", &["spheres[0].center"]),
    ("neg.toml", "[[spheres]]\ncenter = [0.0, 0.0, 0.0]\nradius = -2.0\nmaterial = \"m\"\n", &["spheres[0].radius = -2"]),
    (
        "normal.toml",
        "[[triangles]]\nvertices = [[0.0,0.0,0.0],[1.0,0.0,0.0],[0.0,1.0,0.0]]\nnormals = [[0.0,0.0,0.0],[0.0,0.0,1.0],[0.0,0.0,1.0]]\nmaterial = \"m\"\n",
        &["triangles[0].normals[0]"],
    ),
    ("mat.toml", "[[spheres]]\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\nmaterial = \"unobtainium\"\n", &["'unobtainium'"]),
];

#[test]
fn bad_scene_files_are_named_by_file_and_line_or_field() {
    let dir = scratch("bad-scene-files");
    for (file, body, words) in BAD_FILES {
        let p = scene_file(&dir, file, body);
        expect_both(&strs(&headless(&p)), &[], 2, &[&[file], words].concat());
    }
}

#[test]
fn missing_and_broken_obj() {
    let dir = scratch("obj");
    let p = obj_scene(&dir, "mesh.toml", "pot.obj");
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

/// A scene file `toml` in `dir` whose one mesh is the OBJ file `obj`.
fn obj_scene(dir: &std::path::Path, toml: &str, obj: &str) -> String {
    let body = format!("[[meshes]]\nobj = \"{obj}\"\nmaterial = \"m\"\n");
    scene_file(dir, toml, &body)
}

/// The three tools, each with its arguments for an 8x8 headless render of
/// `scene`: both apps, and the reference through `twinray render`.
fn three_tools(scene: &str) -> [(std::path::PathBuf, Vec<&str>); 3] {
    let run = ["--headless", "--size", "8x8", "--scene", scene];
    [
        (bin("twinray-vk"), run.to_vec()),
        (bin("twinray-gl"), run.to_vec()),
        (
            bin("twinray"),
            [&["render", "--api", "reference", "--json"], &run[..]].concat(),
        ),
    ]
}

#[test]
fn a_polygon_past_the_triangle_limit_is_refused_from_its_line_in_little_memory() {
    // One face of 44.8 million vertices in 90 MB, just past the 44.7 million
    // triangle limit: expanded first, it took gigabytes and seconds (8.1 GB
    // and 15 s at 50 million); counted from its line it needs the file's size.
    let dir = scratch("polygon");
    let mut obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf ".to_vec();
    let n = twinray_common::limits::MAX_TRIANGLES + 3;
    obj.extend(b"1 2 3 ".repeat(n / 3 + 1));
    std::fs::write(dir.join("big.obj"), &obj).unwrap();
    drop(obj);
    let p = obj_scene(&dir, "big.toml", "big.obj");
    for (exe, args) in three_tools(&p) {
        // 1 GiB of address space: enough for the file, the tool and the
        // driver's reservations (the device is open before the scene is read,
        // so that its storage limit can refuse a scene before it is built),
        // far from the 8 GB that expanding the polygon took.
        let mut all = vec!["--as=1073741824", exe.to_str().unwrap()];
        all.extend(&args);
        let start = std::time::Instant::now();
        let (code, stderr) = fail(std::path::Path::new("prlimit"), &all, &[]);
        let secs = start.elapsed().as_secs_f64();
        assert_eq!(code, 2, "{exe:?}: {stderr}");
        assert!(
            stderr.contains("big.obj', line 4") && stderr.contains("limit of"),
            "{exe:?}: {stderr}"
        );
        assert!(secs < 5.0, "{exe:?} took {secs:.1} s");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `exe args`'s exit code, stderr, seconds and peak resident memory in MB.
/// GNU time measures it: it forks `exe` from its own small process, where a
/// child of this test process would inherit, through vfork and exec, the peak
/// of every test that runs beside it.
fn measured(exe: &std::path::Path, args: &[&str]) -> (i32, String, f64, f64) {
    let time = std::path::Path::new("/usr/bin/time");
    assert!(
        time.exists(),
        "GNU time is missing: source scripts/setup.sh installs it"
    );
    let mut all = vec!["-f", "peak-kb %M", exe.to_str().unwrap()];
    all.extend(args);
    let start = std::time::Instant::now();
    let (code, stderr) = fail(time, &all, &[]);
    let secs = start.elapsed().as_secs_f64();
    let kb: f64 = stderr
        .lines()
        .find_map(|l| l.strip_prefix("peak-kb "))
        .and_then(|v| v.trim().parse().ok())
        .unwrap_or_else(|| panic!("no peak memory from GNU time: {stderr}"));
    (code, stderr, secs, kb / 1024.0)
}

#[test]
fn fifty_million_points_or_lines_are_refused_from_their_first_line_in_little_memory() {
    // Each `f 1` and `l 1 2` became a zero-area triangle no count saw: 50
    // million of them took 5.9 GB and 173 s before an allocation of 10 GB failed.
    let dir = scratch("points-and-lines");
    for (name, head, line, words) in [
        ("points", "v 0 0 0\n", "f 1\n", "one vertex"),
        ("lines", "v 0 0 0\nv 1 0 0\n", "l 1 2\n", "line element"),
    ] {
        let mut obj = head.as_bytes().to_vec();
        obj.extend(line.as_bytes().repeat(50_000_000));
        std::fs::write(dir.join(format!("{name}.obj")), &obj).unwrap();
        drop(obj);
        let p = obj_scene(&dir, &format!("{name}.toml"), &format!("{name}.obj"));
        let at = format!("{name}.obj', line {}", head.lines().count() + 1);
        for (exe, args) in three_tools(&p) {
            let (code, stderr, secs, mb) = measured(&exe, &args);
            assert_eq!(code, 2, "{exe:?}: {stderr}");
            assert!(
                stderr.contains(&at) && stderr.contains(words),
                "{exe:?}: {stderr}"
            );
            assert!(secs < 2.0, "{exe:?} took {secs:.1} s");
            assert!(mb < 200.0, "{exe:?} took {mb:.0} MB");
        }
        let _ = std::fs::remove_file(dir.join(format!("{name}.obj")));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_obj_with_a_byte_order_mark_renders() {
    let dir = scratch("bom");
    std::fs::write(
        dir.join("bom.obj"),
        "\u{feff}v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let p = obj_scene(&dir, "bom.toml", "bom.obj");
    for (exe, args) in three_tools(&p) {
        twinray_tests::run_ok(&exe, &args, &[]);
    }
}

#[test]
fn a_loop_of_symbolic_links_is_named_as_one() {
    let dir = scratch("symlink-loop");
    for (a, b) in [("a.toml", "b.toml"), ("a.obj", "b.obj")] {
        let _ = std::fs::remove_file(dir.join(a));
        let _ = std::fs::remove_file(dir.join(b));
        std::os::unix::fs::symlink(dir.join(b), dir.join(a)).unwrap();
        std::os::unix::fs::symlink(dir.join(a), dir.join(b)).unwrap();
    }
    let scene = dir.join("a.toml");
    expect_both(
        &strs(&headless(scene.to_str().unwrap())),
        &[],
        2,
        &["a.toml", "loop of symbolic links"],
    );
    let p = obj_scene(&dir, "mesh.toml", "a.obj");
    expect_both(
        &strs(&headless(&p)),
        &[],
        2,
        &["a.obj", "loop of symbolic links"],
    );
}
