//! Scene files: the TOML format (documented in scenes/README.md), the built-in
//! scenes embedded in the binary, `--set` overrides, validation, and OBJ meshes
//! through tobj. Everything downstream sees one resolved, validated `Scene` in f64.

use crate::error::bad_input;
use crate::limits;
use crate::numerics::Numerics;
use glam::{DMat3, DVec3};
use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::Deserialize;
use std::collections::{HashMap, HashSet};
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

/// The largest `max_depth` a scene may ask for (`limits::MAX_DEPTH`); the shader's generic ray stack holds this + 1.
pub use crate::limits::MAX_DEPTH as MAX_DEPTH_LIMIT;

// ---------------------------------------------------------------- file format

/// A fixed-size array that refuses a wrong number of elements. serde's own
/// `[T; N]` stops reading after N and drops the rest, so `eye = [0, 1, 5, 1]`
/// or a quad with five corners would be cut short without a word.
#[derive(Debug, Clone, Copy)]
struct Exact<T, const N: usize>([T; N]);

type V3 = Exact<f64, 3>;

impl<'de, T: Deserialize<'de>, const N: usize> Deserialize<'de> for Exact<T, N> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Elements<T, const N: usize>(std::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de>, const N: usize> Visitor<'de> for Elements<T, N> {
            type Value = Exact<T, N>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                write!(f, "an array of exactly {N} elements")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
                let mut v = Vec::with_capacity(N);
                while let Some(x) = seq.next_element::<T>()? {
                    v.push(x);
                }
                let n = v.len();
                <[T; N]>::try_from(v)
                    .map(Exact)
                    .map_err(|_| de::Error::invalid_length(n, &self))
            }
        }
        d.deserialize_seq(Elements::<T, N>(std::marker::PhantomData))
    }
}

impl<const N: usize> Exact<Exact<f64, 3>, N> {
    fn rows(&self) -> [[f64; 3]; N] {
        self.0.map(|r| r.0)
    }
}

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
    eye: V3,
    look_at: V3,
    #[serde(default = "default_up")]
    up: V3,
    #[serde(default = "default_fov")]
    fov_y: f64,
}

fn default_up() -> V3 {
    Exact([0.0, 1.0, 0.0])
}
fn default_fov() -> f64 {
    45.0
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields, default)]
struct RenderDef {
    background: V3,
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
            background: Exact([0.0; 3]),
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
    #[serde(default = "zero3")]
    ambient: V3,
    #[serde(default = "zero3")]
    diffuse: V3,
    #[serde(default = "zero3")]
    specular: V3,
    #[serde(default = "default_shininess")]
    shininess: f64,
    #[serde(default)]
    reflectivity: f64,
    #[serde(default)]
    transparency: f64,
    #[serde(default = "default_ior")]
    ior: f64,
}

fn zero3() -> V3 {
    Exact([0.0; 3])
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
    position: V3,
    #[serde(default = "default_light")]
    color: V3,
}

fn default_light() -> V3 {
    Exact([1.0; 3])
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
struct SphereDef {
    center: V3,
    radius: f64,
    material: String,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
struct TriangleDef {
    vertices: Exact<V3, 3>,
    #[serde(default)]
    normals: Option<Exact<V3, 3>>,
    material: String,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
struct QuadDef {
    corners: Exact<V3, 4>,
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
    tessellation: Option<Exact<u32, 2>>,
    material: String,
    #[serde(default = "one")]
    scale: f64,
    #[serde(default)]
    rotate_y: f64,
    #[serde(default = "zero3")]
    translate: V3,
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
    center: V3,
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

/// Applies `--set` overrides to the parsed file. Only the syntax of each value
/// is checked here; its range is checked once, in `resolve`, with the same
/// limits as a value from the file. Returns the keys set, so that `resolve`
/// names `--set KEY` rather than the file when such a value is refused.
fn apply_overrides(
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
                crate::camera::OriginMode::parse(value, "--set origin")?;
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

/// Names the source of each value in error messages: the scene file and field,
/// or `--set KEY` for a value that an override replaced.
struct Labels<'a> {
    origin: &'a str,
    set: HashSet<String>,
}

impl Labels<'_> {
    /// A field of the file: "scene file 'a.toml': spheres[2].radius".
    fn field(&self, field: &str) -> String {
        format!("{}: {field}", self.origin)
    }

    /// A field that `--set key` may have replaced.
    fn settable(&self, key: &str, field: &str) -> String {
        if self.set.contains(key) {
            format!("--set {key}")
        } else {
            self.field(field)
        }
    }
}

// Every value is checked against what the GPU receives: an f32. A value finite
// in f64 may overflow f32 (1e300 becomes infinity) or underflow to zero
// (1e-300), so each check looks at the f32 as well.

/// Finite in f32.
fn finite(at: &str, v: f64) -> anyhow::Result<f64> {
    if v.is_finite() && (v as f32).is_finite() {
        Ok(v)
    } else {
        Err(bad_input(format!(
            "{at} = {v:?} is not finite in f32 (the GPU's precision)"
        )))
    }
}

/// From `lo` to `hi` (both finite in f32).
fn within(at: &str, v: f64, lo: f64, hi: f64) -> anyhow::Result<f64> {
    if !(lo..=hi).contains(&v) {
        return Err(bad_input(format!("{at} = {v:?} must be from {lo} to {hi}")));
    }
    Ok(v)
}

/// Above zero in f32 too (no zero or subnormal after rounding), and at most `hi`.
fn positive(at: &str, v: f64, hi: f64) -> anyhow::Result<f64> {
    let v = finite(at, v)?;
    if !(v > 0.0 && (v as f32) >= f32::MIN_POSITIVE) {
        return Err(bad_input(format!(
            "{at} = {v:?} must be positive (at least {:e} in f32)",
            f32::MIN_POSITIVE
        )));
    }
    if v > hi {
        return Err(bad_input(format!("{at} = {v:?} must be at most {hi:e}")));
    }
    Ok(v)
}

/// Finite and within `limits::MAX_COORDINATE`; for the hot loops over mesh
/// vertices, which format a label only for a vertex that fails.
fn coord_ok(p: DVec3) -> bool {
    p.is_finite() && p.abs().max_element() <= limits::MAX_COORDINATE
}

/// A point or offset within `limits::MAX_COORDINATE`.
fn coord3(at: &str, v: [f64; 3]) -> anyhow::Result<DVec3> {
    let p = DVec3::from_array(v);
    if !p.is_finite() {
        return Err(bad_input(format!(
            "{at} = {v:?} is not finite (NaN or infinity)"
        )));
    }
    if p.abs().max_element() > limits::MAX_COORDINATE {
        return Err(bad_input(format!(
            "{at} = {v:?} lies beyond the coordinate limit of {:e}",
            limits::MAX_COORDINATE
        )));
    }
    Ok(p)
}

/// A colour: each component from 0 to `limits::MAX_COLOUR`.
fn colour3(at: &str, v: [f64; 3]) -> anyhow::Result<DVec3> {
    let c = DVec3::from_array(v);
    if !c.is_finite() {
        return Err(bad_input(format!(
            "{at} = {v:?} is not finite (NaN or infinity)"
        )));
    }
    if c.min_element() < 0.0 {
        return Err(bad_input(format!("{at} = {v:?} has a negative component")));
    }
    if c.max_element() > limits::MAX_COLOUR {
        return Err(bad_input(format!(
            "{at} = {v:?} has a component above the limit of {:e}",
            limits::MAX_COLOUR
        )));
    }
    Ok(c)
}

/// A count against its limit, as a usize.
fn count(at: &str, n: u32, max: u32) -> anyhow::Result<usize> {
    limits::check_count(at, n as usize, max as usize)?;
    Ok(n as usize)
}

fn resolve(
    name: &str,
    def: SceneFile,
    labels: &Labels,
    files: &FileSource,
) -> anyhow::Result<Scene> {
    let origin = labels.origin;
    let field = |f: &str| labels.field(f);
    let cam = &def.camera;
    let camera = Camera {
        eye: coord3(&field("camera.eye"), cam.eye.0)?,
        look_at: coord3(&field("camera.look_at"), cam.look_at.0)?,
        up: coord3(&field("camera.up"), cam.up.0)?,
        fov_y: finite(&labels.settable("fov_y", "camera.fov_y"), cam.fov_y)?,
    };
    if !(camera.fov_y >= 1e-3 && camera.fov_y < 180.0) {
        return Err(bad_input(format!(
            "{} = {:?} must lie between 0.001 and 180 degrees",
            labels.settable("fov_y", "camera.fov_y"),
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
    let background = colour3(&field("render.background"), r.background.0)?;
    let depth_at = labels.settable("max_depth", "render.max_depth");
    if !(1..=limits::MAX_DEPTH).contains(&r.max_depth) {
        return Err(bad_input(format!(
            "{depth_at} = {} must be from 1 to {}",
            r.max_depth,
            limits::MAX_DEPTH
        )));
    }
    let weight_at = labels.settable("min_weight", "render.min_weight");
    let min_weight = finite(&weight_at, r.min_weight)?;
    if min_weight < 0.0 {
        return Err(bad_input(format!(
            "{weight_at} = {min_weight:?} must not be negative"
        )));
    }
    let epsilon_at = labels.settable("epsilon", "render.epsilon");
    let epsilon = positive(&epsilon_at, r.epsilon, 1.0)?;
    if epsilon >= 1.0 {
        return Err(bad_input(format!(
            "{epsilon_at} = {epsilon:?} must lie between 0 and 1"
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
    limits::check_count(
        &field("materials (count)"),
        def.materials.len(),
        limits::MAX_MATERIALS,
    )?;
    let mut materials = Vec::new();
    let mut by_name: HashMap<String, u32> = HashMap::new();
    for (i, m) in def.materials.iter().enumerate() {
        let at = field(&format!("materials[{i}] ('{}')", m.name));
        let mat = Material {
            name: m.name.clone(),
            ambient: colour3(&format!("{at}.ambient"), m.ambient.0)?,
            diffuse: colour3(&format!("{at}.diffuse"), m.diffuse.0)?,
            specular: colour3(&format!("{at}.specular"), m.specular.0)?,
            shininess: finite(&format!("{at}.shininess"), m.shininess)?,
            reflectivity: within(&format!("{at}.reflectivity"), m.reflectivity, 0.0, 1.0)?,
            transparency: within(&format!("{at}.transparency"), m.transparency, 0.0, 1.0)?,
            ior: finite(&format!("{at}.ior"), m.ior)?,
        };
        if mat.shininess < 0.0 {
            return Err(bad_input(format!(
                "{at}.shininess = {:?} must not be negative",
                mat.shininess
            )));
        }
        if mat.reflectivity + mat.transparency > 1.0 {
            return Err(bad_input(format!(
                "{at}: reflectivity + transparency must not exceed 1"
            )));
        }
        if mat.ior <= 0.0 {
            return Err(bad_input(format!(
                "{at}.ior = {:?} must be positive",
                mat.ior
            )));
        }
        within(
            &format!("{at}.ior"),
            mat.ior,
            limits::MIN_IOR,
            limits::MAX_IOR,
        )?;
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
                "{at}.material '{name}' is not a defined material (defined: {})",
                known
                    .iter()
                    .map(|s| s.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })
    };

    limits::check_count(
        &field("lights (count)"),
        def.lights.len(),
        limits::MAX_LIGHTS,
    )?;
    let mut lights = Vec::new();
    for (i, l) in def.lights.iter().enumerate() {
        lights.push(Light {
            position: coord3(&field(&format!("lights[{i}].position")), l.position.0)?,
            color: colour3(&field(&format!("lights[{i}].color")), l.color.0)?,
        });
    }

    let sphere = |at: &str, center: [f64; 3], radius: f64, mat: &str| -> anyhow::Result<Sphere> {
        Ok(Sphere {
            center: coord3(&format!("{at}.center"), center)?,
            radius: positive(&format!("{at}.radius"), radius, limits::MAX_COORDINATE)?,
            material: material(at, mat)?,
        })
    };
    let extra = match &def.extra_spheres {
        Some(e) => {
            let n = count(
                &labels.settable("extra_spheres", "extra_spheres.count"),
                e.count,
                limits::MAX_EXTRA_SPHERES,
            )?;
            Some((
                sphere(&field("extra_spheres"), e.center.0, e.radius, &e.material)?,
                n,
            ))
        }
        None => None,
    };
    let sphere_count = def.spheres.len() + extra.as_ref().map_or(0, |e| e.1);
    limits::check_count(
        &field("spheres + extra_spheres.count"),
        sphere_count,
        limits::MAX_SPHERES,
    )?;
    let mut spheres = Vec::with_capacity(sphere_count);
    for (i, s) in def.spheres.iter().enumerate() {
        spheres.push(sphere(
            &field(&format!("spheres[{i}]")),
            s.center.0,
            s.radius,
            &s.material,
        )?);
    }
    if let Some((s, n)) = extra {
        spheres.extend(std::iter::repeat_n(s, n));
    }

    let mut triangles = Vec::new();
    for (i, t) in def.triangles.iter().enumerate() {
        let at = field(&format!("triangles[{i}]"));
        let mut p = [DVec3::ZERO; 3];
        for (k, v) in t.vertices.rows().into_iter().enumerate() {
            p[k] = coord3(&format!("{at}.vertices[{k}]"), v)?;
        }
        let n = match &t.normals {
            Some(ns) => {
                let mut n = [DVec3::ZERO; 3];
                for (k, v) in ns.rows().into_iter().enumerate() {
                    n[k] = unit_normal(&format!("{at}.normals[{k}]"), v)?;
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
        let at = field(&format!("quads[{i}]"));
        let mut c = [DVec3::ZERO; 4];
        for (k, v) in q.corners.rows().into_iter().enumerate() {
            c[k] = coord3(&format!("{at}.corners[{k}]"), v)?;
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
        let at = field(&format!("meshes[{i}]"));
        let mat = material(&at, &m.material)?;
        let scale = positive(&format!("{at}.scale"), m.scale, limits::MAX_COORDINATE)?;
        let rot =
            DMat3::from_rotation_y(finite(&format!("{at}.rotate_y"), m.rotate_y)?.to_radians());
        let translate = coord3(&format!("{at}.translate"), m.translate.0)?;
        // The room left under the triangle limit, so that no mesh is expanded beyond it.
        let room = limits::MAX_TRIANGLES - triangles.len().min(limits::MAX_TRIANGLES);
        let (obj, file) = match (&m.obj, &m.bpt) {
            (Some(obj), None) if m.tessellation.is_none() => (load_obj(&at, obj, files)?, obj),
            (None, Some(bpt)) => {
                let t = m.tessellation.map_or([20, 15], |t| t.0);
                let t_at = labels.settable("tessellation", &format!("meshes[{i}].tessellation"));
                (load_bpt(&at, &t_at, bpt, t, room, files)?, bpt)
            }
            _ => {
                return Err(bad_input(format!(
                    "{at} needs either `obj` or `bpt` (with an optional `tessellation`), not both"
                )))
            }
        };
        limits::check_count(
            &format!("{at}: triangles of '{file}' with those before it"),
            triangles.len() + obj.len(),
            limits::MAX_TRIANGLES,
        )?;
        let before = triangles.len();
        for (f, (p, n)) in obj.into_iter().enumerate() {
            let p = p.map(|v| rot * (v * scale) + translate);
            for v in p.iter().filter(|v| !coord_ok(**v)) {
                coord3(
                    &format!("{at}: '{file}' face {} after scale and translate", f + 1),
                    v.to_array(),
                )?;
            }
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
            return Err(bad_input(format!("{at}: '{file}' contains no faces")));
        }
    }
    let primitives = spheres.len() + triangles.len();
    limits::check_count(
        &field("spheres + triangles (the BVH's primitives)"),
        primitives,
        limits::MAX_BVH_PRIMITIVES,
    )?;

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
        bvh: primitives >= AUTO_BVH_MIN_PRIMITIVES,
        bvh_cache: BvhCache::default(),
        spheres,
        triangles,
    })
}

fn unit_normal(at: &str, v: [f64; 3]) -> anyhow::Result<DVec3> {
    let n = DVec3::from_array(v);
    if !n.is_finite() {
        return Err(bad_input(format!(
            "{at} = {v:?} is not finite (NaN or infinity)"
        )));
    }
    let len = n.length();
    if !(len > 1e-12 && len.is_finite()) {
        return Err(bad_input(format!("{at} = {v:?} has zero length")));
    }
    Ok(n / len)
}

/// The unit geometric normal, or zero for a degenerate triangle: the tracer never
/// hits those, so their normal is never used.
fn flat_normal(p: &[DVec3; 3]) -> DVec3 {
    (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero()
}

type ObjTriangle = ([DVec3; 3], Option<[DVec3; 3]>);

/// A file's text, refused with a message naming `what` when it is not a regular
/// file (`/dev/zero`, a pipe, a folder), is larger than `max` bytes, or is not
/// UTF-8 (with the line and column of the first bad byte).
pub fn read_file(what: &str, path: &Path, max: u64) -> anyhow::Result<String> {
    use std::io::Read;
    let cannot = |e: std::io::Error| bad_input(format!("{what} cannot be read: {e}"));
    let meta = std::fs::metadata(path).map_err(cannot)?;
    if !meta.is_file() {
        return Err(bad_input(format!(
            "{what} is not a regular file (a folder, device or pipe)"
        )));
    }
    let too_big = || {
        bad_input(format!(
            "{what} is larger than the limit of {max} bytes ({})",
            limits::gib(max)
        ))
    };
    if meta.len() > max {
        return Err(too_big());
    }
    // Read at most max + 1 bytes: the file may grow between the check and the read.
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    std::fs::File::open(path)
        .and_then(|f| f.take(max + 1).read_to_end(&mut bytes))
        .map_err(cannot)?;
    if bytes.len() as u64 > max {
        return Err(too_big());
    }
    String::from_utf8(bytes).map_err(|e| {
        let bad = e.utf8_error().valid_up_to();
        let good = std::str::from_utf8(&e.as_bytes()[..bad]).unwrap_or("");
        let (line, col) = line_col(good, good.len());
        bad_input(format!(
            "{what}, line {line}, column {col}: not UTF-8 text (byte 0x{:02x})",
            e.as_bytes()[bad]
        ))
    })
}

/// The text of a file a scene names: built in, or next to the scene file.
fn read_text(what: &str, file: &str, files: &FileSource) -> anyhow::Result<String> {
    match files {
        FileSource::Builtin => BUILTIN_FILES
            .iter()
            .find(|(n, _)| *n == file)
            .map(|(_, t)| t.to_string())
            .ok_or_else(|| bad_input(format!("{what} '{file}' is not a built-in file"))),
        FileSource::Dir(dir) => {
            let path = dir.join(file);
            read_file(
                &format!("{what} '{}'", path.display()),
                &path,
                limits::MAX_MESH_FILE_BYTES,
            )
        }
    }
}

/// Newell-style Bezier patches, tessellated as twinray-gen-teapot does.
/// `t_at` names the tessellation's source; `room` is how many triangles may still be added.
fn load_bpt(
    at: &str,
    t_at: &str,
    file: &str,
    [nu, nv]: [u32; 2],
    room: usize,
    files: &FileSource,
) -> anyhow::Result<Vec<ObjTriangle>> {
    let max = limits::MAX_TESSELLATION;
    if !(1..=max).contains(&nu) || !(1..=max).contains(&nv) {
        return Err(bad_input(format!(
            "{t_at} = {nu}x{nv}: each must be from 1 to {max}"
        )));
    }
    let text = read_text(&format!("{at}.bpt"), file, files)?;
    let patches = crate::teapot::parse_bpt(&text)
        .map_err(|e| bad_input(format!("{at}.bpt '{file}' is not a valid patch file: {e}")))?;
    // Counted before tessellating: a large patch count times a fine
    // tessellation must be refused, not allocated.
    let n = patches
        .len()
        .checked_mul(nu as usize * nv as usize * 2)
        .unwrap_or(usize::MAX);
    limits::check_count(
        &format!(
            "{at}: triangles of '{file}' ({} patches at {t_at} = {nu}x{nv}) with those before it",
            patches.len()
        ),
        n,
        room,
    )?;
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

fn load_obj(at: &str, file: &str, files: &FileSource) -> anyhow::Result<Vec<ObjTriangle>> {
    let text = read_text(&format!("{at}.obj"), file, files)?;
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj_buf(&mut text.as_bytes(), &opts, |_| {
        // Materials come from the scene file, never from an OBJ's mtllib.
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| bad_input(format!("{at}.obj '{file}' is not a valid OBJ file: {e}")))?;
    let mut out = Vec::new();
    for model in &models {
        let mesh = &model.mesh;
        let pos = |i: u32| -> anyhow::Result<DVec3> {
            let i = i as usize * 3;
            let v = mesh.positions.get(i..i + 3).ok_or_else(|| {
                bad_input(format!(
                    "{at}.obj '{file}' has a face index beyond its vertex list"
                ))
            })?;
            let p = DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
            if coord_ok(p) {
                return Ok(p);
            }
            coord3(
                &format!("{at}.obj '{file}' vertex {}", i / 3 + 1),
                p.to_array(),
            )
        };
        let has_normals = !mesh.normals.is_empty();
        for (f, tri) in mesh.indices.chunks(3).enumerate() {
            if tri.len() != 3 {
                return Err(bad_input(format!(
                    "{at}.obj '{file}' has an incomplete face"
                )));
            }
            let p = [pos(tri[0])?, pos(tri[1])?, pos(tri[2])?];
            let n = if has_normals {
                let mut n = [DVec3::ZERO; 3];
                for k in 0..3 {
                    let i = tri[k] as usize * 3;
                    let v = mesh.normals.get(i..i + 3).ok_or_else(|| {
                        bad_input(format!(
                            "{at}.obj '{file}' has a normal index beyond its normal list"
                        ))
                    })?;
                    let raw = DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
                    let len = raw.length();
                    n[k] = if len > 1e-12 && len.is_finite() {
                        raw / len
                    } else {
                        unit_normal(
                            &format!("{at}.obj '{file}' face {} normal {k}", f + 1),
                            raw.to_array(),
                        )?
                    };
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
