//! The CPU reference: shaders/trace.glsl step by step in f64, one pixel per
//! rayon task. Same ray stack, same push order, same offsets and tests — the
//! shader's compile-time numerical choices (numerics.rs) are run-time branches
//! here — so the GPU images differ from it only by f32 arithmetic.
//! It traces the scene as the GPU holds it (in the local frame of
//! `camera::in_local_frame`, inputs rounded to f32, see `Scene::rounded_to_f32`).
//! Change both together.

use crate::camera::{in_local_frame, RayFrame};
use crate::image_io::FloatImage;
use crate::numerics::{Numerics, Offset, SphereTest, TriangleTest};
use crate::scene::{Scene, Sphere, Triangle};
use glam::DVec3;
use rayon::prelude::*;

const T_MAX: f64 = 1.0e30;

/// Renders `scene` at width × height with the scene's own numerics. Uses the
/// generic stack (no variant pruning is needed on the CPU: absent features
/// simply never trigger).
pub fn render(scene: &Scene, width: u32, height: u32) -> FloatImage {
    render_with(scene, width, height, &scene.numerics)
}

/// Renders `scene` with the given numerical choices instead of the scene's.
pub fn render_with(scene: &Scene, width: u32, height: u32, numerics: &Numerics) -> FloatImage {
    // The GPU's frame: positions relative to the local origin, then rounded to f32.
    let frame = RayFrame::local(scene, &scene.camera, width, height).rounded_to_f32();
    let mut scene = in_local_frame(scene).rounded_to_f32();
    scene.numerics = *numerics;
    let pixels: Vec<[f32; 3]> = (0..width * height)
        .into_par_iter()
        .map(|i| {
            let (x, y) = ((i % width) as f64, (i / width) as f64);
            let c = trace(&scene, frame.eye, frame.dir(x, y));
            [c.x as f32, c.y as f32, c.z as f32]
        })
        .collect();
    FloatImage {
        width,
        height,
        pixels,
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

enum Hit {
    Sphere(usize),
    Triangle(usize, f64, f64),
}

fn closest_hit(scene: &Scene, o: DVec3, d: DVec3) -> Option<(f64, Hit)> {
    let mut best_t = T_MAX;
    let mut best = None;
    let n = &scene.numerics;
    for (i, s) in scene.spheres.iter().enumerate() {
        if let Some(t) = hit_sphere(n.sphere, o, d, s, 0.0, best_t) {
            best_t = t;
            best = Some(Hit::Sphere(i));
        }
    }
    let r = tri_ray(n.triangle, o, d);
    for (i, tri) in scene.triangles.iter().enumerate() {
        if let Some((t, u, v)) = hit_triangle(n.triangle, &r, tri, 0.0, best_t) {
            best_t = t;
            best = Some(Hit::Triangle(i, u, v));
        }
    }
    best.map(|h| (best_t, h))
}

fn occluded(scene: &Scene, o: DVec3, d: DVec3, dist: f64) -> bool {
    let n = &scene.numerics;
    let r = tri_ray(n.triangle, o, d);
    scene
        .spheres
        .iter()
        .any(|s| hit_sphere(n.sphere, o, d, s, 0.0, dist).is_some())
        || scene
            .triangles
            .iter()
            .any(|t| hit_triangle(n.triangle, &r, t, 0.0, dist).is_some())
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
pub fn trace(scene: &Scene, origin: DVec3, dir: DVec3) -> DVec3 {
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
        let Some((t, hit)) = closest_hit(scene, o, d) else {
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
            if ndl > 0.0 && ng.dot(l) > 0.0 && !occluded(scene, p_out, l, dist * SHADOW_REACH) {
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
