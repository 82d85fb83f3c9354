//! Finding and reading a scene: a built-in scene by name, a scene file by path,
//! or `random:SEED`, parsed and handed to `resolve` with the `--set` overrides.

use crate::error::bad_input;
use crate::limits;
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
        if let Some(seed) = random::seed_of(name_or_path) {
            let seed = seed?;
            return Scene::parse(
                &format!("random-{seed}"),
                &random::toml(seed),
                &format!("random scene {seed}"),
                FileSource::Builtin,
                overrides,
            );
        }
        if let Some((name, text)) = BUILTIN_SCENES.iter().find(|(n, _)| *n == name_or_path) {
            return Scene::parse(
                name,
                text,
                &format!("built-in scene '{name}'"),
                FileSource::Builtin,
                overrides,
            );
        }
        let path = Path::new(name_or_path);
        if !path.exists() {
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
    ) -> anyhow::Result<Scene> {
        let mut def: SceneFile = toml::from_str(text).map_err(|e| {
            let (line, col) = e.span().map(|s| line_col(text, s.start)).unwrap_or((1, 1));
            let msg = e.message().trim().replace('\n', " ");
            bad_input(format!("{origin}, line {line}, column {col}: {msg}"))
        })?;
        let set = apply_overrides(&mut def, overrides)?;
        resolve(name, def, &Labels { origin, set }, &files)
    }
}
