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
//! the same answer in any order, and the partitions move primitives by fixed
//! chunks, so each run gives the same tree, byte for byte, and so the same
//! images.

use super::split::{boxes, split, Box3, Node, PrimRef, BIN_CHUNK, INTERSECT_COST, TRAVERSAL_COST};
use crate::gpu::layout::{child_ref, Bounds, Bvh, GpuBvhNode, GpuBvhPrim, PRIM_SPHERE_BIT};
use crate::scene::Scene;
use glam::DVec3;
use rayon::prelude::*;

/// A subtree with at least this many primitives builds its two halves as
/// separate tasks.
const PARALLEL_SUBTREE: usize = 1 << 12;

/// -0.0 as +0.0. SIMD min and max return either zero when both meet, so a
/// box merged in another order could hold the other one: same tree, other
/// bytes. The teapot has both (its y-up conversion negates zeros).
fn positive_zero(v: [f32; 3]) -> [f32; 3] {
    v.map(|x| x + 0.0)
}

/// The f32 box of a sphere as the GPU holds it (centre and radius rounded to
/// f32), rounded outwards so that it contains the sphere.
fn sphere_ref(center: glam::DVec3, radius: f64, code: u32) -> PrimRef {
    let (c, r) = (center.as_vec3().as_dvec3(), radius as f32 as f64);
    let lo = (c - r).to_array();
    let hi = (c + r).to_array();
    PrimRef {
        min: positive_zero(lo.map(|v| next_down(v as f32, v))),
        code,
        max: positive_zero(hi.map(|v| next_up(v as f32, v))),
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

/// The primitives' boxes, every position less `origin` (as `in_local_frame`
/// subtracts it, element by element, without copying the scene).
fn prim_refs(scene: &Scene, origin: DVec3) -> Vec<PrimRef> {
    let mut refs = Vec::with_capacity(scene.primitive_count());
    refs.extend(
        scene
            .spheres
            .iter()
            .enumerate()
            .map(|(i, s)| sphere_ref(s.center - origin, s.radius, PRIM_SPHERE_BIT | i as u32)),
    );
    // The vertices rounded to f32 exactly as the upload rounds them: the min
    // and max of f32 values are f32 values, so the box is exact.
    refs.par_extend(scene.triangles.par_iter().enumerate().map(|(i, t)| {
        let p = t.p.map(|v| (v - origin).as_vec3());
        let (lo, hi) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
        PrimRef {
            min: positive_zero(lo.to_array()),
            code: i as u32,
            max: positive_zero(hi.to_array()),
            pad: 0,
        }
    }));
    refs
}

impl Bvh {
    pub fn build(scene: &Scene) -> Bvh {
        Bvh::build_at(scene, DVec3::ZERO)
    }

    /// The tree of `scene` with `origin` subtracted from every position: the
    /// tree of `in_local_frame(scene)` when `origin` is its local origin,
    /// without a copy of the scene.
    pub fn build_at(scene: &Scene, origin: DVec3) -> Bvh {
        let start = std::time::Instant::now();
        let mut refs = prim_refs(scene, origin);
        let mut bvh = Bvh {
            width: 2,
            ..Bvh::default()
        };
        if !refs.is_empty() {
            let (bounds, centroids) = refs.par_chunks(BIN_CHUNK).map(boxes).reduce(
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
            let mut slots: Vec<GpuBvhNode> = bytemuck::zeroed_vec(refs.len() - 1);
            let built = build(&mut refs, node, &mut slots);
            bvh.prims = refs.par_iter().map(|r| r.code).collect();
            drop(refs);
            bvh.depth = built.depth;
            bvh.nodes = compact(slots, &built.runs, built.interior);
            if let Some((first, count)) = child_ref::as_leaf(built.child) {
                // Node 0 is always an interior node: a tree that is one leaf
                // gets a root whose two children are that leaf. The second
                // test of the same primitives finds nothing closer.
                let b = bounds.bounds();
                let leaf = child_ref::leaf(first as u32, count as u32);
                bvh.nodes.push(GpuBvhNode::new(b, leaf, b, leaf));
            }
        }
        bvh.build_ms = start.elapsed().as_secs_f64() * 1e3;
        bvh
    }

    /// The traversal stack this tree needs (the shader's BVH_STACK): the
    /// traversal pushes at most one far child per interior level of the path
    /// it is on, so depth - 1 entries always suffice. At least 1, as GLSL has
    /// no empty arrays. A wide tree's is `wide_stack`.
    pub fn stack_entries(&self) -> u32 {
        if self.width > 2 {
            return self.wide_stack.max(1);
        }
        self.depth.saturating_sub(1).max(1)
    }

    /// Interior nodes (the GPU's node array; leaves live in their parents' child references).
    pub fn node_count(&self) -> usize {
        if self.width > 2 {
            return self.wide.len() / super::wide::quads(self.width);
        }
        self.nodes.len()
    }

    /// The tree's SAH cost with the builder's own costs: a node visit costs
    /// TRAVERSAL_COST and a primitive test INTERSECT_COST, each weighted by the
    /// chance that a ray through the root's box meets the box it is in (its
    /// area over the root's). Lower is a better tree for the same scene;
    /// comparable between builders because it reads only the flattened output.
    pub fn sah_cost(&self) -> f64 {
        if self.width > 2 {
            return self.wide_sah_cost();
        }
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
            + std::mem::size_of_val(self.wide.as_slice())
            + self.prims.len() * std::mem::size_of::<GpuBvhPrim>()
    }
}

/// A built subtree: its child reference (a leaf, or `RELATIVE` for an interior
/// node, which is then the first of its slots), its interior node count and
/// its depth.
struct Built {
    child: u32,
    interior: usize,
    depth: u32,
    /// The written runs of its slots, (first slot, count), in order.
    runs: Vec<(usize, usize)>,
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
            runs: if used == 0 { vec![] } else { vec![(0, used)] },
        };
    }
    let Some((mid, left, right)) = split(refs, &node) else {
        return Built {
            child: child_ref::leaf(node.first as u32, refs.len() as u32),
            interior: 0,
            depth: 1,
            runs: vec![],
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
    let mut runs = Vec::with_capacity(1 + l.runs.len() + r.runs.len());
    runs.push((0, 1));
    runs.extend(l.runs.iter().map(|&(first, n)| (1 + first, n)));
    runs.extend(r.runs.iter().map(|&(first, n)| (mid + first, n)));
    Built {
        child: RELATIVE,
        interior: 1 + l.interior + r.interior,
        depth: 1 + l.depth.max(r.depth),
        runs,
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

/// Moves the written runs of the slots to the front, in order (closing the
/// gaps at the ends of the windows of `build`), in place: no run moves right,
/// so each is copied over gaps or runs already moved, and the tree never
/// exists twice. The slots beyond the nodes are freed, and the relative child
/// references become indices, on every core.
fn compact(
    mut slots: Vec<GpuBvhNode>,
    runs: &[(usize, usize)],
    interior: usize,
) -> Vec<GpuBvhNode> {
    let mut at = 0;
    for &(first, n) in runs {
        debug_assert!(first >= at);
        slots.copy_within(first..first + n, at);
        at += n;
    }
    debug_assert_eq!(at, interior);
    slots.truncate(interior);
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
