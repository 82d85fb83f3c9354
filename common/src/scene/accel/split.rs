//! The builder's split of one node: binned SAH over f32 boxes (the bins of
//! a large node counted in parallel chunks, merged with min, max and integer
//! sums, so in any order to the same bins) and the partition of the node's
//! primitives into its two halves (in parallel for a large node, the same
//! order every run).

use crate::gpu::layout::{child_ref, Bounds};
use glam::Vec3A;
use rayon::prelude::*;

/// Primitives per leaf at most; SAH may stop splitting earlier.
pub const MAX_LEAF: usize = child_ref::MAX_LEAF_COUNT;
/// Bins per axis, and finer bins for the nodes of at least `FINE_NODE`
/// primitives: the top of the tree, where a plane's place decides most and
/// more bins cost the build next to nothing. There 32 bins place the planes
/// that 16 put a bin's width off; the rays of the teapot's frames visit 4 %
/// fewer nodes for it (the f64 reference's walk, counted: fewer in four of
/// six views of the teapot, up to 3 % more in two; with the optimal collapse
/// and TRAVERSAL_COST below, fewer in all six), although SAH calls the tree
/// worse (32 bins at every node: `bvh_sah_cost` 7.55 -> 7.85 at a node
/// visit of 1; SAH prices rays spread evenly over the root's box, which the
/// lone sphere behind the camera makes mostly empty). 64 bins were no
/// better; 32 at every node the same at the teapot and 18 % slower to build
/// 4.9M triangles (docs/findings/bvh.md#the-trees-top-h200).
const BINS: usize = 16;
const FINE_BINS: usize = 32;
const FINE_NODE: usize = 4096;
/// Relative cost of one node visit vs one primitive test, for SAH. 1.5
/// makes slightly fuller leaves than 1: with the finer top and the optimal
/// collapse every teapot frame was 0-5 % shorter in both APIs on the H200,
/// the box 2-3 %, the sphere lists the same (docs/findings/bvh.md#the-trees-top-h200).
pub(super) const TRAVERSAL_COST: f64 = 1.5;
pub(super) const INTERSECT_COST: f64 = 1.0;
/// A node with at least this many primitives counts its bins in parallel
/// chunks of `BIN_CHUNK`: below it, the tasks would cost more than they save.
const PARALLEL_BINNING: usize = 1 << 15;
pub(super) const BIN_CHUNK: usize = 1 << 13;
/// A node with at least this many primitives partitions them in parallel,
/// in chunks of `PARTITION_CHUNK`: at the top of the tree the partition would
/// otherwise be one core's work while the others wait.
const PARALLEL_PARTITION: usize = 1 << 17;
const PARTITION_CHUNK: usize = 1 << 14;

/// An f32 box; empty when min > max. SIMD lanes: the builder's inner loops
/// are a few min and max operations per primitive.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Box3 {
    pub(super) min: Vec3A,
    pub(super) max: Vec3A,
}

impl Box3 {
    pub(super) const EMPTY: Box3 = Box3 {
        min: Vec3A::INFINITY,
        max: Vec3A::NEG_INFINITY,
    };

    pub(super) fn grow(&mut self, o: &Box3) {
        self.min = self.min.min(o.min);
        self.max = self.max.max(o.max);
    }

    fn grow_point(&mut self, p: Vec3A) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// In f64, so that near-equal plane costs are told apart the same way every run.
    pub(super) fn area(&self) -> f64 {
        let d = (self.max.as_dvec3() - self.min.as_dvec3()).max(glam::DVec3::ZERO);
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    pub(super) fn bounds(&self) -> Bounds {
        (self.min.to_array(), self.max.to_array())
    }
}

/// One primitive while building: its f32 box and its code (`PRIM_SPHERE_BIT`
/// | sphere, or triangle). 32 bytes; the centroid is recomputed when needed.
#[derive(Clone, Copy)]
#[repr(C, align(16))]
pub(super) struct PrimRef {
    pub(super) min: [f32; 3],
    pub(super) code: u32,
    pub(super) max: [f32; 3],
    pub(super) pad: u32,
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

/// A subtree to build: the box of its primitives, the box of their doubled
/// centroids, and where its primitives start in the final primitive list.
#[derive(Clone, Copy)]
pub(super) struct Node {
    pub(super) bounds: Box3,
    pub(super) centroids: Box3,
    pub(super) first: usize,
}

/// The bins of one axis: each bin's box, its centroids' box and its count.
#[derive(Clone, Copy)]
struct Bin {
    bounds: Box3,
    centroids: Box3,
    count: u32,
}

type Bins<const B: usize> = [[Bin; B]; 3];

const EMPTY_BIN: Bin = Bin {
    bounds: Box3::EMPTY,
    centroids: Box3::EMPTY,
    count: 0,
};

/// Where each axis's centroids fall into `B` bins: the same arithmetic counts
/// the bins and later partitions, so the two always agree.
#[derive(Clone, Copy)]
struct Binning<const B: usize> {
    min: Vec3A,
    scale: Vec3A,
}

impl<const B: usize> Binning<B> {
    fn new(centroids: &Box3) -> Binning<B> {
        let extent = centroids.max - centroids.min;
        // A flat axis puts everything in bin 0, where no plane separates anything.
        let usable = extent.cmpgt(Vec3A::ZERO) & extent.is_finite_mask();
        let scale = Vec3A::select(usable, B as f32 / extent, Vec3A::ZERO);
        Binning {
            min: centroids.min,
            scale,
        }
    }

    /// The primitive's bin on each axis.
    fn bins(&self, c: Vec3A) -> [usize; 3] {
        let b = ((c - self.min) * self.scale).as_uvec3();
        b.min(glam::UVec3::splat(B as u32 - 1))
            .to_array()
            .map(|x| x as usize)
    }

    fn count(&self, refs: &[PrimRef]) -> Bins<B> {
        let mut bins = [[EMPTY_BIN; B]; 3];
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
    fn count_parallel(&self, refs: &[PrimRef]) -> Bins<B> {
        if refs.len() < PARALLEL_BINNING {
            return self.count(refs);
        }
        refs.par_chunks(BIN_CHUNK).map(|c| self.count(c)).reduce(
            || [[EMPTY_BIN; B]; 3],
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
pub(super) fn boxes(refs: &[PrimRef]) -> (Box3, Box3) {
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
pub(super) fn split(refs: &mut [PrimRef], node: &Node) -> Option<(usize, Node, Node)> {
    if refs.len() >= FINE_NODE {
        split_in::<FINE_BINS>(refs, node)
    } else {
        split_in::<BINS>(refs, node)
    }
}

/// `split` with `B` bins per axis.
fn split_in<const B: usize>(refs: &mut [PrimRef], node: &Node) -> Option<(usize, Node, Node)> {
    let count = refs.len();
    if count <= 1 {
        return None;
    }
    let binning = Binning::<B>::new(&node.centroids);
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
    let mid = partition_parallel(refs, |r| {
        binning.bins(centroid2(&r.bounds()))[axis] <= last_left
    });
    Some((
        mid,
        side(0..last_left + 1, node.first),
        side(last_left + 1..B, node.first + mid),
    ))
}

/// Binned SAH: the cheapest of B-1 planes per axis, as (axis, last bin on
/// the left), or None when a leaf is cheaper (and allowed) or no plane has
/// primitives on both sides. Ties go to the first plane found.
fn best_plane<const B: usize>(bins: &Bins<B>, node: &Node, count: usize) -> Option<(usize, usize)> {
    let leaf_cost = INTERSECT_COST * count as f64;
    let area = node.bounds.area().max(1e-300);
    let mut best: Option<(f64, usize, usize)> = None;
    for (a, axis) in bins.iter().enumerate() {
        // Sweep from the right for the right side's area and count per plane.
        let mut right = [(0.0, 0u32); B];
        let mut acc = Box3::EMPTY;
        let mut side = (0.0, 0);
        for i in (1..B).rev() {
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
        for i in 0..B - 1 {
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

/// `partition` for a large node: each chunk is partitioned on its own, and
/// then the left-going primitives past the left side's end trade places with
/// the right-going ones before it, the k-th of one kind with the k-th of the
/// other, in parallel runs. The same order every run, whatever the threads.
fn partition_parallel(refs: &mut [PrimRef], left: impl Fn(&PrimRef) -> bool + Sync) -> usize {
    if refs.len() < PARALLEL_PARTITION {
        return partition(refs, left);
    }
    let counts: Vec<usize> = refs
        .par_chunks_mut(PARTITION_CHUNK)
        .map(|c| partition(c, &left))
        .collect();
    let total: usize = counts.iter().sum();
    // Misplaced runs: right-going ones before `total`, left-going ones after it.
    let (mut early, mut late) = (Vec::new(), Vec::new());
    for (k, &l) in counts.iter().enumerate() {
        let start = k * PARTITION_CHUNK;
        let end = (start + PARTITION_CHUNK).min(refs.len());
        if start + l < end.min(total) {
            early.push(start + l..end.min(total));
        }
        if start.max(total) < start + l {
            late.push(start.max(total) - total..start + l - total);
        }
    }
    // Pair the runs up into equal lengths, cutting them from the two sides in order.
    let (front, back) = refs.split_at_mut(total);
    let (mut front, mut back) = (front, back);
    let (mut front_at, mut back_at) = (0, 0);
    let mut pairs = Vec::new();
    let (mut e, mut l) = (early.into_iter().peekable(), late.into_iter().peekable());
    while let (Some(a), Some(b)) = (e.peek_mut(), l.peek_mut()) {
        let n = a.len().min(b.len());
        let (_, f) = std::mem::take(&mut front).split_at_mut(a.start - front_at);
        let (fa, f) = f.split_at_mut(n);
        let (_, g) = std::mem::take(&mut back).split_at_mut(b.start - back_at);
        let (gb, g) = g.split_at_mut(n);
        (front, back) = (f, g);
        (front_at, back_at) = (a.start + n, b.start + n);
        pairs.push((fa, gb));
        a.start += n;
        b.start += n;
        if a.start >= a.end {
            e.next();
        }
        if b.start >= b.end {
            l.next();
        }
    }
    pairs
        .into_par_iter()
        .for_each(|(a, b)| a.swap_with_slice(b));
    total
}
