//! The CPU reference: shaders/trace.glsl step by step in f64, one pixel per
//! rayon task. Same ray stack, same push order, same offsets and tests — the
//! shader's compile-time numerical choices (numerics.rs) are run-time branches
//! here — so the GPU images differ from it only by f32 arithmetic.
//! It traces the scene as the GPU holds it (in the local frame of
//! `camera::in_local_frame`, inputs rounded to f32, see `Scene::rounded_to_f32`).
//! Change both together.
//!
//! Rays traverse a BVH built by the GPU's own builder (bvh.rs) over the
//! reference's primitives, so a 2-million-triangle mesh takes seconds, not
//! hours. The traversal keeps brute force's answer exactly: the closest hit,
//! ties going to the primitive brute force tests first.

use crate::bvh::Bvh;
use crate::camera::{in_local_frame, RayFrame};
use crate::gpu::PRIM_SPHERE_BIT;
use crate::image_io::FloatImage;
use crate::numerics::{Numerics, Offset, SphereTest, TriangleTest};
use crate::scene::{Scene, Sphere, Triangle};
use glam::DVec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

const T_MAX: f64 = 1.0e30;

/// Renders `scene` at width × height with the scene's own numerics. Uses the
/// generic stack (no variant pruning is needed on the CPU: absent features
/// simply never trigger).
pub fn render(scene: &Scene, width: u32, height: u32) -> FloatImage {
    render_with(scene, width, height, &scene.numerics)
}

/// Renders `scene` with the given numerical choices instead of the scene's.
pub fn render_with(scene: &Scene, width: u32, height: u32, numerics: &Numerics) -> FloatImage {
    render_counting(scene, width, height, numerics, true, &AtomicUsize::new(0))
}

/// `render_with`, through the BVH or (`bvh` false: `--accel none`) testing
/// every primitive, adding 1 to `rows_done` as each row finishes (for a progress bar).
pub fn render_counting(
    scene: &Scene,
    width: u32,
    height: u32,
    numerics: &Numerics,
    bvh: bool,
    rows_done: &AtomicUsize,
) -> FloatImage {
    // The GPU's frame: positions relative to the local origin, then rounded to f32.
    let frame = RayFrame::local(scene, &scene.camera, width, height).rounded_to_f32();
    let mut scene = in_local_frame(scene).rounded_to_f32();
    scene.numerics = *numerics;
    let tracer = if bvh {
        Tracer::new(&scene)
    } else {
        Tracer::brute_force(&scene)
    };
    let w = width as usize;
    let mut pixels = vec![[0f32; 3]; crate::limits::pixel_count(width, height)];
    pixels.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, px) in row.iter_mut().enumerate() {
            let c = tracer.trace(frame.eye, frame.dir(x as f64, y as f64));
            *px = [c.x as f32, c.y as f32, c.z as f32];
        }
        rows_done.fetch_add(1, Ordering::Relaxed);
    });
    FloatImage {
        width,
        height,
        pixels,
    }
}

/// A scene and, above a few primitives, its BVH.
pub struct Tracer<'a> {
    scene: &'a Scene,
    bvh: Option<Bvh>,
}

/// Brute force below this many primitives: one leaf's worth.
const BVH_FROM: usize = crate::bvh::MAX_LEAF + 1;

impl<'a> Tracer<'a> {
    /// `scene` as the reference traces it (already rounded to f32, see `render_with`).
    pub fn new(scene: &'a Scene) -> Tracer<'a> {
        let bvh = (scene.primitive_count() >= BVH_FROM).then(|| Bvh::build(scene));
        Tracer { scene, bvh }
    }

    /// Brute force only, for the tests that check the BVH changes nothing.
    pub fn brute_force(scene: &'a Scene) -> Tracer<'a> {
        Tracer { scene, bvh: None }
    }

    pub fn trace(&self, origin: DVec3, dir: DVec3) -> DVec3 {
        trace_with(self, origin, dir)
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
fn enter_box(min: [f32; 3], max: [f32; 3], o: DVec3, d: DVec3, t_max: f64) -> Option<f64> {
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
        if !(t0 <= t1) {
            return None;
        }
    }
    Some(t0)
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
    let mut stack = vec![(0usize, 0.0f64)];
    while let Some((index, t_enter)) = stack.pop() {
        // Equal distances must be visited: a tie may go to a later leaf.
        if t_enter > t_max {
            continue;
        }
        let node = &bvh.nodes[index];
        if node.count > 0 {
            let first = node.left_or_first as usize;
            match leaf(&bvh.prims[first..first + node.count as usize], t_max) {
                Some(t) => t_max = t,
                None => return,
            }
            continue;
        }
        let child = |c: usize| {
            let n = &bvh.nodes[c];
            enter_box(n.min, n.max, o, d, t_max).map(|t| (c, t))
        };
        // Far child pushed first, so the near one is visited first.
        match (child(index + 1), child(node.left_or_first as usize)) {
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
            if !(disc >= 0.0) {
                return None;
            }
            let sq = disc.sqrt();
            ((-b - sq) / (2.0 * a), (-b + sq) / (2.0 * a))
        }
        SphereTest::Stable => {
            let b = f.dot(d);
            let l = f - b * d;
            let disc = r2 - l.dot(l);
            if !(disc >= 0.0) {
                return None;
            }
            let c = f.dot(f) - r2;
            let q = -b - if b >= 0.0 { 1.0 } else { -1.0 } * disc.sqrt();
            let (t0, t1) = (c / q, q);
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
            let eu = cx * by - cy * bx;
            let ev = ax * cy - ay * cx;
            let ew = bx * ay - by * ax;
            if (eu < 0.0 || ev < 0.0 || ew < 0.0) && (eu > 0.0 || ev > 0.0 || ew > 0.0) {
                return None;
            }
            let det = eu + ev + ew;
            if det == 0.0 {
                return None;
            }
            let tz = eu * (r.s.z * a[kz]) + ev * (r.s.z * b[kz]) + ew * (r.s.z * c[kz]);
            let inv = 1.0 / det;
            let t = tz * inv;
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
            let u = tv.dot(pv) * inv;
            if !(u >= 0.0 && u <= 1.0) {
                return None;
            }
            let qv = tv.cross(e1);
            let v = r.d.dot(qv) * inv;
            if !(v >= 0.0 && u + v <= 1.0) {
                return None;
            }
            let t = e2.dot(qv) * inv;
            if !(t > t_min && t < t_max) || is_degenerate(tri) {
                return None;
            }
            Some((t, u, v))
        }
    }
}

#[derive(Debug, PartialEq)]
enum Hit {
    Sphere(usize),
    Triangle(usize, f64, f64),
}

fn closest_hit(tracer: &Tracer, o: DVec3, d: DVec3) -> Option<(f64, Hit)> {
    let scene = tracer.scene;
    let n = &scene.numerics;
    let r = tri_ray(n.triangle, o, d);
    let Some(bvh) = &tracer.bvh else {
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
    if bvh.nodes.is_empty() || enter_box(bvh.nodes[0].min, bvh.nodes[0].max, o, d, T_MAX).is_none()
    {
        return None;
    }
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

fn occluded(tracer: &Tracer, o: DVec3, d: DVec3, dist: f64) -> bool {
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
    let Some(bvh) = &tracer.bvh else {
        return scene
            .spheres
            .iter()
            .any(|s| hit_sphere(n.sphere, o, d, s, 0.0, dist).is_some())
            || scene
                .triangles
                .iter()
                .any(|t| hit_triangle(n.triangle, &r, t, 0.0, dist).is_some());
    };
    if bvh.nodes.is_empty() || enter_box(bvh.nodes[0].min, bvh.nodes[0].max, o, d, dist).is_none() {
        return false;
    }
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

/// The shader's `ulp_offset_1`. The offset is a distance on the f32 grid (256
/// f32 ULPs), so the reference moves by that same distance: it takes the f32
/// step at `p` and adds it to the f64 coordinate.
fn ulp_offset_1(p: f64, n: f64) -> f64 {
    const ORIGIN: f64 = 1.0 / 32.0;
    const FLOAT_SCALE: f64 = 1.0 / 65536.0;
    if p.abs() < ORIGIN {
        return p + FLOAT_SCALE * n;
    }
    let of = (256.0 * n as f32) as i32;
    let pf = p as f32;
    let bits = (pf.to_bits() as i32).wrapping_add(if pf < 0.0 { -of } else { of });
    p + (f32::from_bits(bits as u32) as f64 - pf as f64)
}

/// The shader's SHADOW_REACH: shadow rays stop this share of the way to the light.
const SHADOW_REACH: f64 = 0.9999;

/// The shader's SCALE_AWARE_REL (2^-22).
const SCALE_AWARE_REL: f64 = 1.0 / 4_194_304.0;

/// The shader's `spawn_point`: where a secondary ray along `dir` leaves `p`;
/// `scale` is the largest coordinate of the ray origin (and of a triangle's vertices).
fn spawn_point(scene: &Scene, p: DVec3, n: DVec3, dir: DVec3, scale: f64) -> DVec3 {
    match scene.numerics.offset {
        Offset::ScaleAware => p + n * (SCALE_AWARE_REL * scale.max(p.abs().max_element())),
        Offset::Ray => p + scene.epsilon * dir,
        Offset::Normal => p + scene.epsilon * n,
        Offset::Ulp => DVec3::new(
            ulp_offset_1(p.x, n.x),
            ulp_offset_1(p.y, n.y),
            ulp_offset_1(p.z, n.z),
        ),
        Offset::NormalScaled => {
            let scale = p.abs().max_element().max(1.0);
            p + n * (scene.epsilon * scale)
        }
    }
}

fn fresnel(cos_i: f64, cos_t: f64, eta: f64) -> f64 {
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (rs * rs + rp * rp)
}

fn reflect(i: DVec3, n: DVec3) -> DVec3 {
    i - 2.0 * n.dot(i) * n
}

struct Ray {
    o: DVec3,
    d: DVec3,
    w: f64,
    depth: u32,
}

/// One pixel: the shader's `trace`, with its stack capacity of max_depth + 1.
fn trace_with(tracer: &Tracer, origin: DVec3, dir: DVec3) -> DVec3 {
    let scene = tracer.scene;
    let capacity = scene.max_depth as usize + 1;
    let mut stack = Vec::with_capacity(capacity);
    stack.push(Ray {
        o: origin,
        d: dir,
        w: 1.0,
        depth: 0,
    });
    let mut color = DVec3::ZERO;
    while let Some(Ray { o, d, w, depth }) = stack.pop() {
        let Some((t, hit)) = closest_hit(tracer, o, d) else {
            color += w * scene.background;
            continue;
        };
        let mut p = o + t * d;
        let max_abs = |v: DVec3| v.abs().max_element();
        let (mut ng, mut ns, mat, scale) = match hit {
            Hit::Sphere(i) => {
                let s = &scene.spheres[i];
                let n = (p - s.center) / s.radius;
                (n, n, s.material, 4.0 * max_abs(o).max(max_abs(p)))
            }
            Hit::Triangle(i, u, v) => {
                let tri = &scene.triangles[i];
                let (e1, e2) = (tri.p[1] - tri.p[0], tri.p[2] - tri.p[0]);
                // The shader's barycentric hit point for the offsets that assume one.
                if matches!(scene.numerics.offset, Offset::ScaleAware | Offset::Ulp) {
                    p = tri.p[0] + u * e1 + v * e2;
                }
                let ng = e1.cross(e2).normalize();
                let ns = ((1.0 - u - v) * tri.n[0] + u * tri.n[1] + v * tri.n[2]).normalize();
                let prim = max_abs(tri.p[0])
                    .max(max_abs(tri.p[1]))
                    .max(max_abs(tri.p[2]));
                (ng, ns, tri.material, max_abs(o).max(prim))
            }
        };
        let inside = d.dot(ng) > 0.0;
        if inside {
            ng = -ng;
        }
        if ns.dot(ng) < 0.0 {
            ns = -ns;
        }
        let m = &scene.materials[mat as usize];

        let mut local = m.ambient;
        for light in &scene.lights {
            let p_out = spawn_point(scene, p, ng, (light.position - p).normalize(), scale);
            let to_light = light.position - p_out;
            let dist = to_light.length();
            let l = to_light / dist;
            let ndl = ns.dot(l);
            if ndl > 0.0 && ng.dot(l) > 0.0 && !occluded(tracer, p_out, l, dist * SHADOW_REACH) {
                let r = reflect(-l, ns);
                let spec = r.dot(-d).max(0.0).powf(m.shininess);
                local += light.color * (m.diffuse * ndl + m.specular * spec);
            }
        }
        color += w * local;

        if depth + 1 < scene.max_depth {
            let mut kr = m.reflectivity;
            let kt = m.transparency;
            if kt > 0.0 {
                let eta = if inside { m.ior } else { 1.0 / m.ior };
                let cos_i = -d.dot(ns);
                let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
                if k < 0.0 {
                    kr += kt;
                } else {
                    let cos_t = k.sqrt();
                    let f = fresnel(cos_i, cos_t, eta);
                    kr += kt * f;
                    let wt = w * kt * (1.0 - f);
                    if wt >= scene.min_weight && stack.len() < capacity {
                        let dir = (eta * d + (eta * cos_i - cos_t) * ns).normalize();
                        stack.push(Ray {
                            o: spawn_point(scene, p, -ng, dir, scale),
                            d: dir,
                            w: wt,
                            depth: depth + 1,
                        });
                    }
                }
            }
            let wr = w * kr;
            if wr >= scene.min_weight && stack.len() < capacity {
                let dir = reflect(d, ns);
                stack.push(Ray {
                    o: spawn_point(scene, p, ng, dir, scale),
                    d: dir,
                    w: wr,
                    depth: depth + 1,
                });
            }
        }
    }
    color
}

/// The numerics of the "truth" against which the accuracy report and the hard
/// cases measure error: in f64, a 1e-8 offset along the normal is far above
/// f64 rounding (1e-10 at 1e6) and far below any feature of the scenes (1e-4),
/// so it neither re-hits surfaces nor detaches shadows.
pub const TRUTH_EPSILON: f64 = 1e-8;

pub fn truth_numerics() -> Numerics {
    Numerics {
        offset: Offset::Normal,
        triangle: TriangleTest::Watertight,
        sphere: SphereTest::Stable,
    }
}

/// The f64 reference with the truth numerics (`truth_numerics`, `TRUTH_EPSILON`):
/// what the GPU image should be, whatever its own numerical choices.
pub fn render_truth(scene: &Scene, width: u32, height: u32) -> FloatImage {
    let mut s = scene.clone();
    s.epsilon = TRUTH_EPSILON;
    render_with(&s, width, height, &truth_numerics())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every pixel through the BVH equals brute force, bit for bit.
    fn same_as_brute_force(scene: &Scene, width: u32, height: u32) {
        let scene = scene.rounded_to_f32();
        let frame = RayFrame::new(&scene.camera, width, height).rounded_to_f32();
        // A BVH even where `Tracer::new` would not build one (under BVH_FROM primitives).
        let bvh = Tracer {
            scene: &scene,
            bvh: Some(Bvh::build(&scene)),
        };
        let brute = Tracer::brute_force(&scene);
        let mismatches = (0..width * height)
            .into_par_iter()
            .filter(|i| {
                let dir = frame.dir((i % width) as f64, (i / width) as f64);
                // The same primitive, not only the same colour: identical
                // spheres would hide a tie broken the other way.
                closest_hit(&bvh, frame.eye, dir) != closest_hit(&brute, frame.eye, dir)
                    || bvh.trace(frame.eye, dir) != brute.trace(frame.eye, dir)
            })
            .count();
        assert_eq!(
            mismatches, 0,
            "{}: pixels differ from brute force",
            scene.name
        );
    }

    #[test]
    fn bvh_gives_the_brute_force_image() {
        let hard = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/hard");
        for (name, set) in [
            ("box", vec![]),
            // 100 identical spheres: every hit is a tie, which brute force gives to the first.
            (
                "spherelist",
                vec![("extra_spheres".to_string(), "100".to_string())],
            ),
            ("teapot", vec![]),
        ] {
            let scene = Scene::load(name, &set).unwrap();
            same_as_brute_force(&scene, 40, 30);
        }
        // Eight coincident spheres of two colours: every primary hit is a tie
        // that brute force gives to spheres[0], and the image shows which won.
        let mut ties = String::from(
            "[camera]\neye = [0.0, 0.0, 5.0]\nlook_at = [0.0, 0.0, 0.0]\n\
             [[materials]]\nname = \"red\"\ndiffuse = [1.0, 0.0, 0.0]\n\
             [[materials]]\nname = \"green\"\ndiffuse = [0.0, 1.0, 0.0]\n\
             [[lights]]\nposition = [0.0, 5.0, 5.0]\n",
        );
        for i in 0..8 {
            let m = if i % 2 == 0 { "green" } else { "red" };
            ties += &format!(
                "[[spheres]]\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\nmaterial = \"{m}\"\n"
            );
        }
        let scene = Scene::from_toml("ties", &ties, std::path::Path::new("."), &[]).unwrap();
        same_as_brute_force(&scene, 16, 16);
        for case in [
            "coplanar",
            "far-1e6",
            "closed-mesh",
            "nested-glass",
            "grazing",
        ] {
            let path = hard.join(format!("{case}.toml"));
            let scene = Scene::load(path.to_str().unwrap(), &[]).unwrap();
            same_as_brute_force(&scene, 32, 32);
        }
    }
}
