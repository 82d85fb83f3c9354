//! `--set KEY=VALUE`: the keys a user may override and their application to
//! the parsed file, before `resolve` checks every value.

use crate::error::bad_input;
use crate::limits;
use crate::scene::format::{Exact, SceneFile};
use crate::scene::numerics::Numerics;
use crate::scene::OriginMode;
use std::collections::HashSet;

/// Keys accepted by `--set`.
pub const OVERRIDE_KEYS: &[&str] = &[
    "max_depth",
    "min_weight",
    "epsilon",
    "extra_spheres",
    "fov_y",
    "tessellation",
    "offset",
    "triangle",
    "sphere",
    "origin",
];

/// is checked here; its range is checked once, in `resolve`, with the same
/// limits as a value from the file. Returns the keys set, so that `resolve`
/// names `--set KEY` rather than the file when such a value is refused.
pub(super) fn apply_overrides(
    def: &mut SceneFile,
    overrides: &[(String, String)],
) -> anyhow::Result<HashSet<String>> {
    let mut set = HashSet::new();
    for (key, value) in overrides {
        let num = || -> anyhow::Result<f64> {
            value
                .parse::<f64>()
                .map_err(|_| bad_input(format!("--set {key}={value}: '{value}' is not a number")))
        };
        let int = || -> anyhow::Result<u32> {
            value.parse::<u32>().map_err(|e| {
                bad_input(match e.kind() {
                    std::num::IntErrorKind::PosOverflow => {
                        format!(
                            "--set {key}={value}: '{value}' is more than the limit of {}",
                            u32::MAX
                        )
                    }
                    _ => format!("--set {key}={value}: '{value}' is not a whole number"),
                })
            })
        };
        match key.as_str() {
            "max_depth" => def.render.max_depth = int()?,
            "min_weight" => def.render.min_weight = num()?,
            "epsilon" => def.render.epsilon = num()?,
            "fov_y" => def.camera.fov_y = num()?,
            "tessellation" => {
                let t = value
                    .split_once(['x', 'X'])
                    .and_then(|(u, v)| Some([u.trim().parse::<u32>().ok()?, v.trim().parse::<u32>().ok()?]))
                    .ok_or_else(|| {
                        bad_input(format!(
                            "--set tessellation={value}: give quads per patch as NUxNV, each from 1 to {} (the study: 20x15)",
                            limits::MAX_TESSELLATION
                        ))
                    })?;
                let mut any = false;
                for m in def.meshes.iter_mut().filter(|m| m.bpt.is_some()) {
                    m.tessellation = Some(Exact(t));
                    any = true;
                }
                if !any {
                    return Err(bad_input("--set tessellation: this scene has no Bezier-patch mesh (try --scene teapot)"));
                }
            }
            "offset" | "triangle" | "sphere" => {
                // Checked here so that the error names --set rather than the scene file.
                Numerics::default().set(key, value, &format!("--set {key}"))?;
                match key.as_str() {
                    "offset" => def.render.offset = Some(value.clone()),
                    "triangle" => def.render.triangle = Some(value.clone()),
                    _ => def.render.sphere = Some(value.clone()),
                }
            }
            "origin" => {
                OriginMode::parse(value, "--set origin")?;
                def.render.origin = Some(value.clone());
            }
            "extra_spheres" => {
                let n = int()?;
                match def.extra_spheres.as_mut() {
                    Some(e) => e.count = n,
                    None => {
                        return Err(bad_input(
                            "--set extra_spheres: this scene has no [extra_spheres] section (try --scene spherelist)",
                        ))
                    }
                }
            }
            _ => {
                return Err(bad_input(format!(
                    "--set {key}: unknown key '{key}' (known keys: {})",
                    OVERRIDE_KEYS.join(", ")
                )))
            }
        }
        set.insert(key.clone());
    }
    Ok(set)
}
