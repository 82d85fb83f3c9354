//! The wide BVH (`--accel bvh4`, `bvh8`): the binary SAH tree of `build`
//! collapsed into nodes of four or eight children (`GpuBvhWideNode`, walked
//! by shaders/trace/bvh.glsl, and by the f64 reference the same way).
//! Each node's children are those of the wide tree of least SAH cost over
//! the binary tree's leaves (`Optimal`). `--experiment greedy-collapse`
//! gives the collapse it replaced, which with the builder's finer top left
//! the teapot's frames up to 5 % longer in both APIs on the H200
//! (docs/findings/bvh.md#the-trees-top-h200), `Rule::Largest`: a wide node starts
//! from its binary node's two children and keeps opening the interior child
//! with the largest box, the one a ray is likeliest to enter, until it has
//! `width` children or only leaves (the greedy collapse of Embree's wide
//! BVHs). Of boxes of equal area it opens the one fewest binary levels down,
//! so that equal boxes (the sphere list's identical spheres) still give a
//! node two binary levels: first-of-equals made that tree 16 levels deep
//! instead of 10, and its stack too large for OpenGL to use every
//! multiprocessor (docs/findings/opengl-compute.md). The leaves are the
//! binary tree's, primitives and order alike, so the leaf primitive array
//! is shared and only the nodes differ.
//!
//! Like the builder it depends only on the binary tree, so the wide tree is
//! as deterministic as the binary one. The top levels are made first, the
//! subtrees below them collapsed side by side on every core, and the pieces
//! laid out where a depth-first collapse on one thread would put them.

use super::split::{Box3, INTERSECT_COST, TRAVERSAL_COST};
use crate::gpu::layout::{child_ref, Bounds, Bvh, GpuBvhNode, GpuBvhWideNode};
use rayon::prelude::*;

/// The widths a tree can have: binary, and the wide nodes of one or two `GpuBvhWideNode`s.
pub const WIDTHS: [u32; 3] = [2, 4, 8];

/// `GpuBvhWideNode`s per node of a tree of `width` children.
pub fn quads(width: u32) -> usize {
    (width as usize).div_ceil(4)
}

fn boxed((min, max): Bounds) -> Box3 {
    Box3 {
        min: min.into(),
        max: max.into(),
    }
}

fn area(b: Bounds) -> f64 {
    boxed(b).area()
}

/// A binary node's two children: box and child reference, left first.
fn children(n: &GpuBvhNode) -> [(Bounds, u32); 2] {
    [
        ((n.left_min, n.left_max), n.left),
        ((n.right_min, n.right_max), n.right),
    ]
}

/// A wide node's children before they are written: box and child reference.
type Kids = ([(Bounds, u32); 8], usize);

const NO_KIDS: Kids = ([(([0.0; 3], [0.0; 3]), 0); 8], 0);

/// How a binary subtree becomes a wide node's children.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Rule {
    /// Open the largest box, the shallowest of equals (`--experiment greedy-collapse`).
    Largest,
    /// Open the largest box, the first of equals (`--experiment first-of-equals`).
    FirstOfEquals,
    /// The children of least SAH cost (`widen`).
    Optimal,
}

/// Levels of the wide tree whose nodes are made first, on one thread; the
/// subtrees below them are then collapsed side by side (rayon). Four levels
/// of a 4-wide tree are up to 256 subtrees, enough for any core count here.
pub(super) const PARALLEL_LEVELS: u32 = 4;

struct Collapse<'a> {
    binary: &'a [GpuBvhNode],
    width: usize,
    rule: Rule,
    /// The optimal collapse's table, for `Rule::Optimal`.
    optimal: Option<Optimal<'a>>,
}

/// A run of the wide tree's nodes, in the order the tree lays them out.
enum Piece {
    /// A node of the top levels: its children, with the piece that holds
    /// each interior child's subtree.
    Top { kids: Box<Kids>, pieces: [usize; 8] },
    /// The whole subtree of a binary node, collapsed on its own, with its
    /// child references counted from its own first node; its depth and stack
    /// entries as `Collapse::node` returns them.
    Subtree {
        root: usize,
        nodes: Vec<GpuBvhWideNode>,
        depth: u32,
        stack: u32,
    },
}

impl Collapse<'_> {
    /// The children of the wide node that replaces binary node `index`.
    fn kids(&self, index: usize) -> Kids {
        let n = &self.binary[index];
        let mut kids: Kids = NO_KIDS;
        kids.0[..2].copy_from_slice(&children(n));
        kids.1 = 2;
        // A tree of one leaf has a root whose two children are that leaf.
        if n.left == n.right && child_ref::as_leaf(n.left).is_some() {
            kids.1 = 1;
            return kids;
        }
        if let Some(o) = &self.optimal {
            return o.kids(index);
        }
        // How many binary levels below this node each child is.
        let mut level = [1u32; 8];
        while kids.1 < self.width {
            // The interior child with the largest box; of equals, the one
            // fewest levels down, then the first.
            let mut open: Option<(usize, f64, u32)> = None;
            for (i, &(b, c)) in kids.0[..kids.1].iter().enumerate() {
                let a = area(b);
                // Of equal areas, first-of-equals opens the first: the
                // collapse as it was (lab/mod.rs).
                let shallower = |l| self.rule != Rule::FirstOfEquals && level[i] < l;
                let better =
                    |(_, best, l): (usize, f64, u32)| a > best || (a == best && shallower(l));
                if child_ref::as_leaf(c).is_none() && open.is_none_or(better) {
                    open = Some((i, a, level[i]));
                }
            }
            let Some((i, _, l)) = open else { break };
            let n = &self.binary[kids.0[i].1 as usize];
            // Its two children take its place, in order, so that a node's
            // children stay in the binary tree's left-to-right order.
            kids.0.copy_within(i + 1..kids.1, i + 2);
            level.copy_within(i + 1..kids.1, i + 2);
            kids.0[i..i + 2].copy_from_slice(&children(n));
            level[i] = l + 1;
            level[i + 1] = l + 1;
            kids.1 += 1;
        }
        kids
    }

    /// Writes the wide subtree of binary node `index`, depth-first (the
    /// node, then each interior child's subtree in slot order). Returns its
    /// index in `out`, and its depth and stack entries (`node_shape`).
    fn node(&self, index: usize, out: &mut Vec<GpuBvhWideNode>) -> (u32, u32, u32) {
        let (kids, count) = self.kids(index);
        let at = out.len();
        out.extend(std::iter::repeat_n(
            GpuBvhWideNode::empty(),
            quads(self.width as u32),
        ));
        let (mut below, mut n) = ([(0, 0); 8], 0);
        for (k, &(bounds, child)) in kids[..count].iter().enumerate() {
            let child = if child_ref::as_leaf(child).is_some() {
                child
            } else {
                let (r, d, s) = self.node(child as usize, out);
                below[n] = (d, s);
                n += 1;
                r
            };
            out[at + k / 4].set(k % 4, bounds, child);
        }
        let (depth, stack) = node_shape(count, &below[..n]);
        (at as u32, depth, stack)
    }

    /// The interior nodes of binary node `index`'s subtree, itself included.
    fn interior(&self, index: usize) -> usize {
        let n = &self.binary[index];
        let mut count = 1;
        for c in [n.left, n.right] {
            if child_ref::as_leaf(c).is_none() {
                count += self.interior(c as usize);
            }
        }
        count
    }

    /// The pieces of the subtree of binary node `index`, `level` levels
    /// below the root, appended to `pieces` in layout order (the node, then
    /// each interior child's subtree in slot order); returns the first.
    /// Below `levels` levels a subtree is one piece, collapsed later.
    fn top(&self, index: usize, level: u32, levels: u32, pieces: &mut Vec<Piece>) -> usize {
        let me = pieces.len();
        if level == levels {
            pieces.push(Piece::Subtree {
                root: index,
                nodes: Vec::new(),
                depth: 0,
                stack: 0,
            });
            return me;
        }
        let kids = self.kids(index);
        pieces.push(Piece::Top {
            kids: Box::new(kids),
            pieces: [0; 8],
        });
        let mut at = [0; 8];
        for (k, &(_, child)) in kids.0[..kids.1].iter().enumerate() {
            if child_ref::as_leaf(child).is_none() {
                at[k] = self.top(child as usize, level + 1, levels, pieces);
            }
        }
        if let Piece::Top { pieces: p, .. } = &mut pieces[me] {
            *p = at;
        }
        me
    }
}

/// The depth and stack entries of the subtree that starts at piece `i`, as
/// `Collapse::node` gives them for a whole tree.
fn shape(pieces: &[Piece], i: usize) -> (u32, u32) {
    match &pieces[i] {
        Piece::Subtree { depth, stack, .. } => (*depth, *stack),
        Piece::Top { kids, pieces: at } => {
            let below: Vec<(u32, u32)> = kids.0[..kids.1]
                .iter()
                .enumerate()
                .filter(|(_, &(_, child))| child_ref::as_leaf(child).is_none())
                .map(|(k, _)| shape(pieces, at[k]))
                .collect();
            node_shape(kids.1, &below)
        }
    }
}

/// A wide node's depth (leaves included) and the most stack entries a walk
/// of its subtree leaves pending, from its `children` and the depth and stack
/// entries of its interior children's subtrees: the walk pushes every child
/// it enters but the nearest, so all but one of a node's children on the way
/// down. The shader's BVH_STACK is this bound.
fn node_shape(children: usize, below: &[(u32, u32)]) -> (u32, u32) {
    let (depth, stack) = below
        .iter()
        .fold((2, 0), |(d, s), &(bd, bs)| (d.max(1 + bd), s.max(bs)));
    (depth, children as u32 - 1 + stack)
}

impl Bvh {
    /// This tree collapsed to `width` children a node (4 or 8; 2 keeps it
    /// binary), each node's children those of the wide tree of least SAH
    /// cost over the same leaves (`Optimal`). The binary nodes are dropped:
    /// the wide tree replaces them.
    pub fn widen(self, width: u32) -> Bvh {
        self.widen_on(width, PARALLEL_LEVELS, Rule::Optimal)
    }

    /// `widen` by the greedy rule, opening the largest box until a node is
    /// full (`--experiment greedy-collapse`).
    pub fn widen_greedy(self, width: u32) -> Bvh {
        self.widen_on(width, PARALLEL_LEVELS, Rule::Largest)
    }

    /// The greedy collapse opening the first of equal-area boxes instead of
    /// the shallowest (`--experiment first-of-equals`): the sphere list's
    /// tree as it was before, 16 levels deep at 100k spheres.
    pub fn widen_first_of_equals(self, width: u32) -> Bvh {
        self.widen_on(width, PARALLEL_LEVELS, Rule::FirstOfEquals)
    }

    /// `widen` by `rule`, with the top `levels` levels made first and the subtrees
    /// below them collapsed in parallel, then laid out in the order a
    /// depth-first collapse writes them: the same tree for every `levels`
    /// (0: the whole tree one subtree, on this thread), which a test holds.
    pub(super) fn widen_on(mut self, width: u32, levels: u32, rule: Rule) -> Bvh {
        debug_assert!(WIDTHS.contains(&width), "width {width}");
        if width <= 2 || self.nodes.is_empty() {
            return self;
        }
        let start = std::time::Instant::now();
        let c = Collapse {
            binary: &self.nodes,
            width: width as usize,
            rule,
            optimal: (rule == Rule::Optimal).then(|| Optimal::new(&self.nodes, width as usize)),
        };
        let mut pieces = Vec::new();
        c.top(0, 0, levels, &mut pieces);
        // Each subtree's memory taken here, on this thread, as much as it
        // can need: a wide subtree has no more nodes than its binary one has
        // interior nodes. Grown on the worker threads instead, it would come
        // from their allocators, which keep it after it is freed (a whole
        // wide tree's worth more resident memory for the rest of the run).
        let most: Vec<usize> = pieces
            .par_iter()
            .map(|p| match p {
                Piece::Subtree { root, .. } => c.interior(*root),
                Piece::Top { .. } => 0,
            })
            .collect();
        for (p, n) in pieces.iter_mut().zip(most) {
            if let Piece::Subtree { nodes, .. } = p {
                *nodes = Vec::with_capacity(n * quads(width));
            }
        }
        pieces.par_iter_mut().for_each(|p| {
            if let Piece::Subtree {
                root,
                nodes,
                depth,
                stack,
            } = p
            {
                (_, *depth, *stack) = c.node(*root, nodes);
            }
        });
        // The binary tree is done with: gone before the wide array is made,
        // so that the pieces and the array are the only trees in memory at
        // once (as the binary tree and the array were, before the pieces).
        drop(c);
        self.nodes = Vec::new();
        let (depth, stack) = shape(&pieces, 0);
        // Where each piece starts, in nodes.
        let q = quads(width);
        let mut starts = Vec::with_capacity(pieces.len());
        let mut len = 0;
        for p in &pieces {
            starts.push(len);
            len += match p {
                Piece::Top { .. } => q,
                Piece::Subtree { nodes, .. } => nodes.len(),
            };
        }
        // Each node made where it goes, on every thread: a node of the top
        // levels names its children where their pieces start; a subtree's
        // own references count from its first node.
        let mut wide = Vec::with_capacity(len);
        (0..len)
            .into_par_iter()
            .map(|i| {
                let p = starts.partition_point(|&s| s <= i) - 1;
                let at = starts[p];
                match &pieces[p] {
                    Piece::Top { kids, pieces: to } => {
                        let mut node = GpuBvhWideNode::empty();
                        let first = ((i - at) * 4).min(kids.1);
                        let slots = first..(first + 4).min(kids.1);
                        for (k, &(bounds, child)) in kids.0[slots.clone()].iter().enumerate() {
                            let child = match child_ref::as_leaf(child) {
                                Some(_) => child,
                                None => starts[to[slots.start + k]] as u32,
                            };
                            node.set(k, bounds, child);
                        }
                        node
                    }
                    Piece::Subtree { nodes, .. } => nodes[i - at].moved_by(at as u32),
                }
            })
            .collect_into_vec(&mut wide);
        self.wide = wide;
        self.width = width;
        self.depth = depth;
        self.wide_stack = stack;
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
        let mut root_box = Box3::EMPTY;
        for (b, _) in self.wide_children(0) {
            root_box.grow(&boxed(b));
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

/// The low bits of a key: the depth of what fills the slots (a leaf 1, a
/// kept interior node its wide subtree's depth). The cost is above them, so
/// that keys order by cost, then depth, and two keys add as costs do.
const DEPTH_BITS: u32 = 8;
const DEPTH: u64 = (1 << DEPTH_BITS) - 1;
/// A leaf in a slot: no cost, one level.
const LEAF: u64 = 1;
/// The largest cost a whole tree can reach, so that a cost and its depth bits
/// fit a u64: every interior node's area is at most the root's.
const MOST_COST: f64 = (1u64 << (63 - DEPTH_BITS)) as f64;
/// A subtree with fewer binary nodes fills its table on one thread.
const PARALLEL_NODES: usize = 1 << 12;

/// Two covers side by side: their costs add, the deeper one counts.
fn join(a: u64, b: u64) -> u64 {
    ((a & !DEPTH) + (b & !DEPTH)) | (a & DEPTH).max(b & DEPTH)
}

/// For one child of a binary node, the best cover of its subtree by at most
/// `i` slots (index `i`, from 1): its key and whether the child is opened
/// (its own children take the slots) rather than kept as one wide child.
type Slots = [(u64, bool); 8];

/// A choice of the table: the left child's share of the slots, and whether
/// each child is opened.
const SHARE: u8 = 0xf;
const OPEN_LEFT: u8 = 0x10;
const OPEN_RIGHT: u8 = 0x20;

/// The optimal collapse (`widen`): of the wide trees
/// whose leaves are the binary tree's and whose nodes' children are each a
/// cut of a binary subtree, kept in order, the one of least SAH cost, by
/// dynamic programming over the binary tree (Ylitie, Karras, Laine and Aila
/// 2017, "Efficient incoherent ray traversal on GPUs through compressed wide
/// BVHs", without its leaf merging). The leaves being fixed, so is their
/// share of the cost: what it minimises is the summed area of the interior
/// nodes. Of equal costs it keeps the shallowest tree (the sphere list's
/// identical spheres make many), then, node by node, a child kept whole over
/// one opened, then the fewest slots to the left child. Costs are whole
/// units of a share of the root's area, whose sums are exact in any order:
/// a tie is a tie however the table was filled, and the tree as
/// deterministic as the binary one. What is kept, for each node and each j
/// from 2 to the width, is how the best cover of its two children by at
/// most j slots shares them out: all that writing the tree needs.
struct Optimal<'a> {
    binary: &'a [GpuBvhNode],
    width: usize,
    /// The cost of the root's box: the most any node's can be.
    most: f64,
    /// Cost units per unit of area.
    unit: f64,
    /// `width - 1` choices a node, for j = 2..=width, in node order.
    choice: Vec<u8>,
}

impl<'a> Optimal<'a> {
    fn new(binary: &'a [GpuBvhNode], width: usize) -> Optimal<'a> {
        let root = &binary[0];
        let mut root_box = boxed((root.left_min, root.left_max));
        root_box.grow(&boxed((root.right_min, root.right_max)));
        let root_area = root_box.area().max(f64::MIN_POSITIVE);
        let most = (MOST_COST / (binary.len() + 1) as f64).floor();
        let mut o = Optimal {
            binary,
            width,
            most,
            unit: most / root_area,
            choice: Vec::new(),
        };
        // The keys only while the table fills: writing the tree needs only
        // the choices.
        let mut best = vec![0; binary.len() * (width - 1)];
        let mut choice = vec![0; best.len()];
        o.fill(0, binary.len(), &mut best, &mut choice);
        o.choice = choice;
        o
    }

    /// The children of the wide node that replaces binary node `index`.
    fn kids(&self, index: usize) -> Kids {
        let mut kids = NO_KIDS;
        self.cut(index, self.width, &mut kids);
        kids
    }

    /// Appends the best cover of node `n`'s children by `j` slots, left to right.
    fn cut(&self, n: usize, j: usize, kids: &mut Kids) {
        let choice = self.choice[n * (self.width - 1) + j - 2];
        let i = (choice & SHARE) as usize;
        let [left, right] = children(&self.binary[n]);
        for (open, (b, c), share) in [(OPEN_LEFT, left, i), (OPEN_RIGHT, right, j - i)] {
            if choice & open != 0 {
                self.cut(c as usize, share, kids);
            } else {
                kids.0[kids.1] = (b, c);
                kids.1 += 1;
            }
        }
    }

    /// A box's area in cost units.
    fn cost(&self, b: Bounds) -> u64 {
        (area(b) * self.unit).round().min(self.most) as u64
    }

    /// The slots of both children of node `n`, from `best`, the keys of the
    /// nodes from `base` on (`width - 1` a node, for j = 2..=width).
    fn slots(&self, n: usize, best: &[u64], base: usize) -> [Slots; 2] {
        let stride = self.width - 1;
        children(&self.binary[n]).map(|(b, c)| {
            let mut s = [(LEAF, false); 8];
            if child_ref::as_leaf(c).is_none() {
                let at = (c as usize - base) * stride;
                let own = &best[at..at + stride];
                // One slot: a wide node of its own, one level deeper.
                let keep = own[stride - 1] + (self.cost(b) << DEPTH_BITS) + 1;
                debug_assert!(keep & DEPTH != 0, "a tree deeper than the depth bits hold");
                s[1] = (keep, false);
                for i in 2..self.width {
                    s[i] = if own[i - 2] < keep {
                        (own[i - 2], true)
                    } else {
                        (keep, false)
                    };
                }
            }
            s
        })
    }

    /// Fills the keys and choices of the subtree of node `n`, which ends
    /// before node `end`, children before parents: a subtree's nodes are one
    /// run of the depth-first array, its left child's subtree then its right
    /// one's, so the two are filled apart.
    fn fill(&self, n: usize, end: usize, best: &mut [u64], choice: &mut [u8]) {
        if end - n < PARALLEL_NODES {
            for m in (n..end).rev() {
                self.solve(m, n, best, choice);
            }
            return;
        }
        let node = &self.binary[n];
        let interior = |c: u32| child_ref::as_leaf(c).is_none().then_some(c as usize);
        let (left, right) = (interior(node.left), interior(node.right));
        let mid = right.unwrap_or(end);
        debug_assert!(left.is_none_or(|l| l == n + 1) && (left.is_some() || mid == n + 1));
        let (stride, at) = (self.width - 1, (mid - n - 1) * (self.width - 1));
        let (lbest, rbest) = best[stride..].split_at_mut(at);
        let (lchoice, rchoice) = choice[stride..].split_at_mut(at);
        rayon::join(
            || left.map(|l| self.fill(l, mid, lbest, lchoice)),
            || right.map(|r| self.fill(r, end, rbest, rchoice)),
        );
        self.solve(n, n, best, choice);
    }

    /// Node `n`'s keys and choices, from its children's keys, in the tables
    /// of the nodes from `base` on.
    fn solve(&self, n: usize, base: usize, best: &mut [u64], choice: &mut [u8]) {
        let slots = self.slots(n, best, base);
        let at = (n - base) * (self.width - 1);
        for j in 2..=self.width {
            let (key, i) = share(&slots, j);
            best[at + j - 2] = key;
            choice[at + j - 2] = i as u8
                | if slots[0][i].1 { OPEN_LEFT } else { 0 }
                | if slots[1][j - i].1 { OPEN_RIGHT } else { 0 };
        }
    }
}

/// The least key of `j` slots shared by the two children, and the left
/// child's share: of equal keys, the fewest slots to the left. Slots are
/// never fewer for more of them, so all `j` are shared out.
fn share([left, right]: &[Slots; 2], j: usize) -> (u64, usize) {
    (1..j)
        .map(|i| (join(left[i].0, right[j - i].0), i))
        .min()
        .expect("two slots or more")
}

#[cfg(test)]
mod tests;
