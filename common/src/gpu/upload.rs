//! The bytes both apps upload: a `Scene` converted into the layouts of
//! `gpu::layout`, every position relative to the scene's local origin
//! (`camera::local_origin`), made a chunk at a time as an upload asks for
//! them, and the checks of those buffers against a device's limits.

use crate::gpu::layout::{
    binding, child_ref, Bvh, GpuBvhNode, GpuBvhPrim, GpuBvhWideNode, GpuFrame, GpuLight,
    GpuMaterial, GpuSphere, GpuTriangle, PRIM_SPHERE_BIT,
};
use crate::limits::StorageLimit;
use crate::scene::camera::{local_origin, RayFrame};
use crate::scene::numerics::TriangleTest;
use crate::scene::{Camera, Scene, Triangle};
use bytemuck::Pod;
use glam::DVec3;
use rayon::prelude::*;

/// Everything a frame needs on the GPU. The small arrays are held as bytes;
/// the triangles, the BVH's nodes and its leaves' primitives, millions of each
/// for a fine mesh, are made from the scene and the tree only as an upload
/// asks for them, a chunk at a time (`write_storage`), so that the host never
/// holds a second full copy of the scene. Both apps upload exactly these bytes.
#[derive(Clone, Debug)]
pub struct GpuScene<'a> {
    pub frame: GpuFrame,
    pub spheres: Vec<GpuSphere>,
    pub materials: Vec<GpuMaterial>,
    pub lights: Vec<GpuLight>,
    /// The scene's triangles, in world coordinates.
    triangles: &'a [Triangle],
    /// Subtracted from every triangle vertex (`camera::local_origin`).
    origin: DVec3,
    /// Empty unless the scene traces through a binary BVH.
    bvh_nodes: &'a [GpuBvhNode],
    /// A wide tree's nodes, bound where `bvh_nodes` is when there are any.
    bvh_wide_nodes: &'a [GpuBvhWideNode],
    /// The leaves' primitive codes, expanded into `GpuBvhPrim`s.
    bvh_codes: &'a [u32],
    /// Whether a leaf triangle holds p0 and its two edges (the Möller–Trumbore
    /// test's inputs) rather than its three vertices (the watertight test's).
    leaf_edges: bool,
    /// The compute path's launch order (`plan::launch`), empty until
    /// `with_launch_order`: the shader then takes the tiles in rows.
    launch_order: Vec<u32>,
}

/// How many bytes of a storage buffer an upload converts at once, at most
/// (`chunks` rounds it down to whole elements); 48 MiB keeps a 16-core conversion and a copy busy without
/// a full-size staging copy.
pub const UPLOAD_CHUNK_BYTES: usize = 48 << 20;

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
            launch_grid: 0,
        }
    }
}

impl<'a> GpuScene<'a> {
    /// The buffers of `world` in its local frame: positions have the local
    /// origin subtracted in f64 before they become f32 (as `in_local_frame`
    /// does, element by element, without copying the scene), and `bvh` (where
    /// the run traces through one) was built over those translated primitives,
    /// so its boxes are rounded in the same frame.
    pub fn new(world: &'a Scene, bvh: Option<&'a Bvh>, width: u32, height: u32) -> GpuScene<'a> {
        let origin = local_origin(world);
        GpuScene {
            frame: GpuFrame::new(world, &world.camera, width, height),
            spheres: world
                .spheres
                .iter()
                .map(|s| GpuSphere {
                    center: v3(s.center - origin),
                    radius: s.radius as f32,
                    material: s.material,
                    pad: [0; 3],
                })
                .collect(),
            materials: world
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
            lights: world
                .lights
                .iter()
                .map(|l| GpuLight {
                    position: v3(l.position - origin),
                    color: v3(l.color),
                    ..Default::default()
                })
                .collect(),
            triangles: &world.triangles,
            origin,
            bvh_nodes: bvh.map_or(&[], |b| &b.nodes),
            bvh_wide_nodes: bvh.map_or(&[], |b| &b.wide),
            bvh_codes: bvh.map_or(&[], |b| &b.prims),
            leaf_edges: world.numerics.triangle == TriangleTest::MollerTrumbore,
            launch_order: Vec::new(),
        }
    }

    /// The same buffers with the compute path's launch order (binding 8):
    /// `tiles` of a grid of `across` × `down`, which the frame's
    /// `launch_grid` names so that the shader uses it. A grid too wide to
    /// pack (never, at the image sizes the limits allow) keeps the rows.
    pub fn with_launch_order(
        mut self,
        (across, down): (u32, u32),
        tiles: Vec<u32>,
    ) -> GpuScene<'a> {
        if across < 1 << 16 && down < 1 << 16 {
            self.frame.launch_grid = across << 16 | down;
            self.launch_order = tiles;
        }
        self
    }

    /// Triangle `i`'s vertices as the GPU holds them.
    fn positions(&self, i: usize) -> [[f32; 3]; 3] {
        self.triangles[i].p.map(|p| v3(p - self.origin))
    }

    /// Triangle `i` as the GPU holds it.
    pub fn triangle(&self, i: usize) -> GpuTriangle {
        let t = &self.triangles[i];
        let [p0, p1, p2] = self.positions(i);
        GpuTriangle {
            p0,
            material: t.material,
            p1,
            p2,
            n0: v3(t.n[0]),
            n1: v3(t.n[1]),
            n2: v3(t.n[2]),
            ..Default::default()
        }
    }

    /// The leaf primitive of `code`, from the same f32 values as the sphere
    /// and triangle buffers, so a leaf tests exactly the positions that the
    /// brute-force loops and the shading read (for Möller–Trumbore, as p0
    /// and the edges that its test subtracts from them).
    pub fn bvh_prim(&self, code: u32) -> GpuBvhPrim {
        if code & PRIM_SPHERE_BIT != 0 {
            let s = &self.spheres[(code & !PRIM_SPHERE_BIT) as usize];
            GpuBvhPrim {
                a: s.center,
                code,
                b: [s.radius, 0.0, 0.0],
                ..Default::default()
            }
        } else {
            let [a, mut b, mut c] = self.positions(code as usize);
            if self.leaf_edges {
                // The f32 subtractions the shader's hit_triangle makes: the
                // same values, so a leaf's hit is the brute-force loop's.
                b = std::array::from_fn(|k| b[k] - a[k]);
                c = std::array::from_fn(|k| c[k] - a[k]);
            }
            GpuBvhPrim {
                a,
                code,
                b,
                c,
                ..Default::default()
            }
        }
    }

    pub fn bvh_nodes(&self) -> &'a [GpuBvhNode] {
        self.bvh_nodes
    }

    pub fn bvh_wide_nodes(&self) -> &'a [GpuBvhWideNode] {
        self.bvh_wide_nodes
    }

    pub fn frame_bytes(&self) -> &[u8] {
        bytemuck::bytes_of(&self.frame)
    }

    /// The size in bytes of a storage buffer by binding number. An empty array
    /// still gets one zeroed element: neither API accepts a zero-sized buffer
    /// binding, and the counts in `Frame` keep the shader from reading it.
    pub fn storage_len(&self, binding: u32) -> usize {
        let (count, size) = match binding {
            binding::SPHERES => (self.spheres.len(), size_of::<GpuSphere>()),
            binding::TRIANGLES => (self.triangles.len(), size_of::<GpuTriangle>()),
            binding::MATERIALS => (self.materials.len(), size_of::<GpuMaterial>()),
            binding::LIGHTS => (self.lights.len(), size_of::<GpuLight>()),
            // The GPU's copy of a tree starts with a sentinel (`child_ref::GPU_ROOT`).
            binding::BVH_NODES if !self.bvh_wide_nodes.is_empty() => {
                (self.bvh_wide_nodes.len() + 1, size_of::<GpuBvhWideNode>())
            }
            binding::BVH_NODES if !self.bvh_nodes.is_empty() => {
                (self.bvh_nodes.len() + 1, size_of::<GpuBvhNode>())
            }
            binding::BVH_NODES => (0, size_of::<GpuBvhNode>()),
            binding::BVH_PRIMS => (self.bvh_codes.len(), size_of::<GpuBvhPrim>()),
            binding::LAUNCH_ORDER => (self.launch_order.len(), size_of::<u32>()),
            _ => panic!("binding {binding} is not a storage buffer"),
        };
        count.max(1) * size
    }

    /// Writes bytes `offset..offset + out.len()` of a storage buffer into
    /// `out` (a mapped staging buffer, or a chunk the app hands the driver).
    /// The triangles and the BVH's primitives are converted here, on every
    /// core; a range that does not start and end on whole elements, or an
    /// `out` not aligned for them, goes through a small copy.
    pub fn write_storage(&self, binding: u32, offset: usize, out: &mut [u8]) {
        assert!(
            offset + out.len() <= self.storage_len(binding),
            "bytes {offset}..{} of a {}-byte buffer",
            offset + out.len(),
            self.storage_len(binding)
        );
        match binding {
            binding::SPHERES => copy_elements(&self.spheres, offset, out),
            binding::MATERIALS => copy_elements(&self.materials, offset, out),
            binding::LIGHTS => copy_elements(&self.lights, offset, out),
            binding::LAUNCH_ORDER => copy_elements(&self.launch_order, offset, out),
            binding::BVH_NODES if !self.bvh_wide_nodes.is_empty() => convert(offset, out, |i| {
                gpu_node(self.bvh_wide_nodes, i, |n| n.on_gpu())
            }),
            binding::BVH_NODES if !self.bvh_nodes.is_empty() => {
                convert(offset, out, |i| gpu_node(self.bvh_nodes, i, |n| n.on_gpu()))
            }
            binding::TRIANGLES if !self.triangles.is_empty() => {
                convert(offset, out, |i| self.triangle(i))
            }
            binding::BVH_PRIMS if !self.bvh_codes.is_empty() => {
                convert(offset, out, |i| self.bvh_prim(self.bvh_codes[i]))
            }
            // The one zeroed element of an empty array.
            _ => out.fill(0),
        }
    }

    /// A whole storage buffer's bytes: for small buffers and tests (an upload
    /// goes through `write_storage` a chunk at a time).
    pub fn storage_vec(&self, binding: u32) -> Vec<u8> {
        let mut bytes = vec![0; self.storage_len(binding)];
        self.write_storage(binding, 0, &mut bytes);
        bytes
    }

    /// The byte ranges, each at most `max_bytes` long (at least one element),
    /// in which an upload fills a storage buffer: whole elements each.
    pub fn chunks(&self, binding: u32, max_bytes: usize) -> Vec<std::ops::Range<usize>> {
        let len = self.storage_len(binding);
        let step = max_bytes.max(UPLOAD_CHUNK_ALIGN) / UPLOAD_CHUNK_ALIGN * UPLOAD_CHUNK_ALIGN;
        (0..len)
            .step_by(step)
            .map(|start| start..(start + step).min(len))
            .collect()
    }

    /// The largest storage buffer, to check against the device's limit.
    pub fn largest_storage(&self) -> (u32, usize) {
        binding::STORAGE
            .iter()
            .map(|&b| (b, self.storage_len(b)))
            .max_by_key(|(_, n)| *n)
            .unwrap_or((0, 0))
    }
}

/// A multiple of every element size (96, 64, 48, 32, 16 and a wide node's
/// 112 bytes), so that chunks hold whole elements.
const UPLOAD_CHUNK_ALIGN: usize = 1344;

/// Slot `i` of the GPU's copy of a tree: a zeroed sentinel, then the nodes one
/// slot later, their interior references moved with them (`child_ref::GPU_ROOT`).
fn gpu_node<T: Pod>(nodes: &[T], i: usize, on_gpu: impl Fn(&T) -> T) -> T {
    match i.checked_sub(child_ref::GPU_ROOT as usize) {
        Some(i) => on_gpu(&nodes[i]),
        None => T::zeroed(),
    }
}

/// Bytes `offset..` of `items` (one zeroed element when empty) into `out`.
fn copy_elements<T: Pod>(items: &[T], offset: usize, out: &mut [u8]) {
    if items.is_empty() {
        out.fill(0);
    } else {
        out.copy_from_slice(&bytemuck::cast_slice(items)[offset..offset + out.len()]);
    }
}

/// Fills `out`, bytes `offset..` of an array whose element `i` is `make(i)`,
/// in parallel: straight into `out` when the range holds whole, aligned
/// elements (every chunk an app asks for), through a copy otherwise.
fn convert<T: Pod + Send>(offset: usize, out: &mut [u8], make: impl Fn(usize) -> T + Sync) {
    let size = size_of::<T>();
    let first = offset / size;
    if offset % size == 0 && out.len() % size == 0 {
        if let Ok(items) = bytemuck::try_cast_slice_mut::<u8, T>(out) {
            items
                .par_iter_mut()
                .enumerate()
                .for_each(|(i, x)| *x = make(first + i));
            return;
        }
    }
    let end = (offset + out.len()).div_ceil(size);
    let items: Vec<T> = (first..end).into_par_iter().map(&make).collect();
    let skip = offset - first * size;
    out.copy_from_slice(&bytemuck::cast_slice(&items)[skip..skip + out.len()]);
}

pub fn storage_name(binding: u32) -> &'static str {
    match binding {
        binding::SPHERES => "spheres",
        binding::TRIANGLES => "triangles",
        binding::MATERIALS => "materials",
        binding::LIGHTS => "lights",
        binding::BVH_NODES => "BVH node",
        binding::BVH_PRIMS => "BVH primitive",
        binding::LAUNCH_ORDER => "launch order",
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
    use crate::scene::camera::{in_local_frame, local_origin, Orbit, LOCAL_ORIGIN_GRID_VIEWS};
    use crate::scene::OriginMode;
    use glam::DVec3;
    use std::borrow::Cow;

    /// The frame names the order's grid as trace.comp compares it with the
    /// dispatch's (`x << 16 | y`), and the buffer holds one word a tile.
    #[test]
    fn a_launch_order_names_its_grid_in_the_frame() {
        let s = Scene::load("box", &[]).unwrap();
        let g = GpuScene::new(&s, None, 8, 8);
        assert_eq!(g.frame.launch_grid, 0, "no order: rows");
        let g = g.with_launch_order((3, 5), (0..15).rev().collect());
        assert_eq!(g.frame.launch_grid, 3 << 16 | 5);
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&g.storage_vec(binding::LAUNCH_ORDER));
        assert_eq!(words, (0..15).rev().collect::<Vec<u32>>());
        let too_wide =
            GpuScene::new(&s, None, 8, 8).with_launch_order((1 << 16, 1), vec![0; 1 << 16]);
        assert_eq!(
            too_wide.frame.launch_grid, 0,
            "a grid that does not pack keeps the rows"
        );
    }

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
                .chain((0..s.triangles.len()).map(|i| g.triangle(i).p0))
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

    #[test]
    fn chunks_of_any_size_give_the_whole_buffers_bytes() {
        let s = Scene::load("teapot", &[]).unwrap();
        let bvh = Bvh::build(&s);
        let g = GpuScene::new(&s, Some(&bvh), 8, 8);
        for b in binding::STORAGE {
            let whole = g.storage_vec(b);
            assert_eq!(whole.len(), g.storage_len(b));
            for max in [1, 1000, 1 << 20] {
                let mut joined = Vec::new();
                for c in g.chunks(b, max) {
                    let mut bytes = vec![0; c.len()];
                    g.write_storage(b, c.start, &mut bytes);
                    joined.extend(bytes);
                }
                assert!(joined == whole, "binding {b}, chunks of {max}");
            }
            // A range that cuts elements goes through the copy, to the same bytes.
            let (start, end) = (7.min(whole.len()), 107.min(whole.len()));
            let mut bytes = vec![0; end - start];
            g.write_storage(b, start, &mut bytes);
            assert!(bytes == whole[start..end], "binding {b}, bytes 7..107");
        }
    }

    /// A leaf's triangle is the triangle buffer's to the bit: its vertices
    /// for the watertight test, and for Möller–Trumbore p0 and the edges that
    /// hit_triangle subtracts in f32 from them.
    #[test]
    fn the_leaves_hold_what_each_triangle_test_reads() {
        for (set, edges) in [("moller-trumbore", true), ("watertight", false)] {
            let s = Scene::load("teapot", &[("triangle".into(), set.into())]).unwrap();
            let bvh = Bvh::build(&s);
            let g = GpuScene::new(&s, Some(&bvh), 8, 8);
            let prims: Vec<GpuBvhPrim> =
                bytemuck::pod_collect_to_vec(&g.storage_vec(binding::BVH_PRIMS));
            let tris: Vec<GpuTriangle> =
                bytemuck::pod_collect_to_vec(&g.storage_vec(binding::TRIANGLES));
            let sub = |a: [f32; 3], b: [f32; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
            let mut checked = 0;
            for p in prims.iter().filter(|p| p.code & PRIM_SPHERE_BIT == 0) {
                let t = &tris[p.code as usize];
                let want = if edges {
                    [t.p0, sub(t.p1, t.p0), sub(t.p2, t.p0)]
                } else {
                    [t.p0, t.p1, t.p2]
                };
                let bits = |v: [[f32; 3]; 3]| v.map(|p| p.map(f32::to_bits));
                assert_eq!(
                    bits([p.a, p.b, p.c]),
                    bits(want),
                    "{set}, triangle {}",
                    p.code
                );
                checked += 1;
            }
            assert_eq!(checked, tris.len(), "{set}: every triangle in a leaf");
        }
    }
}
