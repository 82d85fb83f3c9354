//! GPU buffer layouts: the one Rust mirror of every struct in shaders/trace.glsl
//! (`#[repr(C)]` + bytemuck), the binding numbers, and the flattened BVH as the
//! shader reads it. A test checks these layouts against naga's view of the GLSL.
//! The bottom layer of the crate: it imports nothing from it.

use bytemuck::{Pod, Zeroable};

/// Uniform block `Frame` (std140, binding 0).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct GpuFrame {
    pub eye: [f32; 3],
    pub min_weight: f32,
    pub top_left: [f32; 3],
    pub epsilon: f32,
    pub step_x: [f32; 3],
    pub max_depth: u32,
    pub step_y: [f32; 3],
    pub sphere_count: u32,
    pub background: [f32; 3],
    pub triangle_count: u32,
    pub light_count: u32,
    /// The image size, for the compute entry point's bounds check (the fragment
    /// path's viewport does that job there).
    pub width: u32,
    pub height: u32,
    pub pad: u32,
}

/// `Sphere` (std430 array element, binding 1).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct GpuSphere {
    pub center: [f32; 3],
    pub radius: f32,
    pub material: u32,
    pub pad: [u32; 3],
}

/// `Triangle` (std430 array element, binding 2): vertices, then per-vertex normals.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct GpuTriangle {
    pub p0: [f32; 3],
    pub material: u32,
    pub p1: [f32; 3],
    pub pad0: u32,
    pub p2: [f32; 3],
    pub pad1: u32,
    pub n0: [f32; 3],
    pub pad2: u32,
    pub n1: [f32; 3],
    pub pad3: u32,
    pub n2: [f32; 3],
    pub pad4: u32,
}

/// `Material` (std430 array element, binding 3).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct GpuMaterial {
    pub ambient: [f32; 3],
    pub reflectivity: f32,
    pub diffuse: [f32; 3],
    pub transparency: f32,
    pub specular: [f32; 3],
    pub shininess: f32,
    pub ior: f32,
    pub pad: [u32; 3],
}

/// `Light` (std430 array element, binding 4).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct GpuLight {
    pub position: [f32; 3],
    pub pad0: f32,
    pub color: [f32; 3],
    pub pad1: f32,
}

/// `BvhNode` (std430 array element, binding 6). Depth-first layout: an interior
/// node's left child is the next node and `left_or_first` is its right child;
/// a leaf (`count > 0`) holds `prims[left_or_first .. left_or_first + count]`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct GpuBvhNode {
    pub min: [f32; 3],
    pub left_or_first: u32,
    pub max: [f32; 3],
    pub count: u32,
}

impl GpuBvhNode {
    pub fn leaf((min, max): ([f32; 3], [f32; 3]), first: u32, count: u32) -> GpuBvhNode {
        GpuBvhNode {
            min,
            left_or_first: first,
            max,
            count,
        }
    }

    pub fn interior((min, max): ([f32; 3], [f32; 3]), right: u32) -> GpuBvhNode {
        GpuBvhNode {
            min,
            left_or_first: right,
            max,
            count: 0,
        }
    }
}

/// `RayCount` (std430 array element, binding 10): one pixel's rays by kind, as
/// the counting variant (COUNT_RAYS) traced them.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq, Eq)]
pub struct GpuRayCount {
    pub primary: u32,
    pub shadow: u32,
    /// Reflected from a surface that is not glass.
    pub mirror: u32,
    pub glass_reflected: u32,
    pub glass_refracted: u32,
}

/// In the BVH's primitive list (binding 7): set for a sphere index, clear for a triangle index.
pub const PRIM_SPHERE_BIT: u32 = 1 << 31;

/// Per BVH node (binding 8), for the stackless traversal: the parent's index
/// in the low bits and, for an interior node, the axis its children were split
/// on in the top two (the left child holds the lower side).
pub const LINK_AXIS_SHIFT: u32 = 30;
pub const LINK_PARENT_MASK: u32 = (1 << LINK_AXIS_SHIFT) - 1;

/// Binding numbers, shared by the shader build (GLSL binding map) and both apps.
pub mod binding {
    pub const FRAME: u32 = 0;
    pub const SPHERES: u32 = 1;
    pub const TRIANGLES: u32 = 2;
    pub const MATERIALS: u32 = 3;
    pub const LIGHTS: u32 = 4;
    /// The compute path's RGBA32F storage image (the fragment path has a colour attachment instead).
    pub const IMAGE: u32 = 5;
    /// 5 is the compute path's output image.
    pub const BVH_NODES: u32 = 6;
    pub const BVH_PRIMS: u32 = 7;
    pub const BVH_LINKS: u32 = 8;
    /// The sphere, triangle and light counts, where the shader reads them at
    /// run time (`--experiment storage-counts`) instead of baking them in.
    pub const COUNTS: u32 = 9;
    /// The counting variant's per-pixel ray counts (`GpuRayCount`), written
    /// only by the untimed counting frame; no other variant declares it.
    pub const RAY_COUNTS: u32 = 10;
    pub const LAST: u32 = RAY_COUNTS;
    /// The storage buffers in binding order.
    pub const STORAGE: [u32; 8] = [
        SPHERES, TRIANGLES, MATERIALS, LIGHTS, BVH_NODES, BVH_PRIMS, BVH_LINKS, COUNTS,
    ];
}

/// A flattened BVH, ready to upload: the three arrays the shader walks
/// (bindings 6, 7 and 8). `Bvh::build` (scene/accel.rs) makes one.
#[derive(Debug, Clone, Default)]
pub struct Bvh {
    pub nodes: Vec<GpuBvhNode>,
    /// Leaf contents: a sphere index with `PRIM_SPHERE_BIT` set, or a triangle index.
    pub prims: Vec<u32>,
    /// Per node: parent index and split axis (`LINK_*`), for the stackless traversal.
    pub links: Vec<u32>,
    pub build_ms: f64,
    pub depth: u32,
}
