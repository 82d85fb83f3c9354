//! From the file as written to a validated `Scene`: one function per kind of
//! scene element (camera, render settings, materials, lights, spheres,
//! triangles, quads, meshes), each checking its values in the order a reader
//! meets them in the file, so the first bad value is the one reported.

use crate::error::bad_input;
use crate::gpu::layout::GpuSphere;
use crate::limits::{self, StorageLimit};
use crate::scene::check::{
    colour3, coord3, coord_ok, count, finite, flat_normal, positive, unit_normal, within,
};
use crate::scene::format::{
    CameraDef, LightDef, MaterialDef, MeshDef, QuadDef, RenderDef, SceneFile, TriangleDef,
};
use crate::scene::mesh::{load_bpt, load_obj, FileSource, ObjTriangle};
use crate::scene::numerics::Numerics;
use crate::scene::{Camera, Light, Material, OriginMode, Scene, Sphere, Triangle};
use glam::{DMat3, DVec3};
use rayon::prelude::*;
use std::collections::{HashMap, HashSet};

/// Names the source of each value in error messages: the scene file and field,
/// or `--set KEY` for a value that an override replaced.
pub(super) struct Labels<'a> {
    pub(super) origin: &'a str,
    pub(super) set: HashSet<String>,
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

/// The render settings of `[render]`, checked.
struct Render {
    background: DVec3,
    max_depth: u32,
    min_weight: f64,
    epsilon: f64,
    numerics: Numerics,
    origin: OriginMode,
}

/// Material names to indices, for the elements that name one.
struct MaterialNames(HashMap<String, u32>);

impl MaterialNames {
    fn index(&self, at: &str, name: &str) -> anyhow::Result<u32> {
        self.0.get(name).copied().ok_or_else(|| {
            let mut known: Vec<&String> = self.0.keys().collect();
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
    }
}

pub(super) fn resolve(
    name: &str,
    def: SceneFile,
    labels: &Labels,
    files: &FileSource,
    limit: &StorageLimit,
) -> anyhow::Result<Scene> {
    let camera = camera(&def.camera, labels)?;
    let render = render(&def.render, labels)?;
    let (materials, names) = materials(&def.materials, labels)?;
    let lights = lights(&def.lights, labels)?;
    let spheres = spheres(&def, labels, &names, limit)?;
    let mut triangles = triangles(&def.triangles, labels, &names)?;
    quads(&def.quads, labels, &names, &mut triangles)?;
    for (i, m) in def.meshes.iter().enumerate() {
        mesh(i, m, (labels, &names, files, limit), &mut triangles)?;
    }
    let primitives = spheres.len() + triangles.len();
    limits::check_count(
        &labels.field("spheres + triangles (the BVH's primitives)"),
        primitives,
        limits::MAX_BVH_PRIMITIVES,
    )?;

    Ok(Scene {
        name: name.to_string(),
        description: def.description.unwrap_or_default(),
        camera,
        background: render.background,
        max_depth: render.max_depth,
        min_weight: render.min_weight,
        epsilon: render.epsilon,
        numerics: render.numerics,
        origin: render.origin,
        materials,
        lights,
        spheres,
        triangles,
    })
}

fn camera(cam: &CameraDef, labels: &Labels) -> anyhow::Result<Camera> {
    let field = |f: &str| labels.field(f);
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
            "{}: camera.eye, camera.look_at and camera.up must give a view direction not parallel to up",
            labels.origin
        )));
    }
    Ok(camera)
}

fn render(r: &RenderDef, labels: &Labels) -> anyhow::Result<Render> {
    let origin = labels.origin;
    let background = colour3(&labels.field("render.background"), r.background.0)?;
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
        Some(v) => OriginMode::parse(v, &format!("{origin}: render.origin"))?,
        None => Default::default(),
    };
    Ok(Render {
        background,
        max_depth: r.max_depth,
        min_weight,
        epsilon,
        numerics,
        origin: origin_mode,
    })
}

fn materials(
    defs: &[MaterialDef],
    labels: &Labels,
) -> anyhow::Result<(Vec<Material>, MaterialNames)> {
    let origin = labels.origin;
    if defs.is_empty() {
        return Err(bad_input(format!(
            "{origin}: the scene defines no [[materials]]"
        )));
    }
    limits::check_count(
        &labels.field("materials (count)"),
        defs.len(),
        limits::MAX_MATERIALS,
    )?;
    let mut materials = Vec::new();
    let mut by_name: HashMap<String, u32> = HashMap::new();
    for (i, m) in defs.iter().enumerate() {
        let at = labels.field(&format!("materials[{i}] ('{}')", m.name));
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
    Ok((materials, MaterialNames(by_name)))
}

fn lights(defs: &[LightDef], labels: &Labels) -> anyhow::Result<Vec<Light>> {
    limits::check_count(
        &labels.field("lights (count)"),
        defs.len(),
        limits::MAX_LIGHTS,
    )?;
    let mut lights = Vec::new();
    for (i, l) in defs.iter().enumerate() {
        lights.push(Light {
            position: coord3(
                &labels.field(&format!("lights[{i}].position")),
                l.position.0,
            )?,
            color: colour3(&labels.field(&format!("lights[{i}].color")), l.color.0)?,
        });
    }
    Ok(lights)
}

/// The listed spheres, then `extra_spheres` copies of its sphere, counted
/// against the limits before any is made.
fn spheres(
    def: &SceneFile,
    labels: &Labels,
    names: &MaterialNames,
    limit: &StorageLimit,
) -> anyhow::Result<Vec<Sphere>> {
    let field = |f: &str| labels.field(f);
    let sphere = |at: &str, center: [f64; 3], radius: f64, mat: &str| -> anyhow::Result<Sphere> {
        Ok(Sphere {
            center: coord3(&format!("{at}.center"), center)?,
            radius: positive(&format!("{at}.radius"), radius, limits::MAX_COORDINATE)?,
            material: names.index(at, mat)?,
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
    let what = field("spheres + extra_spheres.count");
    limits::check_count(&what, sphere_count, limits::MAX_SPHERES)?;
    let what = match &def.extra_spheres {
        Some(_) => labels.settable("extra_spheres", "spheres + extra_spheres.count"),
        None => what,
    };
    limit.check(&what, "spheres", sphere_count, size_of::<GpuSphere>())?;
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
    Ok(spheres)
}

fn triangles(
    defs: &[TriangleDef],
    labels: &Labels,
    names: &MaterialNames,
) -> anyhow::Result<Vec<Triangle>> {
    let mut triangles = Vec::new();
    for (i, t) in defs.iter().enumerate() {
        let at = labels.field(&format!("triangles[{i}]"));
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
            material: names.index(&at, &t.material)?,
        });
    }
    Ok(triangles)
}

/// Each quad as two flat triangles, appended to `triangles`.
fn quads(
    defs: &[QuadDef],
    labels: &Labels,
    names: &MaterialNames,
    triangles: &mut Vec<Triangle>,
) -> anyhow::Result<()> {
    for (i, q) in defs.iter().enumerate() {
        let at = labels.field(&format!("quads[{i}]"));
        let mut c = [DVec3::ZERO; 4];
        for (k, v) in q.corners.rows().into_iter().enumerate() {
            c[k] = coord3(&format!("{at}.corners[{k}]"), v)?;
        }
        let m = names.index(&at, &q.material)?;
        for p in [[c[0], c[1], c[2]], [c[0], c[2], c[3]]] {
            triangles.push(Triangle {
                p,
                n: [flat_normal(&p); 3],
                material: m,
            });
        }
    }
    Ok(())
}

/// Mesh `i`'s triangles, placed by its scale, rotation and translation,
/// appended to `triangles`.
fn mesh(
    i: usize,
    m: &MeshDef,
    (labels, names, files, limit): (&Labels, &MaterialNames, &FileSource, &StorageLimit),
    triangles: &mut Vec<Triangle>,
) -> anyhow::Result<()> {
    let at = labels.field(&format!("meshes[{i}]"));
    let mat = names.index(&at, &m.material)?;
    let scale = positive(&format!("{at}.scale"), m.scale, limits::MAX_COORDINATE)?;
    let rot = DMat3::from_rotation_y(finite(&format!("{at}.rotate_y"), m.rotate_y)?.to_radians());
    let translate = coord3(&format!("{at}.translate"), m.translate.0)?;
    // Each mesh counts its triangles with those before it, so that none is expanded beyond the limits.
    let before = (triangles.len(), limit);
    let (obj, file) = match (&m.obj, &m.bpt) {
        (Some(obj), None) if m.tessellation.is_none() => (load_obj(&at, obj, before, files)?, obj),
        (None, Some(bpt)) => {
            let t = m.tessellation.map_or([20, 15], |t| t.0);
            let t_at = labels.settable("tessellation", &format!("meshes[{i}].tessellation"));
            (load_bpt(&at, &t_at, bpt, t, before, files)?, bpt)
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
    let place = |(p, n): ObjTriangle| {
        let p = p.map(|v| rot * (v * scale) + translate);
        let n = match (m.smooth, n) {
            (true, Some(n)) => n.map(|v| rot * v),
            _ => [flat_normal(&p); 3],
        };
        Triangle {
            p,
            n,
            material: mat,
        }
    };
    // Millions of faces for a fine tessellation: placed on every core, each
    // written once, straight into its slot of the scene's list.
    triangles.reserve_exact(obj.len());
    triangles.par_extend((0..obj.len()).into_par_iter().map(|f| place(obj.get(f))));
    drop(obj);
    // The first face (in file order) that scale and translate moved out of range.
    let bad = |t: &Triangle| t.p.iter().any(|v| !coord_ok(*v));
    if let Some(f) = triangles[before..].par_iter().position_first(bad) {
        for v in triangles[before + f].p.iter().filter(|v| !coord_ok(**v)) {
            coord3(
                &format!("{at}: '{file}' face {} after scale and translate", f + 1),
                v.to_array(),
            )?;
        }
    }
    if triangles.len() == before {
        return Err(bad_input(format!("{at}: '{file}' contains no faces")));
    }
    Ok(())
}
