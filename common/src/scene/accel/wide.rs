//! The wide BVH (`--accel bvh4`, `bvh8`): the binary SAH tree of `build`
//! collapsed into nodes of four or eight children (`GpuBvhWideNode`, walked
//! by shaders/trace/bvh.glsl, and by the f64 reference the same way).
//! A wide node starts from its binary node's two children and keeps opening
//! the interior child with the largest box, the one a ray is likeliest to
//! enter, until it has `width` children or only leaves (the greedy collapse
//! of Embree's wide BVHs). The leaves are the binary tree's, primitives and
//! order alike, so the leaf primitive array is shared and only the nodes differ.
//!
//! Like the builder it depends only on the binary tree, so the wide tree is
//! as deterministic as the binary one.

use super::split::{Box3, INTERSECT_COST, TRAVERSAL_COST};
use crate::gpu::layout::{child_ref, Bounds, Bvh, GpuBvhNode, GpuBvhWideNode};

/// The widths a tree can have: binary, and the wide nodes of one or two `GpuBvhWideNode`s.
pub const WIDTHS: [u32; 3] = [2, 4, 8];

/// `GpuBvhWideNode`s per node of a tree of `width` children.
pub fn quads(width: u32) -> usize {
    (width as usize).div_ceil(4)
}

fn area((min, max): Bounds) -> f64 {
    Box3 {
        min: min.into(),
        max: max.into(),
    }
    .area()
}

/// A wide node's children before they are written: box and child reference.
type Kids = ([(Bounds, u32); 8], usize);

struct Collapse<'a> {
    binary: &'a [GpuBvhNode],
    width: usize,
    out: Vec<GpuBvhWideNode>,
}

impl Collapse<'_> {
    /// The children of the wide node that replaces binary node `index`.
    fn kids(&self, index: usize) -> Kids {
        let n = &self.binary[index];
        let mut kids: Kids = ([(([0.0; 3], [0.0; 3]), 0); 8], 2);
        kids.0[0] = ((n.left_min, n.left_max), n.left);
        kids.0[1] = ((n.right_min, n.right_max), n.right);
        // A tree of one leaf has a root whose two children are that leaf.
        if n.left == n.right && child_ref::as_leaf(n.left).is_some() {
            kids.1 = 1;
        }
        while kids.1 < self.width {
            // The interior child with the largest box; the first of equals.
            let mut open: Option<(usize, f64)> = None;
            for (i, &(b, c)) in kids.0[..kids.1].iter().enumerate() {
                let a = area(b);
                if child_ref::as_leaf(c).is_none() && open.is_none_or(|(_, best)| a > best) {
                    open = Some((i, a));
                }
            }
            let Some((i, _)) = open else { break };
            let n = &self.binary[kids.0[i].1 as usize];
            // Its two children take its place, in order, so that a node's
            // children stay in the binary tree's left-to-right order.
            kids.0.copy_within(i + 1..kids.1, i + 2);
            kids.0[i] = ((n.left_min, n.left_max), n.left);
            kids.0[i + 1] = ((n.right_min, n.right_max), n.right);
            kids.1 += 1;
        }
        kids
    }

    /// Writes the wide subtree of binary node `index`, depth-first (the
    /// node, then each interior child's subtree in slot order). Returns its
    /// index, its depth (leaves included) and the most stack entries a walk
    /// of it leaves pending: each node pushes every child it enters but the
    /// nearest, so all but one of its children on the way down.
    fn node(&mut self, index: usize) -> (u32, u32, u32) {
        let (kids, count) = self.kids(index);
        let at = self.out.len();
        self.out.extend(std::iter::repeat_n(
            GpuBvhWideNode::empty(),
            quads(self.width as u32),
        ));
        let (mut depth, mut below) = (2, 0);
        for (k, &(bounds, child)) in kids[..count].iter().enumerate() {
            let child = if child_ref::as_leaf(child).is_some() {
                child
            } else {
                let (r, d, s) = self.node(child as usize);
                depth = depth.max(1 + d);
                below = below.max(s);
                r
            };
            self.out[at + k / 4].set(k % 4, bounds, child);
        }
        (at as u32, depth, count as u32 - 1 + below)
    }
}

impl Bvh {
    /// This tree collapsed to `width` children a node (4 or 8; 2 keeps it
    /// binary). The binary nodes are dropped: the wide tree replaces them.
    pub fn widen(mut self, width: u32) -> Bvh {
        debug_assert!(WIDTHS.contains(&width), "width {width}");
        if width <= 2 || self.nodes.is_empty() {
            return self;
        }
        let start = std::time::Instant::now();
        let mut c = Collapse {
            binary: &self.nodes,
            width: width as usize,
            // A binary tree of n nodes collapses into about n / (width - 1) nodes.
            out: Vec::with_capacity(self.nodes.len() / (width as usize - 1) * quads(width) + 2),
        };
        let (_, depth, stack) = c.node(0);
        self.wide = c.out;
        self.width = width;
        self.depth = depth;
        self.wide_stack = stack;
        self.nodes = Vec::new();
        self.build_ms += start.elapsed().as_secs_f64() * 1e3;
        self
    }

    /// The children of wide node `index` (its first `GpuBvhWideNode`):
    /// box and reference of each occupied slot, in slot order.
    pub fn wide_children(&self, index: usize) -> impl Iterator<Item = (Bounds, u32)> + '_ {
        self.wide[index..index + quads(self.width)]
            .iter()
            .flat_map(|q| (0..4).map(move |k| (q.bounds(k), q.child[k])))
            .filter(|&(_, c)| c != child_ref::NO_CHILD)
    }

    /// `sah_cost` of the wide tree: a node visit costs TRAVERSAL_COST
    /// whatever its width, so it favours the wide tree by the extra box tests
    /// a visit makes; what it compares fairly is trees of one width.
    pub(super) fn wide_sah_cost(&self) -> f64 {
        let root: Vec<_> = self.wide_children(0).collect();
        let mut root_box = Box3::EMPTY;
        for &((min, max), _) in &root {
            root_box.grow(&Box3 {
                min: min.into(),
                max: max.into(),
            });
        }
        let root_area = root_box.area().max(f64::MIN_POSITIVE);
        let mut cost = TRAVERSAL_COST;
        for index in (0..self.wide.len()).step_by(quads(self.width)) {
            for (b, child) in self.wide_children(index) {
                let p = area(b) / root_area;
                cost += match child_ref::as_leaf(child) {
                    Some((_, count)) => INTERSECT_COST * count as f64 * p,
                    None => TRAVERSAL_COST * p,
                };
            }
        }
        cost
    }
}
