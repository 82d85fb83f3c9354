//! The scene: one resolved, validated `Scene` in f64 that everything downstream
//! sees, and the files that make it. `load` reads a built-in scene, a scene file
//! or a random seed; `format` is the TOML schema (scenes/README.md); `overrides`
//! applies `--set`; `resolve` and `check` validate every value into a `Scene`;
//! `mesh` and `teapot` read OBJ and Bezier-patch meshes. Beside them: `camera`
//! (ray frames, the orbit, the local origin), `numerics` (the accuracy
//! choices), `accel` (`--accel` and the BVH), `random` and `hard` (the seeded
//! and the numerically hard scenes).
//!
//! This file holds the data model only; its children add to it and it imports none of them.

pub mod accel;
pub mod camera;
mod check;
mod format;
pub mod hard;
pub mod load;
pub mod mesh;
pub mod numerics;
pub mod overrides;
pub mod random;
mod resolve;
pub mod teapot;

use crate::error::bad_input;
use crate::value_name::ValueName;
use glam::DVec3;
use numerics::Numerics;

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
    pub origin: OriginMode,
    pub materials: Vec<Material>,
    pub lights: Vec<Light>,
    pub spheres: Vec<Sphere>,
    pub triangles: Vec<Triangle>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Features {
    pub spheres: bool,
    pub triangles: bool,
    pub mirror: bool,
    pub glass: bool,
}

impl Features {
    /// The ray stack's entries (the shader's STACK_SIZE; the f64 reference
    /// holds as many). Only glass makes the ray tree branch (reflected and
    /// refracted rays). A ray of depth d pushes its children only while
    /// d + 1 < max_depth, and each level's pop and two pushes leave one ray
    /// more: after a ray of depth d pushed, the stack holds at most d + 2, so
    /// max_depth at the deepest push (d = max_depth - 2), and no push is ever
    /// dropped (a brute-force shader declares one entry more:
    /// `Variant::ray_stack_declared` says why). Without glass a hit pushes at
    /// most one ray after popping one, so one entry serves every max depth,
    /// and every max depth compiles to one shader.
    pub fn ray_stack_entries(self, max_depth: u32) -> u32 {
        if self.glass {
            max_depth.max(1)
        } else {
            1
        }
    }
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

/// Where the GPU's coordinates are measured from (`--set origin=`, `[render] origin`).
// ValueEnum for its name only (`ValueName`): `--set` and scene files parse it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, serde::Serialize, clap::ValueEnum)]
pub enum OriginMode {
    /// The camera's look-at point, snapped to a power-of-two grid (`local_origin`).
    #[default]
    Local,
    /// The world origin: every coordinate converted to f32 as written (the
    /// behaviour before local origins, kept to measure what they gain).
    World,
}

impl OriginMode {
    pub const ALL: [OriginMode; 2] = [OriginMode::Local, OriginMode::World];

    /// Parses `local` or `world`; `what` names the source in the error.
    pub fn parse(value: &str, what: &str) -> anyhow::Result<OriginMode> {
        let v = value.trim().to_ascii_lowercase();
        OriginMode::ALL
            .into_iter()
            .find(|m| m.name() == v)
            .ok_or_else(|| bad_input(format!("{what}: '{value}' is not one of local, world")))
    }
}

impl Scene {
    pub fn features(&self) -> Features {
        // The materials first: where none has the property, no primitive is
        // read (a 4.9M-triangle mesh is 750 MB of them, two scans of which
        // were a tenth of the start-up).
        let used = |pred: &dyn Fn(&Material) -> bool| {
            let wanted: Vec<bool> = self.materials.iter().map(pred).collect();
            wanted.contains(&true)
                && self
                    .spheres
                    .iter()
                    .map(|s| s.material)
                    .chain(self.triangles.iter().map(|t| t.material))
                    .any(|m| wanted[m as usize])
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

    /// The scene as the GPU buffers hold it: every position, normal, radius and
    /// material value rounded to f32 (the camera is rounded in `RayFrame`). The
    /// reference traces this in f64, so its images differ from the GPU's by the
    /// GPU's arithmetic only, not by its inputs — which matters far from the
    /// origin, where f32 moves a vertex by up to half an ULP (1/32 at 1e6).
    pub fn rounded_to_f32(&self) -> Scene {
        let r = |x: f64| x as f32 as f64;
        let v = |x: DVec3| x.as_vec3().as_dvec3();
        let mut s = self.clone();
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
