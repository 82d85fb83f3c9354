//! Finding and reading a scene: a built-in scene by name, a scene file by path,
//! or `random:SEED`, parsed and handed to `resolve` with the `--set` overrides.

use crate::error::bad_input;
use crate::limits::{self, StorageLimit};
use crate::scene::format::SceneFile;
use crate::scene::mesh::{line_col, read_file, FileSource};
use crate::scene::overrides::apply_overrides;
use crate::scene::resolve::{resolve, Labels};
use crate::scene::{random, Scene};
use std::path::Path;

/// Built-in scenes: (name, scene TOML). Their OBJ files come from `BUILTIN_FILES`.
pub const BUILTIN_SCENES: &[(&str, &str)] = &[
    ("teapot", include_str!("../../../scenes/teapot.toml")),
    ("box", include_str!("../../../scenes/box.toml")),
    (
        "spherelist",
        include_str!("../../../scenes/spherelist.toml"),
    ),
];

impl Scene {
    /// Loads a built-in scene by name, or a scene file by path, and applies `--set` overrides.
    pub fn load(name_or_path: &str, overrides: &[(String, String)]) -> anyhow::Result<Scene> {
        Scene::load_limited(name_or_path, overrides, &StorageLimit::ANY)
    }

    /// `load` for a device that binds at most `limit` per storage buffer: a
    /// tessellation, an OBJ's faces or `extra_spheres` that would not fit are
    /// refused from their count, before they are made.
    pub fn load_limited(
        name_or_path: &str,
        overrides: &[(String, String)],
        limit: &StorageLimit,
    ) -> anyhow::Result<Scene> {
        if let Some(seed) = random::seed_of(name_or_path) {
            let seed = seed?;
            return Scene::parse(
                &format!("random-{seed}"),
                &random::toml(seed),
                &format!("random scene {seed}"),
                FileSource::Builtin,
                overrides,
                limit,
            );
        }
        if let Some((name, text)) = BUILTIN_SCENES.iter().find(|(n, _)| *n == name_or_path) {
            return Scene::parse(
                name,
                text,
                &format!("built-in scene '{name}'"),
                FileSource::Builtin,
                overrides,
                limit,
            );
        }
        let path = Path::new(name_or_path);
        // Only a missing file is "does not exist"; a loop of links or a
        // forbidden folder is said by `read_file` in its own words.
        if std::fs::metadata(path).is_err_and(|e| e.kind() == std::io::ErrorKind::NotFound) {
            let names: Vec<&str> = BUILTIN_SCENES.iter().map(|(n, _)| *n).collect();
            if path.extension().is_none() && !name_or_path.contains('/') {
                return Err(bad_input(format!(
                    "--scene '{name_or_path}' is neither a built-in scene ({}) nor an existing file",
                    names.join(", ")
                )));
            }
            return Err(bad_input(format!(
                "scene file '{name_or_path}' does not exist"
            )));
        }
        let text = read_file(
            &format!("scene file '{name_or_path}'"),
            path,
            limits::MAX_SCENE_FILE_BYTES,
        )?;
        let name = path
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("scene")
            .to_string();
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Scene::parse(
            &name,
            &text,
            &format!("scene file '{name_or_path}'"),
            FileSource::Dir(dir),
            overrides,
            limit,
        )
    }

    /// Parses TOML text; `origin` names the source in error messages.
    pub fn from_toml(
        name: &str,
        text: &str,
        dir: &Path,
        overrides: &[(String, String)],
    ) -> anyhow::Result<Scene> {
        Scene::parse(
            name,
            text,
            &format!("scene '{name}'"),
            FileSource::Dir(dir.to_path_buf()),
            overrides,
            &StorageLimit::ANY,
        )
    }

    /// Splits `--set` overrides into those that apply to the built-in scene
    /// `name` and those that cannot (each with the reason), so that a window's
    /// scene switch keeps what it can instead of refusing the switch. Only the
    /// overrides are tried, on the parsed file: nothing is tessellated here.
    pub fn applicable_overrides(
        name: &str,
        overrides: &[(String, String)],
    ) -> (Vec<(String, String)>, Vec<String>) {
        let Some((_, text)) = BUILTIN_SCENES.iter().find(|(n, _)| *n == name) else {
            return (overrides.to_vec(), Vec::new());
        };
        let Ok(def) = toml::from_str::<SceneFile>(text) else {
            return (overrides.to_vec(), Vec::new());
        };
        let (mut kept, mut dropped) = (Vec::new(), Vec::new());
        for o in overrides {
            match apply_overrides(&mut def.clone(), std::slice::from_ref(o)) {
                Ok(_) => kept.push(o.clone()),
                Err(e) => dropped.push(format!("{e:#}")),
            }
        }
        (kept, dropped)
    }

    fn parse(
        name: &str,
        text: &str,
        origin: &str,
        files: FileSource,
        overrides: &[(String, String)],
        limit: &StorageLimit,
    ) -> anyhow::Result<Scene> {
        let mut def: SceneFile = toml::from_str(text).map_err(|e| {
            let (line, col) = e.span().map(|s| line_col(text, s.start)).unwrap_or((1, 1));
            let msg = e.message().trim().replace('\n', " ");
            bad_input(format!("{origin}, line {line}, column {col}: {msg}"))
        })?;
        let set = apply_overrides(&mut def, overrides)?;
        resolve(name, def, &Labels { origin, set }, &files, limit)
    }
}

/// The files the scene `name_or_path` reads, each with what names it in a
/// message: the scene file and the mesh of each `[[meshes]]` entry (none for a
/// built-in or random scene). Cheap, and meant for before any work: a scene
/// that cannot be read or parsed is left to `Scene::load` to refuse in its words.
pub fn scene_inputs(name_or_path: &str) -> Vec<(String, std::path::PathBuf)> {
    if random::seed_of(name_or_path).is_some()
        || BUILTIN_SCENES.iter().any(|(n, _)| *n == name_or_path)
    {
        return Vec::new();
    }
    let scene = Path::new(name_or_path);
    let mut inputs = vec![("the scene file".to_string(), scene.to_path_buf())];
    let def = read_file("", scene, limits::MAX_SCENE_FILE_BYTES)
        .ok()
        .and_then(|text| toml::from_str::<SceneFile>(&text).ok());
    if let Some(def) = def {
        let dir = scene.parent().unwrap_or(Path::new(""));
        for (i, m) in def.meshes.iter().enumerate() {
            for file in m.obj.iter().chain(&m.bpt) {
                inputs.push((format!("the mesh of meshes[{i}]"), dir.join(file)));
            }
        }
    }
    inputs
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use std::time::Instant;

    /// A device that binds 100 MB per storage buffer: a million triangles.
    const SMALL: StorageLimit = StorageLimit {
        bytes: 100 << 20,
        name: "a test device's limit",
        texel_buffer: 0,
    };

    fn scratch(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("twinray-load-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn message(r: anyhow::Result<Scene>) -> String {
        let e = r.expect_err("refused");
        assert_eq!(crate::error::exit_code_of(&e), 2, "{e}");
        e.to_string()
    }

    #[test]
    fn a_tessellation_beyond_the_device_limit_is_refused_before_it_is_made() {
        let set = [("tessellation".to_string(), "400x400".to_string())];
        let t = Instant::now();
        let e = message(Scene::load_limited("teapot", &set, &SMALL));
        // Tessellating 10.2 million triangles takes seconds; counting them, nothing.
        assert!(t.elapsed().as_secs_f64() < 0.5, "{:?}", t.elapsed());
        for word in [
            "--set tessellation = 400x400",
            "32 patches",
            "a test device's limit",
        ] {
            assert!(e.contains(word), "lacks '{word}': {e}");
        }
        let set = [("tessellation".to_string(), "20x15".to_string())];
        assert!(Scene::load_limited("teapot", &set, &SMALL).is_ok());
    }

    #[test]
    fn extra_spheres_beyond_the_device_limit_are_refused_before_they_are_made() {
        let set = [("extra_spheres".to_string(), "9000000".to_string())];
        let e = message(Scene::load_limited("spherelist", &set, &SMALL));
        assert!(
            e.contains("--set extra_spheres") && e.contains("a test device's limit"),
            "{e}"
        );
        assert!(Scene::load("spherelist", &set).is_ok());
    }

    /// A scene whose mesh is `obj` is refused in words that hold each of `words`.
    fn obj_refused(dir: &Path, obj: &str, words: &[&str]) {
        let e = message(Scene::load(&obj_scene(dir, obj.as_bytes()), &[]));
        for word in words {
            assert!(e.contains(word), "{obj:?}: lacks '{word}': {e}");
        }
    }

    /// Writes `dir`/mesh.obj with `obj` and `dir`/scene.toml whose one mesh
    /// it is; the scene file's path.
    pub(crate) fn obj_scene(dir: &Path, obj: &[u8]) -> String {
        std::fs::write(dir.join("mesh.obj"), obj).unwrap();
        let scene = dir.join("scene.toml");
        std::fs::write(
            &scene,
            "[camera]\neye = [0.0, 0.0, 5.0]\nlook_at = [0.0, 0.0, 0.0]\n\
             [[materials]]\nname = \"m\"\n[[meshes]]\nobj = \"mesh.obj\"\nmaterial = \"m\"\n",
        )
        .unwrap();
        scene.to_str().unwrap().to_string()
    }

    #[test]
    fn a_polygon_is_counted_from_its_line_before_tobj_expands_it() {
        let dir = scratch("polygon");
        // One face of 2 million vertices (4 MB): 2 million triangles, twice SMALL.
        let mut obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\n# a fan\nf ".to_vec();
        obj.extend(b"1 2 3 ".repeat(2_000_000 / 3));
        let scene = obj_scene(&dir, &obj);
        let t = Instant::now();
        let e = message(Scene::load_limited(&scene, &[], &SMALL));
        assert!(t.elapsed().as_secs_f64() < 1.0, "{:?}", t.elapsed());
        assert!(
            e.contains("mesh.obj', line 5") && e.contains("a test device's limit"),
            "{e}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn every_obj_element_that_would_become_a_triangle_is_counted_or_refused() {
        use crate::gpu::layout::GpuTriangle;
        let dir = scratch("obj-elements");
        // A device that binds exactly 1000 triangles.
        let tiny = StorageLimit {
            bytes: 1000 * size_of::<GpuTriangle>() as u64,
            name: "a 1000-triangle limit",
            texel_buffer: 0,
        };
        let head = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n";
        // 499 quads (998 triangles) and two triangles: the limit exactly.
        let at_limit = format!("{head}{}f 1 2 3\nf 2 4 3\n", "f 1 2 4 3\n".repeat(499));
        let scene = obj_scene(&dir, at_limit.as_bytes());
        let loaded = Scene::load_limited(&scene, &[], &tiny).expect("at the limit");
        assert_eq!(loaded.triangles.len(), 1000);
        let over = format!("{at_limit}f 1 2 3\n");
        let e = message(Scene::load_limited(
            &obj_scene(&dir, over.as_bytes()),
            &[],
            &tiny,
        ));
        assert!(e.contains("line 506") && e.contains("1000-triangle"), "{e}");
        // Each of these became a zero-area triangle that no count saw.
        for (obj, words) in [
            ("f 1\n", &["line 5", "one vertex"][..]),
            ("f 1 2\n", &["line 5", "two vertices"]),
            ("l 1 2\n", &["line 5", "line element"]),
            ("l 1 2 3\n", &["line 5", "line element"]),
            ("f\n", &["line 5", "names no vertex"]),
        ] {
            obj_refused(&dir, &format!("{head}{obj}f 1 2 3\n"), words);
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn obj_errors_name_their_line_and_a_byte_order_mark_is_read_past() {
        let dir = scratch("obj-lines");
        let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        let scene = obj_scene(&dir, format!("\u{feff}{tri}").as_bytes());
        assert_eq!(Scene::load(&scene, &[]).unwrap().triangles.len(), 1);
        for (obj, words) in [
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 7\n",
                &["line 5", "vertex 7", "3 vertices"][..],
            ),
            ("v 0 0 0\nv 1 x 0\n", &["line 2", "`v` needs three numbers"]),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n",
                &["line 4", "start at 1"],
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n",
                &["line 4", "counts back"],
            ),
            (
                "v 0 0 0\nv 1 0 0\nvn 0 0 0\nv 0 1 0\nf 1//1 2//1 3//1\n",
                &["line 5", "normal 1 has zero length"],
            ),
            (
                "v 0 0 0\nv 1e39 0 0\n",
                &["line 2", "vertex 2", "not finite"],
            ),
            ("v 0 0 0 0\n", &["line 1", "w must be"]),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/2/3/4 2 3\n",
                &["line 4", "'1/2/3/4'"],
            ),
        ] {
            obj_refused(&dir, obj, words);
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_loop_of_links_is_named_as_a_loop() {
        let dir = scratch("loop");
        let (a, b) = (dir.join("a.toml"), dir.join("b.toml"));
        let _ = (std::fs::remove_file(&a), std::fs::remove_file(&b));
        std::os::unix::fs::symlink(&b, &a).unwrap();
        std::os::unix::fs::symlink(&a, &b).unwrap();
        let e = message(Scene::load(a.to_str().unwrap(), &[]));
        assert!(
            e.contains("loop of symbolic links") && e.contains("a.toml"),
            "{e}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
