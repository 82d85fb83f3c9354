//! The BVH builder: binned SAH over spheres and triangles together, in
//! parallel (rayon: the bins of a large node are counted in chunks at once, and
//! the two halves of a node are built at once), flattened depth-first into the
//! node array the shader walks (`gpu::layout::Bvh`, read by
//! shaders/trace/bvh.glsl), plus the primitive list its leaves point into.
//!
//! It works on the primitives as the GPU holds them, every coordinate rounded
//! to f32, so a box is exactly the box of what the GPU tests, and the f64
//! reference, which traces the same f32-rounded scene, builds the very same
//! tree. Every decision depends only on the input order, never on the thread
//! count or timing: the bins merge with min, max and integer sums, which give
//! the same answer in any order, so each run gives the same tree and the images
//! compare byte for byte.

use crate::gpu::layout::{child_ref, Bounds, Bvh, GpuBvhNode, GpuBvhPrim, PRIM_SPHERE_BIT};
use crate::scene::Scene;
use glam::Vec3A;
use rayon::prelude::*;

/// Primitives per leaf at most; SAH may stop splitting earlier.
pub const MAX_LEAF: usize = child_ref::MAX_LEAF_COUNT;
const BINS: usize = 16;
/// Relative cost of one node visit vs one primitive test, for SAH.
const TRAVERSAL_COST: f64 = 1.0;
const INTERSECT_COST: f64 = 1.0;
/// A node with at least this many primitives counts its bins in parallel
/// chunks of `BIN_CHUNK`: below it, the tasks would cost more than they save.
const PARALLEL_BINNING: usize = 1 << 15;
const BIN_CHUNK: usize = 1 << 13;
/// A subtree with at least this many primitives builds its two halves as
/// separate tasks.
const PARALLEL_SUBTREE: usize = 1 << 12;

/// An f32 box; empty when min > max. SIMD lanes: the builder's inner loops
/// are a few min and max operations per primitive.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Box3 {
    min: Vec3A,
    max: Vec3A,
}

impl Box3 {
    const EMPTY: Box3 = Box3 {
        min: Vec3A::INFINITY,
        max: Vec3A::NEG_INFINITY,
    };

    fn grow(&mut self, o: &Box3) {
        self.min = self.min.min(o.min);
        self.max = self.max.max(o.max);
    }

    fn grow_point(&mut self, p: Vec3A) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// In f64, so that near-equal plane costs are told apart the same way every run.
    fn area(&self) -> f64 {
        let d = (self.max.as_dvec3() - self.min.as_dvec3()).max(glam::DVec3::ZERO);
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    fn bounds(&self) -> Bounds {
        (self.min.to_array(), self.max.to_array())
    }
}

/// One primitive while building: its f32 box and its code (`PRIM_SPHERE_BIT`
/// | sphere, or triangle). 32 bytes; the centroid is recomputed when needed.
#[derive(Clone, Copy)]
#[repr(C, align(16))]
struct PrimRef {
    min: [f32; 3],
    code: u32,
    max: [f32; 3],
    pad: u32,
}

impl PrimRef {
    fn bounds(&self) -> Box3 {
        Box3 {
            min: Vec3A::from_array(self.min),
            max: Vec3A::from_array(self.max),
        }
    }
}

/// Twice a box's centre: only compared with itself, so the half is never taken.
fn centroid2(b: &Box3) -> Vec3A {
    b.min + b.max
}

/// The f32 box of a sphere as the GPU holds it (centre and radius rounded to
/// f32), rounded outwards so that it contains the sphere.
fn sphere_ref(center: glam::DVec3, radius: f64, code: u32) -> PrimRef {
    let (c, r) = (center.as_vec3().as_dvec3(), radius as f32 as f64);
    let lo = (c - r).to_array();
    let hi = (c + r).to_array();
    PrimRef {
        min: lo.map(|v| next_down(v as f32, v)),
        code,
        max: hi.map(|v| next_up(v as f32, v)),
        pad: 0,
    }
}

fn next_down(f: f32, exact: f64) -> f32 {
    if (f as f64) > exact {
        f.next_down()
    } else {
        f
    }
}

fn next_up(f: f32, exact: f64) -> f32 {
    if (f as f64) < exact {
        f.next_up()
    } else {
        f
    }
}

fn prim_refs(scene: &Scene) -> Vec<PrimRef> {
    let mut refs = Vec::with_capacity(scene.primitive_count());
    refs.extend(
        scene
            .spheres
            .iter()
            .enumerate()
            .map(|(i, s)| sphere_ref(s.center, s.radius, PRIM_SPHERE_BIT | i as u32)),
    );
    // The vertices rounded to f32 exactly as the upload rounds them: the min
    // and max of f32 values are f32 values, so the box is exact.
    refs.par_extend(scene.triangles.par_iter().enumerate().map(|(i, t)| {
        let p = t.p.map(|v| v.as_vec3());
        let (lo, hi) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
        PrimRef {
            min: lo.to_array(),
            code: i as u32,
            max: hi.to_array(),
            pad: 0,
        }
    }));
    refs
}

impl Bvh {
    pub fn build(scene: &Scene) -> Bvh {
        let start = std::time::Instant::now();
        let mut refs = prim_refs(scene);
        let mut bvh = Bvh::default();
        if !refs.is_empty() {
            let (bounds, centroids) = refs
                .par_chunks(BIN_CHUNK)
                .map(boxes)
                .reduce(
                    || (Box3::EMPTY, Box3::EMPTY),
                    |(mut b, mut c), (b2, c2)| {
                        b.grow(&b2);
                        c.grow(&c2);
                        (b, c)
                    },
                );
            let node = Node {
                bounds,
                centroids,
                first: 0,
            };
            // Zeroed pages that no node is written to are never touched, so
            // the slots cost about what the tree needs (see `build`).
            let mut slots = bytemuck::zeroed_vec(refs.len() - 1);
            let built = build(&mut refs, node, &mut slots);
            bvh.depth = built.depth;
            bvh.nodes = compact(slots, built.interior);
            if let Some((first, count)) = child_ref::as_leaf(built.child) {
                // Node 0 is always an interior node: a tree that is one leaf
                // gets a root whose two children are that leaf. The second
                // test of the same primitives finds nothing closer.
                let b = bounds.bounds();
                let leaf = child_ref::leaf(first as u32, count as u32);
                bvh.nodes.push(GpuBvhNode::new(b, leaf, b, leaf));
            }
            bvh.prims = refs.par_iter().map(|r| r.code).collect();
        }
        bvh.build_ms = start.elapsed().as_secs_f64() * 1e3;
        bvh
    }

    /// The traversal stack this tree needs (the shader's BVH_STACK): the
    /// traversal pushes at most one far child per interior level of the path
    /// it is on, so depth - 1 entries always suffice. At least 1, as GLSL has
    /// no empty arrays.
    pub fn stack_entries(&self) -> u32 {
        self.depth.saturating_sub(1).max(1)
    }

    /// Interior nodes (the GPU's node array; leaves live in their parents' child references).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// The tree's SAH cost with the builder's own costs: a node visit costs
    /// TRAVERSAL_COST and a primitive test INTERSECT_COST, each weighted by the
    /// chance that a ray through the root's box meets the box it is in (its
    /// area over the root's). Lower is a better tree for the same scene;
    /// comparable between builders because it reads only the flattened output.
    pub fn sah_cost(&self) -> f64 {
        let Some(root) = self.nodes.first() else {
            return 0.0;
        };
        let boxed = |(min, max): Bounds| Box3 {
            min: min.into(),
            max: max.into(),
        };
        let mut root_box = boxed((root.left_min, root.left_max));
        root_box.grow(&boxed((root.right_min, root.right_max)));
        let root_area = root_box.area().max(f64::MIN_POSITIVE);
        // Each interior node pays one visit for the ray that reaches it, and
        // each child box (node or leaf) is entered by the share of rays its area says.
        let mut cost = TRAVERSAL_COST;
        for n in &self.nodes {
            for (b, child) in [
                ((n.left_min, n.left_max), n.left),
                ((n.right_min, n.right_max), n.right),
            ] {
                let p = boxed(b).area() / root_area;
                cost += match child_ref::as_leaf(child) {
                    Some((_, count)) => INTERSECT_COST * count as f64 * p,
                    None => TRAVERSAL_COST * p,
                };
            }
        }
        cost
    }

    /// Bytes on the GPU: the nodes plus the leaves' primitives (`GpuBvhPrim`).
    pub fn bytes(&self) -> usize {
        std::mem::size_of_val(self.nodes.as_slice())
            + self.prims.len() * std::mem::size_of::<GpuBvhPrim>()
    }
}

/// A subtree to build: the box of its primitives, the box of their doubled
/// centroids, and where its primitives start in the final primitive list.
#[derive(Clone, Copy)]
struct Node {
    bounds: Box3,
    centroids: Box3,
    first: usize,
}

/// A built subtree: its child reference (a leaf, or `RELATIVE` for an interior
/// node, which is then the first of its slots), its interior node count and
/// its depth.
struct Built {
    child: u32,
    interior: usize,
    depth: u32,
}

/// The child reference of a built interior subtree until it is placed.
const RELATIVE: u32 = 0;

/// Builds the subtree over `refs` (which it reorders into leaf order) into
/// `slots`, one fewer than `refs`: a binary tree with a primitive or more in
/// each leaf has fewer interior nodes than primitives. The node goes first,
/// then the left subtree's slots (one fewer than its primitives), then the
/// right's, so every subtree's nodes are depth-first in its own window and
/// the two halves can be built at once; `compact` closes the gaps left at
/// the end of each window. An interior child is referred to by its distance
/// from its parent in the compacted array (the left child is always the next
/// node, the right one after the left's subtree), which the gaps do not change.
fn build(refs: &mut [PrimRef], node: Node, slots: &mut [GpuBvhNode]) -> Built {
    if refs.len() < PARALLEL_SUBTREE {
        let mut used = 0;
        let (child, depth) = build_serial(refs, node, slots, &mut used);
        return Built {
            child,
            interior: used,
            depth,
        };
    }
    let Some((mid, left, right)) = split(refs, &node) else {
        return Built {
            child: child_ref::leaf(node.first as u32, refs.len() as u32),
            interior: 0,
            depth: 1,
        };
    };
    let (lrefs, rrefs) = refs.split_at_mut(mid);
    let (own, rest) = slots
        .split_first_mut()
        .expect("two or more primitives have a slot");
    let (lslots, rslots) = rest.split_at_mut(mid - 1);
    let (l, r) = rayon::join(
        || build(lrefs, left, lslots),
        || build(rrefs, right, rslots),
    );
    *own = GpuBvhNode::new(
        left.bounds.bounds(),
        relative(l.child, 1),
        right.bounds.bounds(),
        relative(r.child, 1 + l.interior),
    );
    Built {
        child: RELATIVE,
        interior: 1 + l.interior + r.interior,
        depth: 1 + l.depth.max(r.depth),
    }
}

/// A child's reference as its parent holds it: a leaf's own, or an interior
/// child's distance from the parent.
fn relative(child: u32, distance: usize) -> u32 {
    if child == RELATIVE {
        distance as u32
    } else {
        child
    }
}

/// `build` for a small subtree: on this thread, depth-first into
/// `slots[*used..]`. Returns its child reference and depth.
fn build_serial(
    refs: &mut [PrimRef],
    node: Node,
    slots: &mut [GpuBvhNode],
    used: &mut usize,
) -> (u32, u32) {
    let Some((mid, left, right)) = split(refs, &node) else {
        return (child_ref::leaf(node.first as u32, refs.len() as u32), 1);
    };
    let index = *used;
    *used += 1;
    let (lrefs, rrefs) = refs.split_at_mut(mid);
    let (l, ldepth) = build_serial(lrefs, left, slots, used);
    let lsize = *used - index - 1;
    let (r, rdepth) = build_serial(rrefs, right, slots, used);
    slots[index] = GpuBvhNode::new(
        left.bounds.bounds(),
        relative(l, 1),
        right.bounds.bounds(),
        relative(r, 1 + lsize),
    );
    (RELATIVE, 1 + ldepth.max(rdepth))
}

/// Closes the gaps between the windows of `build`, in order, and turns the
/// relative child references into indices. A written slot is never all
/// zero: its left child is a leaf (LEAF_BIT) or at least one node away.
fn compact(mut slots: Vec<GpuBvhNode>, interior: usize) -> Vec<GpuBvhNode> {
    let mut w = 0;
    for r in 0..slots.len() {
        if slots[r].left != 0 {
            slots[w] = slots[r];
            w += 1;
        }
    }
    debug_assert_eq!(w, interior);
    slots.truncate(w);
    slots.shrink_to_fit();
    slots.par_iter_mut().enumerate().for_each(|(i, n)| {
        for c in [&mut n.left, &mut n.right] {
            if child_ref::as_leaf(*c).is_none() {
                *c += i as u32;
            }
        }
    });
    slots
}

/// The bins of one axis: each bin's box, its centroids' box and its count.
#[derive(Clone, Copy)]
struct Bin {
    bounds: Box3,
    centroids: Box3,
    count: u32,
}

type Bins = [[Bin; BINS]; 3];

const EMPTY_BIN: Bin = Bin {
    bounds: Box3::EMPTY,
    centroids: Box3::EMPTY,
    count: 0,
};

/// Where each axis's centroids fall into bins: the same arithmetic counts the
/// bins and later partitions, so the two always agree.
#[derive(Clone, Copy)]
struct Binning {
    min: Vec3A,
    scale: Vec3A,
}

impl Binning {
    fn new(centroids: &Box3) -> Binning {
        let extent = centroids.max - centroids.min;
        // A flat axis puts everything in bin 0, where no plane separates anything.
        let usable = extent.cmpgt(Vec3A::ZERO) & extent.is_finite_mask();
        let scale = Vec3A::select(usable, BINS as f32 / extent, Vec3A::ZERO);
        Binning {
            min: centroids.min,
            scale,
        }
    }

    /// The primitive's bin on each axis.
    fn bins(&self, c: Vec3A) -> [usize; 3] {
        let b = ((c - self.min) * self.scale).as_uvec3();
        b.min(glam::UVec3::splat(BINS as u32 - 1))
            .to_array()
            .map(|x| x as usize)
    }

    fn count(&self, refs: &[PrimRef]) -> Bins {
        let mut bins = [[EMPTY_BIN; BINS]; 3];
        for r in refs {
            let b = r.bounds();
            let c = centroid2(&b);
            for (axis, i) in bins.iter_mut().zip(self.bins(c)) {
                let bin = &mut axis[i];
                bin.bounds.grow(&b);
                bin.centroids.grow_point(c);
                bin.count += 1;
            }
        }
        bins
    }

    /// `count`, in parallel chunks for a large node. Min, max and integer sums
    /// give the same bins whichever way the chunks are merged.
    fn count_parallel(&self, refs: &[PrimRef]) -> Bins {
        if refs.len() < PARALLEL_BINNING {
            return self.count(refs);
        }
        refs.par_chunks(BIN_CHUNK)
            .map(|c| self.count(c))
            .reduce(
                || [[EMPTY_BIN; BINS]; 3],
                |mut a, b| {
                    for (x, y) in a.iter_mut().flatten().zip(b.iter().flatten()) {
                        x.bounds.grow(&y.bounds);
                        x.centroids.grow(&y.centroids);
                        x.count += y.count;
                    }
                    a
                },
            )
    }
}

/// The box of some primitives and the box of their doubled centroids.
fn boxes(refs: &[PrimRef]) -> (Box3, Box3) {
    let (mut b, mut c) = (Box3::EMPTY, Box3::EMPTY);
    for r in refs {
        let rb = r.bounds();
        b.grow(&rb);
        c.grow_point(centroid2(&rb));
    }
    (b, c)
}

/// Splits the node's primitives if SAH (or a leaf's size limit) says so:
/// reorders `refs` so the left half comes first and returns its length and
/// both halves. None makes the node a leaf.
fn split(refs: &mut [PrimRef], node: &Node) -> Option<(usize, Node, Node)> {
    let count = refs.len();
    if count <= 1 {
        return None;
    }
    let binning = Binning::new(&node.centroids);
    let bins = binning.count_parallel(refs);
    let Some((axis, last_left)) = best_plane(&bins, node, count) else {
        if count <= MAX_LEAF {
            return None;
        }
        // Too many for a leaf but no plane separates them (identical
        // centroids): split the list in the middle.
        let mid = count / 2;
        let half = |refs: &[PrimRef], first| {
            let (bounds, centroids) = boxes(refs);
            Node {
                bounds,
                centroids,
                first,
            }
        };
        return Some((
            mid,
            half(&refs[..mid], node.first),
            half(&refs[mid..], node.first + mid),
        ));
    };
    let side = |range: std::ops::Range<usize>, first| {
        let mut n = Node {
            bounds: Box3::EMPTY,
            centroids: Box3::EMPTY,
            first,
        };
        for b in &bins[axis][range] {
            n.bounds.grow(&b.bounds);
            n.centroids.grow(&b.centroids);
        }
        n
    };
    let mid = partition(refs, |r| binning.bins(centroid2(&r.bounds()))[axis] <= last_left);
    Some((
        mid,
        side(0..last_left + 1, node.first),
        side(last_left + 1..BINS, node.first + mid),
    ))
}

/// Binned SAH: the cheapest of BINS-1 planes per axis, as (axis, last bin on
/// the left), or None when a leaf is cheaper (and allowed) or no plane has
/// primitives on both sides. Ties go to the first plane found.
fn best_plane(bins: &Bins, node: &Node, count: usize) -> Option<(usize, usize)> {
    let leaf_cost = INTERSECT_COST * count as f64;
    let area = node.bounds.area().max(1e-300);
    let mut best: Option<(f64, usize, usize)> = None;
    for (a, axis) in bins.iter().enumerate() {
        // Sweep from the right for the right side's area and count per plane.
        let mut right = [(0.0, 0u32); BINS];
        let mut acc = Box3::EMPTY;
        let mut side = (0.0, 0);
        for i in (1..BINS).rev() {
            // An empty bin changes neither side: the plane beside it costs the
            // same, and the first of equal planes wins anyway, so it is skipped.
            if axis[i].count != 0 {
                acc.grow(&axis[i].bounds);
                side = (acc.area(), side.1 + axis[i].count);
            }
            right[i] = side;
        }
        let mut acc = Box3::EMPTY;
        let mut n = 0;
        for i in 0..BINS - 1 {
            if axis[i].count == 0 {
                continue;
            }
            acc.grow(&axis[i].bounds);
            n += axis[i].count;
            let (right_area, nr) = right[i + 1];
            if n == 0 || nr == 0 {
                continue;
            }
            let cost = TRAVERSAL_COST
                + INTERSECT_COST * (acc.area() * n as f64 + right_area * nr as f64) / area;
            if best.is_none_or(|b| cost < b.0) {
                best = Some((cost, a, i));
            }
        }
    }
    match best {
        Some((cost, a, i)) if cost < leaf_cost || count > MAX_LEAF => Some((a, i)),
        _ => None,
    }
}

/// Moves the primitives for which `left` holds to the front, keeping no
/// particular order within either side (but the same order every run), and
/// returns how many there are. Without a branch on `left`: which side a
/// primitive goes to is a coin toss to the branch predictor.
fn partition(refs: &mut [PrimRef], left: impl Fn(&PrimRef) -> bool) -> usize {
    // refs[..i] go left and refs[i..j] go right; the swap with i == j, or of
    // a right-going primitive to the front of the right side, changes nothing
    // that matters.
    let mut i = 0;
    for j in 0..refs.len() {
        let goes_left = left(&refs[j]);
        refs.swap(i, j);
        i += goes_left as usize;
    }
    i
}
