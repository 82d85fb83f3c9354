//! Acceleration: `--accel` and the scene's choice of a BVH, and the bounding
//! volume hierarchy itself, built on the CPU with binned SAH over spheres and
//! triangles together, flattened depth-first into the node array the shader
//! walks (`gpu::layout::Bvh`, mirrored in shaders/trace.glsl and layout-tested),
//! plus the primitive list its leaves point into.

use crate::gpu::layout::{child_ref, Bounds, Bvh, GpuBvhNode, GpuBvhPrim, PRIM_SPHERE_BIT};
use crate::scene::camera::in_local_frame;
use crate::scene::{BvhCache, Scene};
use glam::DVec3;

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Accel {
    Auto,
    None,
    Bvh,
}

/// `--accel auto` builds a BVH for scenes with at least this many primitives.
/// Below it the brute-force loop is as fast or faster: see the comparison
/// report's acceleration section for the measurements behind the number.
pub const AUTO_BVH_MIN_PRIMITIVES: usize = 64;

impl Scene {
    /// The scene's BVH where it traces through one (built on first use, then
    /// kept). Primitives changed after that call would not be seen: scenes are
    /// not edited once loaded, except for `--accel` and the ray depth.
    pub fn bvh_tree(&self) -> Option<&Bvh> {
        self.bvh.then(|| {
            &**self
                .bvh_cache
                .0
                // Over the primitives as the GPU holds them: relative to the local origin.
                .get_or_init(|| {
                    let local = in_local_frame(self);
                    std::sync::Arc::new(Bvh::build(&local))
                })
        })
    }

    /// Applies `--accel` (none: brute force; bvh: a BVH; auto: a BVH from the threshold on).
    pub fn set_accel(&mut self, accel: Accel) {
        self.bvh_cache = BvhCache::default();
        self.bvh = match accel {
            Accel::None => false,
            Accel::Bvh => self.primitive_count() > 0,
            Accel::Auto => self.primitive_count() >= AUTO_BVH_MIN_PRIMITIVES,
        };
    }
}

/// Primitives per leaf at most; SAH may stop splitting earlier.
pub const MAX_LEAF: usize = child_ref::MAX_LEAF_COUNT;
const BINS: usize = 16;
/// Relative cost of one node visit vs one primitive test, for SAH.
const TRAVERSAL_COST: f64 = 1.0;
const INTERSECT_COST: f64 = 1.0;

#[derive(Clone, Copy, Debug)]
struct Aabb {
    min: DVec3,
    max: DVec3,
}

impl Aabb {
    const EMPTY: Aabb = Aabb {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    fn grow(&mut self, o: &Aabb) {
        self.min = self.min.min(o.min);
        self.max = self.max.max(o.max);
    }

    fn area(&self) -> f64 {
        let d = (self.max - self.min).max(DVec3::ZERO);
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }
}

#[derive(Clone, Copy)]
struct PrimRef {
    bounds: Aabb,
    centroid: DVec3,
    /// Index into the shader's primitive list encoding (PRIM_SPHERE_BIT | sphere) or triangle.
    code: u32,
}

impl Bvh {
    pub fn build(scene: &Scene) -> Bvh {
        let start = std::time::Instant::now();
        let mut refs: Vec<PrimRef> =
            Vec::with_capacity(scene.spheres.len() + scene.triangles.len());
        for (i, s) in scene.spheres.iter().enumerate() {
            let r = DVec3::splat(s.radius);
            let bounds = Aabb {
                min: s.center - r,
                max: s.center + r,
            };
            refs.push(PrimRef {
                bounds,
                centroid: s.center,
                code: PRIM_SPHERE_BIT | i as u32,
            });
        }
        for (i, t) in scene.triangles.iter().enumerate() {
            let bounds = Aabb {
                min: t.p[0].min(t.p[1]).min(t.p[2]),
                max: t.p[0].max(t.p[1]).max(t.p[2]),
            };
            refs.push(PrimRef {
                bounds,
                centroid: (bounds.min + bounds.max) * 0.5,
                code: i as u32,
            });
        }
        let mut bvh = Bvh::default();
        if !refs.is_empty() {
            let n = refs.len();
            bvh.nodes.reserve(2 * n / MAX_LEAF + 1);
            let (bounds, root) = build_node(&mut bvh, &mut refs, 0, n, 1);
            if child_ref::as_leaf(root).is_some() {
                // Node 0 is always an interior node: a tree that is one leaf
                // gets a root whose two children are that leaf. The second
                // test of the same primitives finds nothing closer.
                let b = bounds_f32(&bounds);
                bvh.nodes.push(GpuBvhNode::new(b, root, b, root));
            }
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
        let area = |(lo, hi): ([f32; 3], [f32; 3])| {
            let d = [0, 1, 2].map(|a| (hi[a] as f64 - lo[a] as f64).max(0.0));
            2.0 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0])
        };
        let union = |a: ([f32; 3], [f32; 3]), b: ([f32; 3], [f32; 3])| {
            (
                [0, 1, 2].map(|i| a.0[i].min(b.0[i])),
                [0, 1, 2].map(|i| a.1[i].max(b.1[i])),
            )
        };
        let root_area = area(union(
            (root.left_min, root.left_max),
            (root.right_min, root.right_max),
        ))
        .max(f64::MIN_POSITIVE);
        // Each interior node pays one visit for the ray that reaches it, and
        // each child box (node or leaf) is entered by the share of rays its area says.
        let mut cost = TRAVERSAL_COST;
        for n in &self.nodes {
            for (b, child) in [
                ((n.left_min, n.left_max), n.left),
                ((n.right_min, n.right_max), n.right),
            ] {
                let p = area(b) / root_area;
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

fn bounds_of(refs: &[PrimRef]) -> (Aabb, Aabb) {
    let mut b = Aabb::EMPTY;
    let mut c = Aabb::EMPTY;
    for r in refs {
        b.grow(&r.bounds);
        c.grow(&Aabb {
            min: r.centroid,
            max: r.centroid,
        });
    }
    (b, c)
}

/// Builds the subtree over refs[lo..hi] and returns its box and its child
/// reference. Interior nodes go in depth-first order, so a subtree's nodes are
/// contiguous and the root is node 0.
fn build_node(
    bvh: &mut Bvh,
    refs: &mut [PrimRef],
    lo: usize,
    hi: usize,
    depth: u32,
) -> (Aabb, u32) {
    bvh.depth = bvh.depth.max(depth);
    let (bounds, centroids) = bounds_of(&refs[lo..hi]);
    let count = hi - lo;
    let split = if count <= 1 {
        None
    } else {
        sah_split(&refs[lo..hi], &bounds, &centroids)
    };
    let split = match split {
        Some(s) => Some(s),
        // Too many for a leaf but SAH found no useful split (e.g. identical
        // centroids): split the list in the middle.
        None if count > MAX_LEAF => Some((count / 2, None)),
        None => None,
    };
    let Some((mid, plane)) = split else {
        let first = bvh.prims.len() as u32;
        bvh.prims.extend(refs[lo..hi].iter().map(|r| r.code));
        return (bounds, child_ref::leaf(first, count as u32));
    };
    if let Some(plane) = plane {
        // Partition with the same bin arithmetic that counted the sides.
        let slice = &mut refs[lo..hi];
        let mut i = 0;
        for j in 0..slice.len() {
            if plane.left(&slice[j]) {
                slice.swap(i, j);
                i += 1;
            }
        }
        debug_assert_eq!(i, mid);
    }
    let mid = lo + mid;
    let index = bvh.nodes.len();
    bvh.nodes.push(GpuBvhNode::default());
    let (left_box, left) = build_node(bvh, refs, lo, mid, depth + 1);
    let (right_box, right) = build_node(bvh, refs, mid, hi, depth + 1);
    bvh.nodes[index] = GpuBvhNode::new(bounds_f32(&left_box), left, bounds_f32(&right_box), right);
    (bounds, index as u32)
}

fn bounds_f32(b: &Aabb) -> Bounds {
    // Round outwards so f32 boxes still contain the f64 primitives.
    let lo = b.min.to_array().map(|v| next_down(v as f32, v));
    let hi = b.max.to_array().map(|v| next_up(v as f32, v));
    (lo, hi)
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

/// A split between centroid bins `..=last_left` and the rest along `axis`.
#[derive(Clone, Copy)]
struct Plane {
    axis: usize,
    cmin: f64,
    scale: f64,
    last_left: usize,
}

impl Plane {
    fn bin(&self, r: &PrimRef) -> usize {
        (((r.centroid[self.axis] - self.cmin) * self.scale) as usize).min(BINS - 1)
    }

    fn left(&self, r: &PrimRef) -> bool {
        self.bin(r) <= self.last_left
    }
}

/// Binned SAH: the best of BINS-1 planes per axis. Returns (left count, plane)
/// or None when making a leaf is cheaper.
fn sah_split(refs: &[PrimRef], bounds: &Aabb, centroids: &Aabb) -> Option<(usize, Option<Plane>)> {
    let leaf_cost = INTERSECT_COST * refs.len() as f64;
    let mut best: Option<(f64, usize, Plane)> = None; // cost, left count, plane
    for axis in 0..3 {
        let (cmin, cmax) = (centroids.min[axis], centroids.max[axis]);
        if cmax.is_nan() || cmin.is_nan() || cmax <= cmin {
            continue;
        }
        let scale = BINS as f64 / (cmax - cmin);
        let mut bins = [(Aabb::EMPTY, 0usize); BINS];
        for r in refs {
            let b = Plane {
                axis,
                cmin,
                scale,
                last_left: 0,
            }
            .bin(r);
            bins[b].0.grow(&r.bounds);
            bins[b].1 += 1;
        }
        // Sweep from the right to get the right side's area and count per plane.
        let mut right_area = [0.0; BINS];
        let mut right_count = [0usize; BINS];
        let mut acc = Aabb::EMPTY;
        let mut n = 0;
        for i in (1..BINS).rev() {
            acc.grow(&bins[i].0);
            n += bins[i].1;
            right_area[i] = acc.area();
            right_count[i] = n;
        }
        let mut acc = Aabb::EMPTY;
        let mut n = 0;
        for i in 0..BINS - 1 {
            acc.grow(&bins[i].0);
            n += bins[i].1;
            let (nl, nr) = (n, right_count[i + 1]);
            if nl == 0 || nr == 0 {
                continue;
            }
            let cost = TRAVERSAL_COST
                + INTERSECT_COST * (acc.area() * nl as f64 + right_area[i + 1] * nr as f64)
                    / bounds.area().max(1e-300);
            if best.is_none_or(|b| cost < b.0) {
                best = Some((
                    cost,
                    nl,
                    Plane {
                        axis,
                        cmin,
                        scale,
                        last_left: i,
                    },
                ));
            }
        }
    }
    match best {
        Some((cost, nl, plane)) if cost < leaf_cost || refs.len() > MAX_LEAF => {
            Some((nl, Some(plane)))
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(scene: &Scene) -> Bvh {
        let bvh = Bvh::build(scene);
        let total = scene.spheres.len() + scene.triangles.len();
        let mut seen = bvh.prims.clone();
        seen.sort_unstable();
        seen.dedup();
        assert_eq!(seen.len(), total, "every primitive is in exactly one leaf");
        assert_eq!(bvh.prims.len(), total);
        // Every leaf's box holds its primitives; every child's box lies in its
        // parent's; every node is reached once.
        let mut reached = vec![false; bvh.nodes.len()];
        let mut todo = vec![(0usize, None::<Bounds>)];
        while let Some((i, outer)) = todo.pop() {
            assert!(!reached[i], "node {i} is reached twice");
            reached[i] = true;
            let n = &bvh.nodes[i];
            for (lo, hi, child) in [
                (n.left_min, n.left_max, n.left),
                (n.right_min, n.right_max, n.right),
            ] {
                if let Some((outer_lo, outer_hi)) = outer {
                    for a in 0..3 {
                        assert!(
                            lo[a] >= outer_lo[a] && hi[a] <= outer_hi[a],
                            "a child of node {i} lies outside it"
                        );
                    }
                }
                let Some((first, count)) = child_ref::as_leaf(child) else {
                    todo.push((child as usize, Some((lo, hi))));
                    continue;
                };
                assert!(count <= MAX_LEAF, "a leaf of node {i} holds {count}");
                for &code in &bvh.prims[first..first + count] {
                    let (plo, phi) = if code & PRIM_SPHERE_BIT != 0 {
                        let s = &scene.spheres[(code & !PRIM_SPHERE_BIT) as usize];
                        (s.center - s.radius, s.center + s.radius)
                    } else {
                        let t = &scene.triangles[code as usize];
                        (
                            t.p[0].min(t.p[1]).min(t.p[2]),
                            t.p[0].max(t.p[1]).max(t.p[2]),
                        )
                    };
                    for a in 0..3 {
                        assert!(
                            lo[a] as f64 <= plo[a] && hi[a] as f64 >= phi[a],
                            "a leaf box of node {i} misses a primitive"
                        );
                    }
                }
            }
        }
        assert!(reached.iter().all(|&r| r), "every node is reached");
        bvh
    }

    #[test]
    fn builtin_scenes_give_valid_trees() {
        for name in ["box", "teapot"] {
            let b = check(&Scene::load(name, &[]).unwrap());
            assert!(b.depth < 64, "{name}: depth {}", b.depth);
        }
        let many = Scene::load("spherelist", &[("extra_spheres".into(), "1000".into())]).unwrap();
        // 1000 identical spheres: no SAH plane separates them, the median split must.
        let b = check(&many);
        assert!(b.depth < 64, "depth {}", b.depth);
        // One primitive: the root's two children are its one leaf.
        let one = Scene::load("spherelist", &[]).unwrap();
        let mut one = one.clone();
        one.spheres.truncate(1);
        one.triangles.clear();
        let b = check(&one);
        assert_eq!((b.nodes.len(), b.depth, b.stack_entries()), (1, 1, 1));
    }

    #[test]
    fn teapot_tree_is_shallow_and_compact() {
        let b = Bvh::build(&Scene::load("teapot", &[]).unwrap());
        assert!(b.depth <= 32, "depth {}", b.depth);
        assert!(b.nodes.len() < 19_200, "{} nodes", b.nodes.len());
    }
}
