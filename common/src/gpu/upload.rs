//! The bytes both apps upload: a `Scene` converted into the layouts of
//! `gpu::layout`, every position relative to the scene's local origin
//! (`camera::local_origin`), and the checks of those buffers against a device's limits.

use crate::gpu::layout::{
    binding, Bvh, GpuBvhNode, GpuBvhPrim, GpuBvhWideNode, GpuFrame, GpuLight, GpuMaterial,
    GpuSphere, GpuTriangle, PRIM_SPHERE_BIT,
};
use crate::limits::StorageLimit;
use crate::scene::camera::{in_local_frame, RayFrame};
use crate::scene::{Camera, Scene};
use bytemuck::Pod;
use rayon::prelude::*;

/// Everything a frame needs on the GPU, as bytes. Both apps upload exactly these.
#[derive(Clone, Debug)]
pub struct GpuScene {
    pub frame: GpuFrame,
    pub spheres: Vec<GpuSphere>,
    pub triangles: Vec<GpuTriangle>,
    pub materials: Vec<GpuMaterial>,
    pub lights: Vec<GpuLight>,
    /// Empty unless the scene traces through a BVH.
    pub bvh_nodes: Vec<GpuBvhNode>,
    /// A wide tree's nodes, bound where `bvh_nodes` is when there are any.
    pub bvh_wide_nodes: Vec<GpuBvhWideNode>,
    /// The leaves' primitives, copied from `spheres` and `triangles`.
    pub bvh_prims: Vec<GpuBvhPrim>,
    /// Spheres, triangles, lights, and a pad word.
    pub counts: [u32; 4],
}

fn v3(v: glam::DVec3) -> [f32; 3] {
    v.as_vec3().to_array()
}

impl GpuFrame {
    /// The uniform block for `scene` seen through `camera` (the windowed apps
    /// pass the orbit camera; everything else passes `scene.camera`), the eye
    /// relative to the scene's local origin like the buffers of `GpuScene::new`.
    pub fn new(scene: &Scene, camera: &Camera, width: u32, height: u32) -> GpuFrame {
        let rf = RayFrame::local(scene, camera, width, height);
        GpuFrame {
            eye: v3(rf.eye),
            min_weight: scene.min_weight as f32,
            top_left: v3(rf.top_left),
            epsilon: scene.epsilon as f32,
            step_x: v3(rf.step_x),
            max_depth: scene.max_depth,
            step_y: v3(rf.step_y),
            sphere_count: scene.spheres.len() as u32,
            background: v3(scene.background),
            triangle_count: scene.triangles.len() as u32,
            light_count: scene.lights.len() as u32,
            width,
            height,
            pad: 0,
        }
    }
}

impl GpuScene {
    /// The buffers of `scene` in its local frame: positions have the local origin
    /// subtracted in f64 before they become f32, and `bvh` (where the run
    /// traces through one) was built over those translated primitives, so its
    /// boxes are rounded in the same frame.
    pub fn new(world: &Scene, bvh: Option<&Bvh>, width: u32, height: u32) -> GpuScene {
        let scene = &*in_local_frame(world);
        let empty = Bvh::default();
        let bvh = bvh.unwrap_or(&empty);
        let mut gpu = GpuScene {
            frame: GpuFrame::new(world, &world.camera, width, height),
            spheres: scene
                .spheres
                .iter()
                .map(|s| GpuSphere {
                    center: v3(s.center),
                    radius: s.radius as f32,
                    material: s.material,
                    pad: [0; 3],
                })
                .collect(),
            // Millions of triangles for a fine mesh: converted on every core.
            triangles: scene
                .triangles
                .par_iter()
                .map(|t| GpuTriangle {
                    p0: v3(t.p[0]),
                    material: t.material,
                    p1: v3(t.p[1]),
                    p2: v3(t.p[2]),
                    n0: v3(t.n[0]),
                    n1: v3(t.n[1]),
                    n2: v3(t.n[2]),
                    ..Default::default()
                })
                .collect(),
            materials: scene
                .materials
                .iter()
                .map(|m| GpuMaterial {
                    ambient: v3(m.ambient),
                    reflectivity: m.reflectivity as f32,
                    diffuse: v3(m.diffuse),
                    transparency: m.transparency as f32,
                    specular: v3(m.specular),
                    shininess: m.shininess as f32,
                    ior: m.ior as f32,
                    pad: [0; 3],
                })
                .collect(),
            lights: scene
                .lights
                .iter()
                .map(|l| GpuLight {
                    position: v3(l.position),
                    color: v3(l.color),
                    ..Default::default()
                })
                .collect(),
            bvh_nodes: bvh.nodes.clone(),
            bvh_wide_nodes: bvh.wide.clone(),
            bvh_prims: Vec::new(),
            counts: [
                scene.spheres.len() as u32,
                scene.triangles.len() as u32,
                scene.lights.len() as u32,
                0,
            ],
        };
        // Copied from the f32 buffers, so a leaf tests exactly the positions
        // that the brute-force loops and the shading read.
        gpu.bvh_prims = bvh
            .prims
            .par_iter()
            .map(|&code| gpu.bvh_prim(code))
            .collect();
        gpu
    }

    fn bvh_prim(&self, code: u32) -> GpuBvhPrim {
        if code & PRIM_SPHERE_BIT != 0 {
            let s = &self.spheres[(code & !PRIM_SPHERE_BIT) as usize];
            GpuBvhPrim {
                a: s.center,
                code,
                b: [s.radius, 0.0, 0.0],
                ..Default::default()
            }
        } else {
            let t = &self.triangles[code as usize];
            GpuBvhPrim {
                a: t.p0,
                code,
                b: t.p1,
                c: t.p2,
                ..Default::default()
            }
        }
    }

    pub fn frame_bytes(&self) -> &[u8] {
        bytemuck::bytes_of(&self.frame)
    }

    /// The bytes of a storage buffer by binding number. An empty array still gets
    /// one zeroed element: neither API accepts a zero-sized buffer binding, and the
    /// counts in `Frame` keep the shader from reading it.
    pub fn storage_bytes(&self, binding: u32) -> &[u8] {
        // Zeroes for the one element of an empty array (the largest struct is 96 bytes).
        static ZEROES: [u8; std::mem::size_of::<GpuTriangle>()] =
            [0; std::mem::size_of::<GpuTriangle>()];
        fn bytes<T: Pod>(v: &[T]) -> &[u8] {
            if v.is_empty() {
                &ZEROES[..std::mem::size_of::<T>()]
            } else {
                bytemuck::cast_slice(v)
            }
        }
        match binding {
            binding::SPHERES => bytes(&self.spheres),
            binding::TRIANGLES => bytes(&self.triangles),
            binding::MATERIALS => bytes(&self.materials),
            binding::LIGHTS => bytes(&self.lights),
            binding::BVH_NODES if !self.bvh_wide_nodes.is_empty() => {
                bytemuck::cast_slice(&self.bvh_wide_nodes)
            }
            binding::BVH_NODES => bytes(&self.bvh_nodes),
            binding::BVH_PRIMS => bytes(&self.bvh_prims),
            binding::COUNTS => bytes(&self.counts),
            _ => panic!("binding {binding} is not a storage buffer"),
        }
    }

    /// The largest storage buffer, to check against the device's limit.
    pub fn largest_storage(&self) -> (u32, usize) {
        binding::STORAGE
            .iter()
            .map(|&b| (b, self.storage_bytes(b).len()))
            .max_by_key(|(_, n)| *n)
            .unwrap_or((0, 0))
    }
}

pub fn storage_name(binding: u32) -> &'static str {
    match binding {
        binding::SPHERES => "spheres",
        binding::TRIANGLES => "triangles",
        binding::MATERIALS => "materials",
        binding::LIGHTS => "lights",
        binding::BVH_NODES => "BVH node",
        binding::BVH_PRIMS => "BVH primitive",
        binding::COUNTS => "counts",
        _ => "frame",
    }
}

/// A clear bad-input error when the scene's largest buffer exceeds the device limit.
pub fn check_storage_limit(gpu: &GpuScene, limit: &StorageLimit) -> anyhow::Result<()> {
    let (b, n) = gpu.largest_storage();
    if n as u64 > limit.bytes {
        // The BVH's buffers are the largest only when it is on, and brute
        // force needs less for the same scene.
        let remedy = match b {
            binding::BVH_NODES | binding::BVH_PRIMS => {
                "use fewer primitives, or trace without the BVH (--accel none)"
            }
            _ => "use fewer primitives",
        };
        return Err(crate::error::bad_input(format!(
            "the scene's {} buffer needs {n} bytes, more than {} ({} bytes); {remedy}",
            storage_name(b),
            limit.name,
            limit.bytes
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::camera::{local_origin, Orbit, LOCAL_ORIGIN_GRID_VIEWS};
    use crate::scene::OriginMode;
    use glam::DVec3;
    use std::borrow::Cow;

    #[test]
    fn near_scenes_keep_a_zero_origin_and_far_ones_trace_near_zero() {
        for (name, _) in crate::scene::load::BUILTIN_SCENES {
            let s = Scene::load(name, &[]).unwrap();
            assert_eq!(local_origin(&s), DVec3::ZERO, "{name}");
            assert!(matches!(in_local_frame(&s), Cow::Borrowed(_)), "{name}");
        }
        let dir = std::path::Path::new(crate::scene::hard::SOURCE_DIR);
        let mut moved = Vec::new();
        for case in crate::scene::hard::list(dir).unwrap() {
            let s = Scene::load(case.path.to_str().unwrap(), &[]).unwrap();
            let o = local_origin(&s);
            if o == DVec3::ZERO {
                continue;
            }
            moved.push(case.name.clone());
            // On the grid: a power of two times a whole number per axis.
            let view = (s.camera.eye - s.camera.look_at).length();
            let grid = (LOCAL_ORIGIN_GRID_VIEWS * view).log2().ceil().exp2();
            assert_eq!(o / grid, (o / grid).round(), "{}", case.name);
            // What the GPU holds lies within a few view distances of zero, and
            // `origin=world` gives the world coordinates back.
            let g = GpuScene::new(&s, None, 8, 8);
            let far = g
                .spheres
                .iter()
                .map(|x| x.center)
                .chain(g.triangles.iter().map(|t| t.p0))
                .chain(std::iter::once(g.frame.eye))
                .flat_map(|v| v.map(f32::abs))
                .fold(0.0f32, f32::max);
            assert!(far < 40.0 * view as f32, "{}: {far}", case.name);
            let mut world = s.clone();
            world.origin = OriginMode::World;
            assert_eq!(local_origin(&world), DVec3::ZERO);
            assert_eq!(
                GpuScene::new(&world, None, 8, 8).frame.eye,
                s.camera.eye.as_vec3().to_array()
            );
        }
        moved.sort();
        assert_eq!(
            moved,
            ["closed-mesh", "far-1e4", "far-1e5", "far-1e6", "far-1e7"],
            "the cases README.md names as moved"
        );
    }

    #[test]
    fn the_orbit_never_moves_the_origin() {
        let s = Scene::load(
            concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/hard/far-1e6.toml"),
            &[],
        )
        .unwrap();
        let o = local_origin(&s);
        let mut orbit = Orbit::new(&s.camera);
        orbit.drag(40.0, 25.0, 100);
        orbit.zoom(-5.0);
        let frame = GpuFrame::new(&s, &orbit.camera(), 8, 8);
        let expect = (orbit.camera().eye - o).as_vec3().to_array();
        assert_eq!(frame.eye, expect);
        // The origin comes from the scene's own camera, never the orbit's: a
        // zoom changes the view distance and so the grid, which would move it.
        assert_eq!(local_origin(&s), o);
    }
}
