//! GPU buffer layouts: the one Rust mirror of every struct in shaders/trace/*.glsl
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
    /// The grid of tiles the launch order (binding 8) was made for, as
    /// `tiles across << 16 | tiles down`; 0 for none (the fragment path, a
    /// window): the compute shader then takes its tiles in rows.
    pub launch_grid: u32,
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

/// `BvhNode` (std430 array element, binding 6): an interior node holding both
/// of its children's boxes, so that one 64-byte read gives the traversal
/// everything it needs to choose its next step (Aila and Laine 2009). With a
/// box per node instead, every step read the node, then each child's box, the
/// right child's only once its index had arrived. Node 0 is the root (on the
/// GPU, slot `child_ref::GPU_ROOT`: the upload shifts the tree). A child
/// is a reference (`child_ref`): an interior node's index, or a leaf's primitives.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct GpuBvhNode {
    pub left_min: [f32; 3],
    pub left: u32,
    pub left_max: [f32; 3],
    pub pad0: u32,
    pub right_min: [f32; 3],
    pub right: u32,
    pub right_max: [f32; 3],
    pub pad1: u32,
}

/// `BvhPrim` (std430 array element, binding 7): one primitive of a leaf, in
/// leaf order, holding only what the intersection tests read, so that a
/// leaf's primitives are one contiguous read (48 bytes each) instead of an
/// index each and then a 96-byte triangle elsewhere. `code` is the primitive
/// (`PRIM_SPHERE_BIT` for a sphere), which the hit keeps for shading.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct GpuBvhPrim {
    /// A triangle's p0, a sphere's centre.
    pub a: [f32; 3],
    pub code: u32,
    /// A triangle's p1, or under Möller–Trumbore (TRIANGLE_WATERTIGHT not
    /// defined) its edge p1 - p0, subtracted in f32 as the test would; a
    /// sphere's radius in x.
    pub b: [f32; 3],
    pub pad0: u32,
    /// A triangle's p2, or its edge p2 - p0 as `b`; zero for a sphere.
    pub c: [f32; 3],
    pub pad1: u32,
}

/// `BvhWideNode` (std430 array element, binding 6 in the wide variants,
/// read by shaders/trace/bvh.glsl): four children's boxes, one `vec4`
/// per corner coordinate, so that the traversal tests all four boxes with
/// vector arithmetic from seven 16-byte reads. A 4-wide tree has one per
/// node; an 8-wide tree two consecutive ones per node (children 0-3, then
/// 4-7), and an interior child reference is the index of its node's first.
/// A slot without a child holds `child_ref::NO_CHILD` and the inside-out
/// box of `EMPTY_SLOT_MIN` and `EMPTY_SLOT_MAX`, which no ray enters. The
/// GLSL declares the six corner fields as one array, `vec4 bounds[6]`, in
/// this order, so that a ray reads each axis's near and far planes by the
/// sign of its direction.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct GpuBvhWideNode {
    pub min_x: [f32; 4],
    pub min_y: [f32; 4],
    pub min_z: [f32; 4],
    pub max_x: [f32; 4],
    pub max_y: [f32; 4],
    pub max_z: [f32; 4],
    pub child: [u32; 4],
}

/// The RGBA32F texels of one `GpuBvhWideNode` where OpenGL reads the nodes
/// through a buffer texture (`shader::node_texels::node_texels_glsl`): the six
/// bounds, then the children's references as the seventh's bits.
pub const WIDE_NODE_TEXELS: u32 = (size_of::<GpuBvhWideNode>() / 16) as u32;

/// An empty slot's box, its min corner at +`f32::MAX` and its max corner at
/// -`f32::MAX`: inside out on every axis. The walk reads the near plane by
/// the ray's sign, and for an inside-out box that plane lies beyond the far
/// one (the two distances even have opposite signs), so the box's entry
/// exceeds its exit and no ray enters it, in any rounding and without
/// infinities; the walk needs no test of the slot's reference.
pub const EMPTY_SLOT_MIN: f32 = f32::MAX;
/// The max corner of an empty slot's box (`EMPTY_SLOT_MIN`).
pub const EMPTY_SLOT_MAX: f32 = -f32::MAX;

impl GpuBvhWideNode {
    /// A node of empty slots.
    pub fn empty() -> GpuBvhWideNode {
        GpuBvhWideNode {
            min_x: [EMPTY_SLOT_MIN; 4],
            min_y: [EMPTY_SLOT_MIN; 4],
            min_z: [EMPTY_SLOT_MIN; 4],
            max_x: [EMPTY_SLOT_MAX; 4],
            max_y: [EMPTY_SLOT_MAX; 4],
            max_z: [EMPTY_SLOT_MAX; 4],
            child: [child_ref::NO_CHILD; 4],
        }
    }

    /// This node with its interior children `by` nodes further on: a
    /// subtree laid out after others (leaves and empty slots stay).
    pub fn moved_by(mut self, by: u32) -> GpuBvhWideNode {
        for c in &mut self.child {
            if child_ref::as_leaf(*c).is_none() {
                *c += by;
            }
        }
        self
    }

    /// Slot `k`'s box.
    pub fn bounds(&self, k: usize) -> Bounds {
        (
            [self.min_x[k], self.min_y[k], self.min_z[k]],
            [self.max_x[k], self.max_y[k], self.max_z[k]],
        )
    }

    /// This node as the GPU's copy of the tree holds it (`child_ref::GPU_ROOT`).
    pub fn on_gpu(&self) -> GpuBvhWideNode {
        GpuBvhWideNode {
            child: self.child.map(child_ref::on_gpu),
            ..*self
        }
    }

    pub fn set(&mut self, k: usize, (min, max): Bounds, child: u32) {
        [self.min_x[k], self.min_y[k], self.min_z[k]] = min;
        [self.max_x[k], self.max_y[k], self.max_z[k]] = max;
        self.child[k] = child;
    }
}

/// A child box, as f32 corners rounded outwards.
pub type Bounds = ([f32; 3], [f32; 3]);

impl GpuBvhNode {
    /// This node as the GPU's copy of the tree holds it (`child_ref::GPU_ROOT`).
    pub fn on_gpu(&self) -> GpuBvhNode {
        GpuBvhNode {
            left: child_ref::on_gpu(self.left),
            right: child_ref::on_gpu(self.right),
            ..*self
        }
    }

    pub fn new(
        (left_min, left_max): Bounds,
        left: u32,
        (right_min, right_max): Bounds,
        right: u32,
    ) -> GpuBvhNode {
        GpuBvhNode {
            left_min,
            left,
            left_max,
            right_min,
            right,
            right_max,
            ..Default::default()
        }
    }
}

/// A child reference in a `GpuBvhNode` and on the traversal stack: with
/// `LEAF_BIT` clear, an interior node's index; with it set, a leaf, which holds
/// `prims[first .. first + count]` with `first` above `LEAF_FIRST_SHIFT` and
/// `count - 1` below it. The shader decodes it the same way (trace/bvh.glsl).
pub mod child_ref {
    pub const LEAF_BIT: u32 = 1 << 31;
    pub const LEAF_FIRST_SHIFT: u32 = 2;
    /// Primitives per leaf at most: what the count's two bits hold.
    pub const MAX_LEAF_COUNT: usize = 1 << LEAF_FIRST_SHIFT;
    /// Primitives a tree can hold: `first` has 29 bits.
    pub const MAX_PRIMS: usize = 1 << (31 - LEAF_FIRST_SHIFT);
    /// No child: an empty slot of a wide node. A leaf reference no tree has
    /// (its count bits say 4 and its first primitive is past any limit).
    pub const NO_CHILD: u32 = u32::MAX;

    /// The root's reference in the GPU's copy of the tree, where every node
    /// sits one slot later than in the tree the host builds: slot 0 is a
    /// sentinel no reference names, so 0 is never an interior node. A walk
    /// then descends only through references > 0 (one compare, like
    /// LEAF_BIT's) and ends even where every read of the tree returns zero,
    /// as Mesa 22.3's lavapipe and llvmpipe make happen for a SIMD vector's
    /// lanes that are no invocation (trace/bvh.glsl's `traverse` says more).
    pub const GPU_ROOT: u32 = 1;

    /// `r` as the GPU's copy holds it: an interior node one slot later.
    pub fn on_gpu(r: u32) -> u32 {
        if r & LEAF_BIT == 0 {
            r + GPU_ROOT
        } else {
            r
        }
    }

    pub fn leaf(first: u32, count: u32) -> u32 {
        debug_assert!((1..=MAX_LEAF_COUNT as u32).contains(&count) && (first as usize) < MAX_PRIMS);
        LEAF_BIT | (first << LEAF_FIRST_SHIFT) | (count - 1)
    }

    /// `Some((first, count))` for a leaf, `None` for an interior node.
    pub fn as_leaf(r: u32) -> Option<(usize, usize)> {
        (r & LEAF_BIT != 0).then(|| {
            let first = (r & !LEAF_BIT) >> LEAF_FIRST_SHIFT;
            let count = (r & (MAX_LEAF_COUNT as u32 - 1)) + 1;
            (first as usize, count as usize)
        })
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

/// In a BVH primitive's code (`Bvh::prims`, `GpuBvhPrim::code`): set for a sphere index, clear for a triangle index.
pub const PRIM_SPHERE_BIT: u32 = 1 << 31;

/// Binding numbers, shared by the shader build (GLSL binding map) and both apps.
pub mod binding {
    pub const FRAME: u32 = 0;
    pub const SPHERES: u32 = 1;
    pub const TRIANGLES: u32 = 2;
    pub const MATERIALS: u32 = 3;
    pub const LIGHTS: u32 = 4;
    /// The compute path's RGBA32F storage image (the fragment path has a colour attachment instead).
    pub const IMAGE: u32 = 5;
    /// The BVH's nodes (`GpuBvhNode`), which the shader walks.
    pub const BVH_NODES: u32 = 6;
    pub const BVH_PRIMS: u32 = 7;
    /// The compute path's launch order (`plan::launch`): the grid of tiles it
    /// was made for, then which tile each workgroup traces. (8 once held the
    /// parent links of a stackless traversal, measured and rejected.)
    pub const LAUNCH_ORDER: u32 = 8;
    // 9 held the counts of `--experiment storage-counts`, retired
    // (docs/findings/software-drivers.md#a-shader-per-draw).
    /// The counting variant's per-pixel ray counts (`GpuRayCount`), written
    /// only by the untimed counting frame; no other variant declares it.
    pub const RAY_COUNTS: u32 = 10;
    pub const LAST: u32 = RAY_COUNTS;
    /// OpenGL's `--experiment warp-probe` buffer (one word per multiprocessor),
    /// which only that experiment's GLSL declares (`shader::post::warp_probe_glsl`).
    pub const WARP_PROBE: u32 = 11;
    /// The storage buffers in binding order.
    pub const STORAGE: [u32; 7] = [
        SPHERES,
        TRIANGLES,
        MATERIALS,
        LIGHTS,
        BVH_NODES,
        BVH_PRIMS,
        LAUNCH_ORDER,
    ];
}

/// A flattened BVH: the nodes the shader walks (binding 6) and the primitive
/// codes in leaf order, from which the upload makes the leaves' `GpuBvhPrim`s
/// (binding 7). `Bvh::build` (scene/accel.rs) makes one.
#[derive(Debug, Clone, Default)]
pub struct Bvh {
    pub nodes: Vec<GpuBvhNode>,
    /// Leaf contents: a sphere index with `PRIM_SPHERE_BIT` set, or a triangle index.
    pub prims: Vec<u32>,
    pub build_ms: f64,
    /// Levels of the tree, leaves included: a single leaf is depth 1.
    pub depth: u32,
    /// Children per node: 2 (`nodes`), or 4 or 8 (`wide`, with `nodes` empty).
    pub width: u32,
    /// The wide tree (`Bvh::widen`, scene/accel/wide.rs): `width / 4`
    /// `GpuBvhWideNode`s per node, the root first.
    pub wide: Vec<GpuBvhWideNode>,
    /// The wide tree's traversal stack: the most entries any path can leave
    /// pending (every node on it pushes all its children but one).
    pub wide_stack: u32,
}
