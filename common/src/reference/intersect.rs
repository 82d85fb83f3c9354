//! Ray against scene in f64: the sphere and triangle tests of each numerical
//! choice, the BVH walk, and the closest hit and shadow queries built on them
//! (the tracer's intersection and traversal, step by step).

use crate::gpu::layout::{child_ref, Bvh, PRIM_SPHERE_BIT};
use crate::reference::perturb::{at, Op};
use crate::scene::accel::MAX_LEAF;
use crate::scene::numerics::{SphereTest, TriangleTest};
use crate::scene::{Scene, Sphere, Triangle};
use glam::DVec3;
use std::borrow::Cow;

pub(super) const T_MAX: f64 = 1.0e30;

/// A scene and, above a few primitives, its BVH: its own, or a run's.
pub struct Tracer<'a> {
    pub(super) scene: &'a Scene,
    pub(super) bvh: Option<Cow<'a, Bvh>>,
}

/// Brute force below this many primitives: one leaf's worth.
const BVH_FROM: usize = MAX_LEAF + 1;

impl<'a> Tracer<'a> {
    /// `scene` as the reference traces it (already rounded to f32, see `render_with`).
    pub fn new(scene: &'a Scene) -> Tracer<'a> {
        Tracer::with_width(scene, 2)
    }

    /// `new`, through the BVH collapsed to `width` children a node, as the
    /// GPU's `--accel bvh4` or `bvh8` traces it.
    pub fn with_width(scene: &'a Scene, width: u32) -> Tracer<'a> {
        let bvh = (scene.primitive_count() >= BVH_FROM).then(|| Bvh::build(scene).widen(width));
        Tracer {
            scene,
            bvh: bvh.map(Cow::Owned),
        }
    }

    /// Through a tree already built over `scene` (a run's, `plan::build_bvh`,
    /// which a test holds to the reference's own), so that nothing is built twice.
    pub fn through(scene: &'a Scene, bvh: &'a Bvh) -> Tracer<'a> {
        Tracer {
            scene,
            bvh: Some(Cow::Borrowed(bvh)),
        }
    }

    /// Brute force only, for the tests that check the BVH changes nothing.
    pub fn brute_force(scene: &'a Scene) -> Tracer<'a> {
        Tracer { scene, bvh: None }
    }
}

/// Where brute force would test a primitive: spheres first, then triangles, in
/// order. Among hits at the same t the earliest wins, as in brute force.
fn order(code: u32) -> u64 {
    if code & PRIM_SPHERE_BIT != 0 {
        (code & !PRIM_SPHERE_BIT) as u64
    } else {
        (1u64 << 32) + code as u64
    }
}

/// The ray against a node's box, padded: the f32 bounds already contain the
/// primitives (rounded outwards), and the pad covers the f64 slab arithmetic and
/// the intersection tests' own rounding, so no node holding a hit is skipped.
/// Returns the entry distance, or None for a miss or a box beyond `t_max`.
pub(super) fn enter_box(
    min: [f32; 3],
    max: [f32; 3],
    o: DVec3,
    d: DVec3,
    t_max: f64,
) -> Option<f64> {
    let (mut t0, mut t1) = (0.0f64, t_max);
    for a in 0..3 {
        let (lo, hi) = (min[a] as f64, max[a] as f64);
        let pad = 1e-9 * lo.abs().max(hi.abs()).max(o[a].abs()) + 1e-300;
        let (lo, hi) = (lo - pad, hi + pad);
        if d[a] == 0.0 {
            if o[a] < lo || o[a] > hi {
                return None;
            }
            continue;
        }
        let inv = 1.0 / d[a];
        let (mut near, mut far) = ((lo - o[a]) * inv, (hi - o[a]) * inv);
        if near > far {
            std::mem::swap(&mut near, &mut far);
        }
        // A relative margin on the distances themselves, for the same reason.
        t0 = t0.max(near - 1e-9 * near.abs());
        t1 = t1.min(far + 1e-9 * far.abs());
        if t0.is_nan() || t1.is_nan() || t0 > t1 {
            return None;
        }
    }
    Some(t0)
}

/// The children of a node that the ray enters, in the order the shader
/// (trace/bvh.glsl) visits them: per `GpuBvhWideNode`, sorted by entry
/// distance with the shader's network; of an 8-wide node's two halves, the
/// nearer half's nearest child first, then the rest of the second half near
/// to far, then the rest of the first. (The shader's shadow rays sort only
/// the nearest child first; whether anything blocks a ray does not depend
/// on the order, so the reference keeps one order for both.)
fn wide_visits(bvh: &Bvh, index: usize, o: DVec3, d: DVec3, t_max: f64) -> Vec<(u32, f64)> {
    let mut near: Option<(u32, f64)> = None;
    let mut pushed: Vec<(u32, f64)> = Vec::new();
    for q in &bvh.wide[index..index + crate::scene::accel::wide::quads(bvh.width)] {
        let mut e: [(u32, f64); 4] = std::array::from_fn(|k| {
            let (min, max) = q.bounds(k);
            let t = (q.child[k] != child_ref::NO_CHILD)
                .then(|| enter_box(min, max, o, d, t_max))
                .flatten();
            (q.child[k], t.unwrap_or(f64::INFINITY))
        });
        for (a, b) in [(0, 1), (2, 3), (0, 2), (1, 3), (1, 2)] {
            if e[b].1 < e[a].1 {
                e.swap(a, b);
            }
        }
        // Pushed far to near, so that they pop near first.
        pushed.extend(e[1..].iter().rev().filter(|c| c.1.is_finite()));
        match near {
            Some(n) if e[0].1 >= n.1 => pushed.extend(e[0].1.is_finite().then_some(e[0])),
            _ if e[0].1.is_finite() => pushed.extend(near.replace(e[0])),
            _ => {}
        }
    }
    pushed.extend(near);
    pushed
}

/// Visits the BVH's leaves along a ray, near child first, calling `leaf` with
/// each leaf's primitive codes and the current bound; `leaf` returns the new
/// bound (or None to stop: a shadow ray's first hit).
fn walk(
    bvh: &Bvh,
    o: DVec3,
    d: DVec3,
    mut t_max: f64,
    mut leaf: impl FnMut(&[u32], f64) -> Option<f64>,
) {
    if bvh.nodes.is_empty() && bvh.wide.is_empty() {
        return;
    }
    // (child reference, entry distance); the root is interior node 0.
    let mut stack = vec![(0u32, 0.0f64)];
    while let Some((child, t_enter)) = stack.pop() {
        // Equal distances must be visited: a tie may go to a later leaf.
        if t_enter > t_max {
            continue;
        }
        if let Some((first, count)) = child_ref::as_leaf(child) {
            match leaf(&bvh.prims[first..first + count], t_max) {
                Some(t) => t_max = t,
                None => return,
            }
            continue;
        }
        if bvh.width > 2 {
            stack.extend(wide_visits(bvh, child as usize, o, d, t_max));
            continue;
        }
        let node = &bvh.nodes[child as usize];
        let left = enter_box(node.left_min, node.left_max, o, d, t_max).map(|t| (node.left, t));
        let right = enter_box(node.right_min, node.right_max, o, d, t_max).map(|t| (node.right, t));
        // Far child pushed first, so the near one is visited first.
        match (left, right) {
            (Some(a), Some(b)) if a.1 <= b.1 => stack.extend([b, a]),
            (Some(a), Some(b)) => stack.extend([a, b]),
            (Some(a), None) | (None, Some(a)) => stack.push(a),
            (None, None) => {}
        }
    }
}

fn hit_sphere(
    test: SphereTest,
    o: DVec3,
    d: DVec3,
    s: &Sphere,
    t_min: f64,
    t_max: f64,
) -> Option<f64> {
    let f = o - s.center;
    let r2 = s.radius * s.radius;
    let (lo, hi) = match test {
        SphereTest::Quadratic => {
            let a = d.dot(d);
            let b = 2.0 * f.dot(d);
            let c = f.dot(f) - r2;
            let disc = b * b - 4.0 * a * c;
            if disc.is_nan() || disc < 0.0 {
                return None;
            }
            let sq = disc.sqrt();
            ((-b - sq) / (2.0 * a), (-b + sq) / (2.0 * a))
        }
        SphereTest::Stable => {
            let b = at(Op::SphereB, f.dot(d));
            let l = f - b * d;
            let disc = r2 - at(Op::SphereDist2, l.dot(l));
            if disc.is_nan() || disc < 0.0 {
                return None;
            }
            let c = at(Op::SphereC, f.dot(f) - r2);
            let q = -b - if b >= 0.0 { 1.0 } else { -1.0 } * disc.sqrt();
            let (t0, t1) = (at(Op::SphereT, c / q), at(Op::SphereT, q));
            (t0.min(t1), t0.max(t1))
        }
    };
    if lo > t_min && lo < t_max {
        return Some(lo);
    }
    if hi > t_min && hi < t_max {
        return Some(hi);
    }
    None
}

/// The shader's `TriRay`: the ray plus the watertight test's permutation and shear.
struct TriRay {
    o: DVec3,
    d: DVec3,
    k: [usize; 3],
    s: DVec3,
}

fn tri_ray(test: TriangleTest, o: DVec3, d: DVec3) -> TriRay {
    let mut r = TriRay {
        o,
        d,
        k: [0, 1, 2],
        s: DVec3::ZERO,
    };
    if test == TriangleTest::Watertight {
        let ad = d.abs();
        let kz = if ad.x > ad.y {
            if ad.x > ad.z {
                0
            } else {
                2
            }
        } else if ad.y > ad.z {
            1
        } else {
            2
        };
        let mut kx = if kz == 2 { 0 } else { kz + 1 };
        let mut ky = if kx == 2 { 0 } else { kx + 1 };
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        r.k = [kx, ky, kz];
        r.s = DVec3::new(d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
    }
    r
}

/// The shader's `is_degenerate`: edges parallel (cross product exactly zero).
fn is_degenerate(tri: &Triangle) -> bool {
    (tri.p[1] - tri.p[0]).cross(tri.p[2] - tri.p[0]) == DVec3::ZERO
}

fn hit_triangle(
    test: TriangleTest,
    r: &TriRay,
    tri: &Triangle,
    t_min: f64,
    t_max: f64,
) -> Option<(f64, f64, f64)> {
    match test {
        TriangleTest::Watertight => {
            let (a, b, c) = (tri.p[0] - r.o, tri.p[1] - r.o, tri.p[2] - r.o);
            let [kx, ky, kz] = r.k;
            let (ax, ay) = (a[kx] - r.s.x * a[kz], a[ky] - r.s.y * a[kz]);
            let (bx, by) = (b[kx] - r.s.x * b[kz], b[ky] - r.s.y * b[kz]);
            let (cx, cy) = (c[kx] - r.s.x * c[kz], c[ky] - r.s.y * c[kz]);
            let eu = at(Op::TriEdge, cx * by - cy * bx);
            let ev = at(Op::TriEdge, ax * cy - ay * cx);
            let ew = at(Op::TriEdge, bx * ay - by * ax);
            if (eu < 0.0 || ev < 0.0 || ew < 0.0) && (eu > 0.0 || ev > 0.0 || ew > 0.0) {
                return None;
            }
            let det = eu + ev + ew;
            if det == 0.0 {
                return None;
            }
            let tz = eu * (r.s.z * a[kz]) + ev * (r.s.z * b[kz]) + ew * (r.s.z * c[kz]);
            let inv = 1.0 / det;
            let t = at(Op::TriT, tz * inv);
            if !(t > t_min && t < t_max) || is_degenerate(tri) {
                return None;
            }
            Some((t, ev * inv, ew * inv))
        }
        TriangleTest::MollerTrumbore => {
            let e1 = tri.p[1] - tri.p[0];
            let e2 = tri.p[2] - tri.p[0];
            let pv = r.d.cross(e2);
            let det = e1.dot(pv);
            if det == 0.0 {
                return None;
            }
            let inv = 1.0 / det;
            let tv = r.o - tri.p[0];
            let u = at(Op::TriEdge, tv.dot(pv) * inv);
            if !(0.0..=1.0).contains(&u) {
                return None;
            }
            let qv = tv.cross(e1);
            let v = at(Op::TriEdge, r.d.dot(qv) * inv);
            if !(v >= 0.0 && u + v <= 1.0) {
                return None;
            }
            let t = at(Op::TriT, e2.dot(qv) * inv);
            if !(t > t_min && t < t_max) || is_degenerate(tri) {
                return None;
            }
            Some((t, u, v))
        }
    }
}

#[derive(Debug, PartialEq)]
pub(super) enum Hit {
    Sphere(usize),
    Triangle(usize, f64, f64),
}

pub(super) fn closest_hit(tracer: &Tracer, o: DVec3, d: DVec3) -> Option<(f64, Hit)> {
    let scene = tracer.scene;
    let n = &scene.numerics;
    let r = tri_ray(n.triangle, o, d);
    let Some(bvh) = tracer.bvh.as_deref() else {
        let mut best_t = T_MAX;
        let mut best = None;
        for (i, s) in scene.spheres.iter().enumerate() {
            if let Some(t) = hit_sphere(n.sphere, o, d, s, 0.0, best_t) {
                best_t = t;
                best = Some(Hit::Sphere(i));
            }
        }
        for (i, tri) in scene.triangles.iter().enumerate() {
            if let Some((t, u, v)) = hit_triangle(n.triangle, &r, tri, 0.0, best_t) {
                best_t = t;
                best = Some(Hit::Triangle(i, u, v));
            }
        }
        return best.map(|h| (best_t, h));
    };
    // (t, brute-force order, hit): the least t, and among equal t the least order.
    let mut best: Option<(f64, u64, Hit)> = None;
    walk(bvh, o, d, T_MAX, |prims, _| {
        for &code in prims {
            let best_t = best.as_ref().map_or(T_MAX, |b| b.0);
            // Up to and including best_t: an equal t may still win on order.
            let limit = if best.is_some() {
                best_t.next_up()
            } else {
                T_MAX
            };
            let hit = if code & PRIM_SPHERE_BIT != 0 {
                let i = (code & !PRIM_SPHERE_BIT) as usize;
                hit_sphere(n.sphere, o, d, &scene.spheres[i], 0.0, limit)
                    .map(|t| (t, Hit::Sphere(i)))
            } else {
                let i = code as usize;
                hit_triangle(n.triangle, &r, &scene.triangles[i], 0.0, limit)
                    .map(|(t, u, v)| (t, Hit::Triangle(i, u, v)))
            };
            if let Some((t, h)) = hit {
                let key = order(code);
                if best
                    .as_ref()
                    .is_none_or(|b| t < b.0 || (t == b.0 && key < b.1))
                {
                    best = Some((t, key, h));
                }
            }
        }
        Some(best.as_ref().map_or(T_MAX, |b| b.0))
    });
    best.map(|(t, _, h)| (t, h))
}

pub(super) fn occluded(tracer: &Tracer, o: DVec3, d: DVec3, dist: f64) -> bool {
    let scene = tracer.scene;
    let n = &scene.numerics;
    let r = tri_ray(n.triangle, o, d);
    let blocks = |code: u32| {
        if code & PRIM_SPHERE_BIT != 0 {
            let s = &scene.spheres[(code & !PRIM_SPHERE_BIT) as usize];
            hit_sphere(n.sphere, o, d, s, 0.0, dist).is_some()
        } else {
            hit_triangle(n.triangle, &r, &scene.triangles[code as usize], 0.0, dist).is_some()
        }
    };
    let Some(bvh) = tracer.bvh.as_deref() else {
        return scene
            .spheres
            .iter()
            .any(|s| hit_sphere(n.sphere, o, d, s, 0.0, dist).is_some())
            || scene
                .triangles
                .iter()
                .any(|t| hit_triangle(n.triangle, &r, t, 0.0, dist).is_some());
    };
    let mut hit = false;
    walk(bvh, o, d, dist, |prims, t_max| {
        if prims.iter().any(|&c| blocks(c)) {
            hit = true;
            None
        } else {
            Some(t_max)
        }
    });
    hit
}
