//! Scene files: the TOML format (documented in scenes/README.md), the built-in
//! scenes embedded in the binary, `--set` overrides, validation, and OBJ meshes
//! through tobj. Everything downstream sees one resolved, validated `Scene` in f64.

use crate::error::bad_input;
use crate::numerics::Numerics;
use glam::{DMat3, DVec3};
use serde::Deserialize;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Built-in scenes: (name, scene TOML). Their OBJ files come from `BUILTIN_FILES`.
pub const BUILTIN_SCENES: &[(&str, &str)] = &[
    ("teapot", include_str!("../../scenes/teapot.toml")),
    ("box", include_str!("../../scenes/box.toml")),
    ("spherelist", include_str!("../../scenes/spherelist.toml")),
];

const BUILTIN_FILES: &[(&str, &str)] = &[
    ("cube.obj", include_str!("../../scenes/cube.obj")),
    ("teapot.bpt", include_str!("../../scenes/teapot.bpt")),
];

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

/// The finest `tessellation` accepted per direction (400 x 400 quads per patch is
/// 10 million triangles for the 32-patch teapot).
pub const MAX_TESSELLATION: u32 = 400;

/// More hidden spheres than any storage buffer needs to hold for the study (10,000),
/// yet enough to exceed a device's storage-buffer limit on purpose.
pub const MAX_EXTRA_SPHERES: u32 = 10_000_000;

/// The largest `max_depth` a scene may ask for; the shader's generic ray stack holds this + 1.
pub const MAX_DEPTH_LIMIT: u32 = 16;

// ---------------------------------------------------------------- file format

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    #[serde(default)]
    description: Option<String>,
    camera: CameraDef,
    #[serde(default)]
    render: RenderDef,
    materials: Vec<MaterialDef>,
    #[serde(default)]
    lights: Vec<LightDef>,
    #[serde(default)]
    spheres: Vec<SphereDef>,
    #[serde(default)]
    triangles: Vec<TriangleDef>,
    #[serde(default)]
    quads: Vec<QuadDef>,
    #[serde(default)]
    meshes: Vec<MeshDef>,
    #[serde(default)]
    extra_spheres: Option<ExtraSpheresDef>,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
struct CameraDef {
    eye: [f64; 3],
    look_at: [f64; 3],
    #[serde(default = "default_up")]
    up: [f64; 3],
    #[serde(default = "default_fov")]
    fov_y: f64,
}

fn default_up() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}
fn default_fov() -> f64 {
    45.0
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields, default)]
struct RenderDef {
    background: [f64; 3],
    max_depth: u32,
    min_weight: f64,
    epsilon: f64,
    /// Numerics (see numerics.rs); absent keys keep the default configuration.
    offset: Option<String>,
    triangle: Option<String>,
    sphere: Option<String>,
    /// `local` (default) or `world`: see `camera::local_origin`.
    origin: Option<String>,
}

impl Default for RenderDef {
    fn default() -> Self {
        RenderDef {
            background: [0.0; 3],
            max_depth: 5,
            min_weight: 0.01,
            epsilon: 1e-4,
            offset: None,
            triangle: None,
            sphere: None,
            origin: None,
        }
    }
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
struct MaterialDef {
    name: String,
    #[serde(default)]
    ambient: [f64; 3],
    #[serde(default)]
    diffuse: [f64; 3],
    #[serde(default)]
    specular: [f64; 3],
    #[serde(default = "default_shininess")]
    shininess: f64,
    #[serde(default)]
    reflectivity: f64,
    #[serde(default)]
    transparency: f64,
    #[serde(default = "default_ior")]
    ior: f64,
}

fn default_shininess() -> f64 {
    32.0
}
fn default_ior() -> f64 {
    1.5
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
struct LightDef {
    position: [f64; 3],
    #[serde(default = "default_light")]
    color: [f64; 3],
}

fn default_light() -> [f64; 3] {
    [1.0; 3]
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
struct SphereDef {
    center: [f64; 3],
    radius: f64,
    material: String,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
struct TriangleDef {
    vertices: [[f64; 3]; 3],
    #[serde(default)]
    normals: Option<[[f64; 3]; 3]>,
    material: String,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
struct QuadDef {
    corners: [[f64; 3]; 4],
    material: String,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
struct MeshDef {
    /// A triangle mesh in an OBJ file ...
    #[serde(default)]
    obj: Option<String>,
    /// ... or Bezier patches in the classic .bpt format, tessellated at load.
    #[serde(default)]
    bpt: Option<String>,
    /// Quads per patch in u and v for `bpt` (2 triangles each); default 20 x 15.
    #[serde(default)]
    tessellation: Option<[u32; 2]>,
    material: String,
    #[serde(default = "one")]
    scale: f64,
    #[serde(default)]
    rotate_y: f64,
    #[serde(default)]
    translate: [f64; 3],
    #[serde(default = "yes")]
    smooth: bool,
}

fn one() -> f64 {
    1.0
}
fn yes() -> bool {
    true
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
struct ExtraSpheresDef {
    count: u32,
    center: [f64; 3],
    radius: f64,
    material: String,
}

// ---------------------------------------------------------------- resolved scene

#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    pub eye: DVec3,
    pub look_at: DVec3,
    pub up: DVec3,
    /// Vertical field of view in degrees.
    pub fov_y: f64,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    pub name: String,
    pub ambient: DVec3,
    pub diffuse: DVec3,
    pub specular: DVec3,
    pub shininess: f64,
    pub reflectivity: f64,
    pub transparency: f64,
    pub ior: f64,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Light {
    pub position: DVec3,
    pub color: DVec3,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Sphere {
    pub center: DVec3,
    pub radius: f64,
    pub material: u32,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Triangle {
    pub p: [DVec3; 3],
    /// Unit per-vertex normals (the geometric normal for flat triangles).
    pub n: [DVec3; 3],
    pub material: u32,
}

/// A validated scene, ready for the GPU buffers and the reference tracer.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    pub name: String,
    pub description: String,
    pub camera: Camera,
    pub background: DVec3,
    pub max_depth: u32,
    pub min_weight: f64,
    pub epsilon: f64,
    /// Secondary-ray offset, triangle and sphere tests: the shader variant and the reference follow it.
    pub numerics: Numerics,
    /// Where the GPU's f32 coordinates are measured from (camera.rs, `local_origin`).
    pub origin: crate::camera::OriginMode,
    pub materials: Vec<Material>,
    pub lights: Vec<Light>,
    pub spheres: Vec<Sphere>,
    pub triangles: Vec<Triangle>,
    /// Trace through a BVH (common/src/bvh.rs) instead of testing every primitive.
    /// `--accel` decides; `auto` (the default) uses one from `AUTO_BVH_MIN_PRIMITIVES` on.
    pub bvh: bool,
    /// The BVH once built (`bvh_tree`): both the shader variant (its stack
    /// depth) and the GPU buffers need it, and building it twice costs seconds
    /// for a million triangles.
    bvh_cache: BvhCache,
}

/// A built BVH carried with its scene. Derived data, not part of the scene's
/// identity: two scenes compare equal whether or not either was built.
#[derive(Clone, Default)]
struct BvhCache(std::sync::OnceLock<std::sync::Arc<crate::bvh::Bvh>>);

impl PartialEq for BvhCache {
    fn eq(&self, _: &BvhCache) -> bool {
        true
    }
}

impl std::fmt::Debug for BvhCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(if self.0.get().is_some() {
            "built"
        } else {
            "not built"
        })
    }
}

/// `--accel auto` builds a BVH for scenes with at least this many primitives.
/// Below it the brute-force loop is as fast or faster: see the comparison
/// report's acceleration section for the measurements behind the number.
pub const AUTO_BVH_MIN_PRIMITIVES: usize = 64;

/// What a scene contains, which decides its shader variant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Features {
    pub spheres: bool,
    pub triangles: bool,
    pub mirror: bool,
    pub glass: bool,
}

#[derive(Debug, Clone, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct SceneStats {
    pub name: String,
    pub spheres: usize,
    pub triangles: usize,
    pub lights: usize,
    pub materials: usize,
    pub max_depth: u32,
}

/// Where OBJ files named by a scene are found.
enum FileSource {
    Builtin,
    Dir(PathBuf),
}

impl Scene {
    /// Loads a built-in scene by name, or a scene file by path, and applies `--set` overrides.
    pub fn load(name_or_path: &str, overrides: &[(String, String)]) -> anyhow::Result<Scene> {
        if let Some(seed) = crate::random_scene::seed_of(name_or_path) {
            let seed = seed?;
            return Scene::parse(
                &format!("random-{seed}"),
                &crate::random_scene::toml(seed),
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
        let text = std::fs::read_to_string(path)
            .map_err(|e| bad_input(format!("scene file '{name_or_path}' cannot be read: {e}")))?;
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
        apply_overrides(&mut def, overrides)?;
        resolve(name, def, origin, &files)
    }

    pub fn features(&self) -> Features {
        let used = |pred: &dyn Fn(&Material) -> bool| {
            self.spheres
                .iter()
                .map(|s| s.material)
                .chain(self.triangles.iter().map(|t| t.material))
                .any(|m| pred(&self.materials[m as usize]))
        };
        Features {
            spheres: !self.spheres.is_empty(),
            triangles: !self.triangles.is_empty(),
            mirror: self.max_depth > 1 && used(&|m| m.reflectivity > 0.0),
            glass: self.max_depth > 1 && used(&|m| m.transparency > 0.0),
        }
    }

    pub fn primitive_count(&self) -> usize {
        self.spheres.len() + self.triangles.len()
    }

    /// The scene's BVH where it traces through one (built on first use, then
    /// kept). Primitives changed after that call would not be seen: scenes are
    /// not edited once loaded, except for `--accel` and the ray depth.
    pub fn bvh_tree(&self) -> Option<&crate::bvh::Bvh> {
        self.bvh.then(|| {
            &**self
                .bvh_cache
                .0
                // Over the primitives as the GPU holds them: relative to the local origin.
                .get_or_init(|| {
                    let local = crate::camera::in_local_frame(self);
                    std::sync::Arc::new(crate::bvh::Bvh::build(&local))
                })
        })
    }

    /// Applies `--accel` (none: brute force; bvh: a BVH; auto: a BVH from the threshold on).
    pub fn set_accel(&mut self, accel: crate::cli::Accel) {
        self.bvh_cache = BvhCache::default();
        self.bvh = match accel {
            crate::cli::Accel::None => false,
            crate::cli::Accel::Bvh => self.primitive_count() > 0,
            crate::cli::Accel::Auto => self.primitive_count() >= AUTO_BVH_MIN_PRIMITIVES,
        };
    }

    /// The scene as the GPU buffers hold it: every position, normal, radius and
    /// material value rounded to f32 (the camera is rounded in `RayFrame`). The
    /// reference traces this in f64, so its images differ from the GPU's by the
    /// GPU's arithmetic only, not by its inputs — which matters far from the
    /// origin, where f32 moves a vertex by up to half an ULP (1/32 at 1e6).
    pub fn rounded_to_f32(&self) -> Scene {
        let r = |x: f64| x as f32 as f64;
        let v = |x: DVec3| x.as_vec3().as_dvec3();
        let mut s = self.clone();
        s.bvh_cache = BvhCache::default();
        s.background = v(s.background);
        s.min_weight = r(s.min_weight);
        s.epsilon = r(s.epsilon);
        for m in &mut s.materials {
            (m.ambient, m.diffuse, m.specular) = (v(m.ambient), v(m.diffuse), v(m.specular));
            (m.shininess, m.reflectivity, m.transparency, m.ior) = (
                r(m.shininess),
                r(m.reflectivity),
                r(m.transparency),
                r(m.ior),
            );
        }
        for l in &mut s.lights {
            (l.position, l.color) = (v(l.position), v(l.color));
        }
        for sp in &mut s.spheres {
            (sp.center, sp.radius) = (v(sp.center), r(sp.radius));
        }
        for t in &mut s.triangles {
            t.p = t.p.map(v);
            t.n = t.n.map(v);
        }
        s
    }

    pub fn stats(&self) -> SceneStats {
        SceneStats {
            name: self.name.clone(),
            spheres: self.spheres.len(),
            triangles: self.triangles.len(),
            lights: self.lights.len(),
            materials: self.materials.len(),
            max_depth: self.max_depth,
        }
    }
}

fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before
        .rsplit('\n')
        .next()
        .map(|l| l.chars().count())
        .unwrap_or(0)
        + 1;
    (line, col)
}

fn apply_overrides(def: &mut SceneFile, overrides: &[(String, String)]) -> anyhow::Result<()> {
    for (key, value) in overrides {
        let num = || -> anyhow::Result<f64> {
            value
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    bad_input(format!(
                        "--set {key}={value}: '{value}' is not a finite number"
                    ))
                })
        };
        let int = |max: u32| -> anyhow::Result<u32> {
            value
                .parse::<u32>()
                .ok()
                .filter(|v| *v <= max)
                .ok_or_else(|| {
                    bad_input(format!(
                        "--set {key}={value}: '{value}' is not a whole number from 0 to {max}"
                    ))
                })
        };
        match key.as_str() {
            "max_depth" => def.render.max_depth = int(MAX_DEPTH_LIMIT)?,
            "min_weight" => def.render.min_weight = num()?,
            "epsilon" => def.render.epsilon = num()?,
            "fov_y" => def.camera.fov_y = num()?,
            "tessellation" => {
                let t = value
                    .split_once(['x', 'X'])
                    .and_then(|(u, v)| Some([u.trim().parse::<u32>().ok()?, v.trim().parse::<u32>().ok()?]))
                    .filter(|t| t.iter().all(|n| (1..=MAX_TESSELLATION).contains(n)))
                    .ok_or_else(|| {
                        bad_input(format!(
                            "--set tessellation={value}: give quads per patch as NUxNV, each from 1 to {MAX_TESSELLATION} (the study: 20x15)"
                        ))
                    })?;
                let mut any = false;
                for m in def.meshes.iter_mut().filter(|m| m.bpt.is_some()) {
                    m.tessellation = Some(t);
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
                crate::camera::OriginMode::parse(value, "--set origin")?;
                def.render.origin = Some(value.clone());
            }
            "extra_spheres" => {
                let n = int(MAX_EXTRA_SPHERES)?;
                match def.extra_spheres.as_mut() {
                    Some(e) => e.count = n,
                    None => {
                        return Err(bad_input(format!(
                            "--set extra_spheres: this scene has no [extra_spheres] section (try --scene spherelist)"
                        )))
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
    }
    Ok(())
}

fn finite3(origin: &str, what: &str, v: [f64; 3]) -> anyhow::Result<DVec3> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(DVec3::from_array(v))
    } else {
        Err(bad_input(format!(
            "{origin}: {what} = {v:?} is not finite (NaN or infinity)"
        )))
    }
}

fn finite(origin: &str, what: &str, v: f64) -> anyhow::Result<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(bad_input(format!(
            "{origin}: {what} = {v} is not finite (NaN or infinity)"
        )))
    }
}

fn resolve(name: &str, def: SceneFile, origin: &str, files: &FileSource) -> anyhow::Result<Scene> {
    let cam = &def.camera;
    let camera = Camera {
        eye: finite3(origin, "camera.eye", cam.eye)?,
        look_at: finite3(origin, "camera.look_at", cam.look_at)?,
        up: finite3(origin, "camera.up", cam.up)?,
        fov_y: finite(origin, "camera.fov_y", cam.fov_y)?,
    };
    if !(camera.fov_y > 0.0 && camera.fov_y < 180.0) {
        return Err(bad_input(format!(
            "{origin}: camera.fov_y = {} must lie between 0 and 180 degrees",
            camera.fov_y
        )));
    }
    let forward = camera.look_at - camera.eye;
    if forward.length() == 0.0
        || forward.cross(camera.up).length() <= 1e-12 * forward.length() * camera.up.length()
    {
        return Err(bad_input(format!(
            "{origin}: camera.eye, camera.look_at and camera.up must give a view direction not parallel to up"
        )));
    }
    let r = &def.render;
    let background = finite3(origin, "render.background", r.background)?;
    if !(1..=MAX_DEPTH_LIMIT).contains(&r.max_depth) {
        return Err(bad_input(format!(
            "{origin}: render.max_depth = {} must be from 1 to {MAX_DEPTH_LIMIT}",
            r.max_depth
        )));
    }
    let min_weight = finite(origin, "render.min_weight", r.min_weight)?;
    if min_weight < 0.0 {
        return Err(bad_input(format!(
            "{origin}: render.min_weight = {min_weight} must not be negative"
        )));
    }
    let epsilon = finite(origin, "render.epsilon", r.epsilon)?;
    if !(epsilon > 0.0 && epsilon < 1.0) {
        return Err(bad_input(format!(
            "{origin}: render.epsilon = {epsilon} must lie between 0 and 1"
        )));
    }

    let mut numerics = Numerics::default();
    for (key, value) in [
        ("offset", &r.offset),
        ("triangle", &r.triangle),
        ("sphere", &r.sphere),
    ] {
        if let Some(v) = value {
            numerics.set(key, v, &format!("{origin}: render.{key}"))?;
        }
    }

    let origin_mode = match &r.origin {
        Some(v) => crate::camera::OriginMode::parse(v, &format!("{origin}: render.origin"))?,
        None => Default::default(),
    };

    if def.materials.is_empty() {
        return Err(bad_input(format!(
            "{origin}: the scene defines no [[materials]]"
        )));
    }
    let mut materials = Vec::new();
    let mut by_name: HashMap<String, u32> = HashMap::new();
    for (i, m) in def.materials.iter().enumerate() {
        let at = format!("materials[{i}] ('{}')", m.name);
        let mat = Material {
            name: m.name.clone(),
            ambient: finite3(origin, &format!("{at}.ambient"), m.ambient)?,
            diffuse: finite3(origin, &format!("{at}.diffuse"), m.diffuse)?,
            specular: finite3(origin, &format!("{at}.specular"), m.specular)?,
            shininess: finite(origin, &format!("{at}.shininess"), m.shininess)?,
            reflectivity: finite(origin, &format!("{at}.reflectivity"), m.reflectivity)?,
            transparency: finite(origin, &format!("{at}.transparency"), m.transparency)?,
            ior: finite(origin, &format!("{at}.ior"), m.ior)?,
        };
        let colours = [mat.ambient, mat.diffuse, mat.specular];
        if colours.iter().any(|c| c.min_element() < 0.0) {
            return Err(bad_input(format!(
                "{origin}: {at} has a negative colour component"
            )));
        }
        if mat.shininess < 0.0 {
            return Err(bad_input(format!(
                "{origin}: {at}.shininess = {} must not be negative",
                mat.shininess
            )));
        }
        for (what, v) in [
            ("reflectivity", mat.reflectivity),
            ("transparency", mat.transparency),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return Err(bad_input(format!(
                    "{origin}: {at}.{what} = {v} must lie between 0 and 1"
                )));
            }
        }
        if mat.reflectivity + mat.transparency > 1.0 {
            return Err(bad_input(format!(
                "{origin}: {at}: reflectivity + transparency must not exceed 1"
            )));
        }
        if mat.ior <= 0.0 {
            return Err(bad_input(format!(
                "{origin}: {at}.ior = {} must be positive",
                mat.ior
            )));
        }
        if by_name.insert(m.name.clone(), i as u32).is_some() {
            return Err(bad_input(format!(
                "{origin}: material '{}' is defined twice",
                m.name
            )));
        }
        materials.push(mat);
    }
    let material = |at: &str, name: &str| -> anyhow::Result<u32> {
        by_name.get(name).copied().ok_or_else(|| {
            let mut known: Vec<&String> = by_name.keys().collect();
            known.sort();
            bad_input(format!(
                "{origin}: {at}.material '{name}' is not a defined material (defined: {})",
                known
                    .iter()
                    .map(|s| s.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })
    };

    let mut lights = Vec::new();
    for (i, l) in def.lights.iter().enumerate() {
        let color = finite3(origin, &format!("lights[{i}].color"), l.color)?;
        if color.min_element() < 0.0 {
            return Err(bad_input(format!(
                "{origin}: lights[{i}].color has a negative component"
            )));
        }
        lights.push(Light {
            position: finite3(origin, &format!("lights[{i}].position"), l.position)?,
            color,
        });
    }

    let mut spheres = Vec::new();
    let sphere = |at: &str, center: [f64; 3], radius: f64, mat: &str| -> anyhow::Result<Sphere> {
        let center = finite3(origin, &format!("{at}.center"), center)?;
        let radius = finite(origin, &format!("{at}.radius"), radius)?;
        if radius <= 0.0 {
            return Err(bad_input(format!(
                "{origin}: {at}.radius = {radius} must be positive"
            )));
        }
        Ok(Sphere {
            center,
            radius,
            material: material(at, mat)?,
        })
    };
    for (i, s) in def.spheres.iter().enumerate() {
        spheres.push(sphere(
            &format!("spheres[{i}]"),
            s.center,
            s.radius,
            &s.material,
        )?);
    }
    if let Some(e) = &def.extra_spheres {
        let s = sphere("extra_spheres", e.center, e.radius, &e.material)?;
        spheres.extend(std::iter::repeat_n(s, e.count as usize));
    }

    let mut triangles = Vec::new();
    for (i, t) in def.triangles.iter().enumerate() {
        let at = format!("triangles[{i}]");
        let mut p = [DVec3::ZERO; 3];
        for k in 0..3 {
            p[k] = finite3(origin, &format!("{at}.vertices[{k}]"), t.vertices[k])?;
        }
        let n = match t.normals {
            Some(ns) => {
                let mut n = [DVec3::ZERO; 3];
                for k in 0..3 {
                    n[k] = unit_normal(origin, &format!("{at}.normals[{k}]"), ns[k])?;
                }
                n
            }
            None => [flat_normal(&p); 3],
        };
        triangles.push(Triangle {
            p,
            n,
            material: material(&at, &t.material)?,
        });
    }
    for (i, q) in def.quads.iter().enumerate() {
        let at = format!("quads[{i}]");
        let mut c = [DVec3::ZERO; 4];
        for k in 0..4 {
            c[k] = finite3(origin, &format!("{at}.corners[{k}]"), q.corners[k])?;
        }
        let m = material(&at, &q.material)?;
        for p in [[c[0], c[1], c[2]], [c[0], c[2], c[3]]] {
            triangles.push(Triangle {
                p,
                n: [flat_normal(&p); 3],
                material: m,
            });
        }
    }
    for (i, m) in def.meshes.iter().enumerate() {
        let at = format!("meshes[{i}]");
        let mat = material(&at, &m.material)?;
        let scale = finite(origin, &format!("{at}.scale"), m.scale)?;
        if scale <= 0.0 {
            return Err(bad_input(format!(
                "{origin}: {at}.scale = {scale} must be positive"
            )));
        }
        let rot = DMat3::from_rotation_y(
            finite(origin, &format!("{at}.rotate_y"), m.rotate_y)?.to_radians(),
        );
        let translate = finite3(origin, &format!("{at}.translate"), m.translate)?;
        let (obj, file) = match (&m.obj, &m.bpt) {
            (Some(obj), None) if m.tessellation.is_none() => (load_obj(origin, &at, obj, files)?, obj),
            (None, Some(bpt)) => (load_bpt(origin, &at, bpt, m.tessellation.unwrap_or([20, 15]), files)?, bpt),
            _ => {
                return Err(bad_input(format!(
                    "{origin}: {at} needs either `obj` or `bpt` (with an optional `tessellation`), not both"
                )))
            }
        };
        let before = triangles.len();
        for (p, n) in obj {
            let p = p.map(|v| rot * (v * scale) + translate);
            let n = match (m.smooth, n) {
                (true, Some(n)) => n.map(|v| rot * v),
                _ => [flat_normal(&p); 3],
            };
            triangles.push(Triangle {
                p,
                n,
                material: mat,
            });
        }
        if triangles.len() == before {
            return Err(bad_input(format!(
                "{origin}: {at}: '{file}' contains no faces"
            )));
        }
    }

    Ok(Scene {
        name: name.to_string(),
        description: def.description.unwrap_or_default(),
        camera,
        background,
        max_depth: r.max_depth,
        min_weight,
        epsilon,
        numerics,
        origin: origin_mode,
        materials,
        lights,
        bvh: spheres.len() + triangles.len() >= AUTO_BVH_MIN_PRIMITIVES,
        bvh_cache: BvhCache::default(),
        spheres,
        triangles,
    })
}

fn unit_normal(origin: &str, what: &str, v: [f64; 3]) -> anyhow::Result<DVec3> {
    let n = finite3(origin, what, v)?;
    let len = n.length();
    if !(len > 1e-12) {
        return Err(bad_input(format!(
            "{origin}: {what} = {v:?} has zero length"
        )));
    }
    Ok(n / len)
}

/// The unit geometric normal, or zero for a degenerate triangle: the tracer never
/// hits those, so their normal is never used.
fn flat_normal(p: &[DVec3; 3]) -> DVec3 {
    (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero()
}

type ObjTriangle = ([DVec3; 3], Option<[DVec3; 3]>);

/// The text of a file a scene names: built in, or next to the scene file.
fn read_text(origin: &str, what: &str, file: &str, files: &FileSource) -> anyhow::Result<String> {
    match files {
        FileSource::Builtin => BUILTIN_FILES
            .iter()
            .find(|(n, _)| *n == file)
            .map(|(_, t)| t.to_string())
            .ok_or_else(|| bad_input(format!("{origin}: {what} '{file}' is not a built-in file"))),
        FileSource::Dir(dir) => {
            let path = dir.join(file);
            std::fs::read_to_string(&path).map_err(|e| {
                bad_input(format!(
                    "{origin}: {what} '{}' cannot be read: {e}",
                    path.display()
                ))
            })
        }
    }
}

/// Newell-style Bezier patches, tessellated by the generator that wrote teapot.obj.
fn load_bpt(
    origin: &str,
    at: &str,
    file: &str,
    [nu, nv]: [u32; 2],
    files: &FileSource,
) -> anyhow::Result<Vec<ObjTriangle>> {
    if !(1..=MAX_TESSELLATION).contains(&nu) || !(1..=MAX_TESSELLATION).contains(&nv) {
        return Err(bad_input(format!(
            "{origin}: {at}.tessellation = [{nu}, {nv}]: each must be from 1 to {MAX_TESSELLATION}"
        )));
    }
    let text = read_text(origin, &format!("{at}.bpt"), file, files)?;
    let patches = crate::teapot::parse_bpt(&text).map_err(|e| {
        bad_input(format!(
            "{origin}: {at}.bpt '{file}' is not a valid patch file: {e}"
        ))
    })?;
    let mesh = crate::teapot::tessellate(&patches, nu, nv);
    let v = |i: u32| DVec3::from_array(mesh.positions[i as usize]);
    let n = |i: u32| DVec3::from_array(mesh.normals[i as usize]);
    Ok(mesh
        .triangles
        .iter()
        .map(|t| {
            (
                [v(t[0]), v(t[1]), v(t[2])],
                Some([n(t[0]), n(t[1]), n(t[2])]),
            )
        })
        .collect())
}

fn load_obj(
    origin: &str,
    at: &str,
    file: &str,
    files: &FileSource,
) -> anyhow::Result<Vec<ObjTriangle>> {
    let text = read_text(origin, &format!("{at}.obj"), file, files)?;
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj_buf(&mut text.as_bytes(), &opts, |_| {
        // Materials come from the scene file, never from an OBJ's mtllib.
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| {
        bad_input(format!(
            "{origin}: {at}.obj '{file}' is not a valid OBJ file: {e}"
        ))
    })?;
    let mut out = Vec::new();
    for model in &models {
        let mesh = &model.mesh;
        let pos = |i: u32| -> anyhow::Result<DVec3> {
            let i = i as usize * 3;
            let v = mesh.positions.get(i..i + 3).ok_or_else(|| {
                bad_input(format!(
                    "{origin}: {at}.obj '{file}' has a face index beyond its vertex list"
                ))
            })?;
            finite3(
                origin,
                &format!("{at}.obj '{file}' vertex"),
                [v[0] as f64, v[1] as f64, v[2] as f64],
            )
        };
        let has_normals = !mesh.normals.is_empty();
        for (f, tri) in mesh.indices.chunks(3).enumerate() {
            if tri.len() != 3 {
                return Err(bad_input(format!(
                    "{origin}: {at}.obj '{file}' has an incomplete face"
                )));
            }
            let p = [pos(tri[0])?, pos(tri[1])?, pos(tri[2])?];
            let n = if has_normals {
                let mut n = [DVec3::ZERO; 3];
                for k in 0..3 {
                    let i = tri[k] as usize * 3;
                    let v = mesh.normals.get(i..i + 3).ok_or_else(|| {
                        bad_input(format!(
                            "{origin}: {at}.obj '{file}' has a normal index beyond its normal list"
                        ))
                    })?;
                    n[k] = unit_normal(
                        origin,
                        &format!("{at}.obj '{file}' face {} normal {k}", f + 1),
                        [v[0] as f64, v[1] as f64, v[2] as f64],
                    )?;
                }
                Some(n)
            } else {
                None
            };
            out.push((p, n));
        }
    }
    Ok(out)
}
