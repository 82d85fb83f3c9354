//! The scene file as written: the TOML schema that serde reads (documented in
//! scenes/README.md), before any value is checked. `resolve` turns it into a `Scene`.

use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::Deserialize;

/// A fixed-size array that refuses a wrong number of elements. serde's own
/// `[T; N]` stops reading after N and drops the rest, so `eye = [0, 1, 5, 1]`
/// or a quad with five corners would be cut short without a word.
#[derive(Debug, Clone, Copy)]
pub(super) struct Exact<T, const N: usize>(pub(super) [T; N]);

pub(super) type V3 = Exact<f64, 3>;

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
    pub(super) fn rows(&self) -> [[f64; 3]; N] {
        self.0.map(|r| r.0)
    }
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub(super) struct SceneFile {
    #[serde(default)]
    pub(super) description: Option<String>,
    pub(super) camera: CameraDef,
    #[serde(default)]
    pub(super) render: RenderDef,
    pub(super) materials: Vec<MaterialDef>,
    #[serde(default)]
    pub(super) lights: Vec<LightDef>,
    #[serde(default)]
    pub(super) spheres: Vec<SphereDef>,
    #[serde(default)]
    pub(super) triangles: Vec<TriangleDef>,
    #[serde(default)]
    pub(super) quads: Vec<QuadDef>,
    #[serde(default)]
    pub(super) meshes: Vec<MeshDef>,
    #[serde(default)]
    pub(super) extra_spheres: Option<ExtraSpheresDef>,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub(super) struct CameraDef {
    pub(super) eye: V3,
    pub(super) look_at: V3,
    #[serde(default = "default_up")]
    pub(super) up: V3,
    #[serde(default = "default_fov")]
    pub(super) fov_y: f64,
}

fn default_up() -> V3 {
    Exact([0.0, 1.0, 0.0])
}
fn default_fov() -> f64 {
    45.0
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields, default)]
pub(super) struct RenderDef {
    pub(super) background: V3,
    pub(super) max_depth: u32,
    pub(super) min_weight: f64,
    pub(super) epsilon: f64,
    /// Numerics (see numerics.rs); absent keys keep the default configuration.
    pub(super) offset: Option<String>,
    pub(super) triangle: Option<String>,
    pub(super) sphere: Option<String>,
    /// `local` (default) or `world`: see `camera::local_origin`.
    pub(super) origin: Option<String>,
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
pub(super) struct MaterialDef {
    pub(super) name: String,
    #[serde(default = "zero3")]
    pub(super) ambient: V3,
    #[serde(default = "zero3")]
    pub(super) diffuse: V3,
    #[serde(default = "zero3")]
    pub(super) specular: V3,
    #[serde(default = "default_shininess")]
    pub(super) shininess: f64,
    #[serde(default)]
    pub(super) reflectivity: f64,
    #[serde(default)]
    pub(super) transparency: f64,
    #[serde(default = "default_ior")]
    pub(super) ior: f64,
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
pub(super) struct LightDef {
    pub(super) position: V3,
    #[serde(default = "default_light")]
    pub(super) color: V3,
}

fn default_light() -> V3 {
    Exact([1.0; 3])
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub(super) struct SphereDef {
    pub(super) center: V3,
    pub(super) radius: f64,
    pub(super) material: String,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub(super) struct TriangleDef {
    pub(super) vertices: Exact<V3, 3>,
    #[serde(default)]
    pub(super) normals: Option<Exact<V3, 3>>,
    pub(super) material: String,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub(super) struct QuadDef {
    pub(super) corners: Exact<V3, 4>,
    pub(super) material: String,
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub(super) struct MeshDef {
    /// A triangle mesh in an OBJ file ...
    #[serde(default)]
    pub(super) obj: Option<String>,
    /// ... or Bezier patches in the classic .bpt format, tessellated at load.
    #[serde(default)]
    pub(super) bpt: Option<String>,
    /// Quads per patch in u and v for `bpt` (2 triangles each); default 20 x 15.
    #[serde(default)]
    pub(super) tessellation: Option<Exact<u32, 2>>,
    pub(super) material: String,
    #[serde(default = "one")]
    pub(super) scale: f64,
    #[serde(default)]
    pub(super) rotate_y: f64,
    #[serde(default = "zero3")]
    pub(super) translate: V3,
    #[serde(default = "yes")]
    pub(super) smooth: bool,
}

fn one() -> f64 {
    1.0
}
fn yes() -> bool {
    true
}

#[derive(Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub(super) struct ExtraSpheresDef {
    pub(super) count: u32,
    pub(super) center: V3,
    pub(super) radius: f64,
    pub(super) material: String,
}
