//! Finding and reading a scene: a built-in scene by name, a scene file by path,
//! or `random:SEED`, parsed and handed to `resolve` with the `--set` overrides.

use crate::error::bad_input;
use crate::limits::{self, StorageLimit};
use crate::reference::image_io::same_file;
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

/// Refuses an output path (`option`, e.g. `--out`) that names the scene file
/// `name_or_path` or a mesh file it loads: the write would replace an input
/// with a PNG. Compared as files, so a link or another spelling of the same
/// path is caught too. Cheap, and meant for before any work: a scene that
/// cannot be read or parsed is left to `Scene::load` to refuse in its words.
pub fn check_output_not_input(option: &str, out: &Path, name_or_path: &str) -> anyhow::Result<()> {
    if random::seed_of(name_or_path).is_some()
        || BUILTIN_SCENES.iter().any(|(n, _)| *n == name_or_path)
    {
        return Ok(());
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
    match inputs.into_iter().find(|(_, input)| same_file(out, input)) {
        Some((what, input)) => Err(bad_input(format!(
            "{option} '{}' is {what} '{}': writing it would replace an input; choose another file name",
            out.display(),
            input.display()
        ))),
        None => Ok(()),
    }
}
