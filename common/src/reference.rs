//! The CPU reference: shaders/trace.glsl step by step in f64, one pixel per
//! rayon task. Same ray stack, same push order, same offsets and tests, so the
//! GPU images differ from it only by f32 rounding. Change both together.

use crate::camera::RayFrame;
use crate::image_io::FloatImage;
use crate::scene::{Scene, Sphere, Triangle};
use glam::DVec3;
use rayon::prelude::*;

const T_MAX: f64 = 1.0e30;

/// Renders `scene` at width × height. Uses the generic stack (no variant
/// pruning is needed on the CPU: absent features simply never trigger).
pub fn render(scene: &Scene, width: u32, height: u32) -> FloatImage {
    let frame = RayFrame::new(&scene.camera, width, height);
    let pixels: Vec<[f32; 3]> = (0..width * height)
        .into_par_iter()
        .map(|i| {
            let (x, y) = ((i % width) as f64, (i / width) as f64);
            let c = trace(scene, frame.eye, frame.dir(x, y));
            [c.x as f32, c.y as f32, c.z as f32]
        })
        .collect();
    FloatImage { width, height, pixels }
}

fn hit_sphere(o: DVec3, d: DVec3, s: &Sphere, t_min: f64, t_max: f64) -> Option<f64> {
    let f = o - s.center;
    let b = f.dot(d);
    let l = f - b * d;
    let r2 = s.radius * s.radius;
    let disc = r2 - l.dot(l);
    if !(disc >= 0.0) {
        return None;
    }
    let c = f.dot(f) - r2;
    let q = -b - if b >= 0.0 { 1.0 } else { -1.0 } * disc.sqrt();
    let (t0, t1) = (c / q, q);
    let (lo, hi) = (t0.min(t1), t0.max(t1));
    if lo > t_min && lo < t_max {
        return Some(lo);
    }
    if hi > t_min && hi < t_max {
        return Some(hi);
    }
    None
}

fn hit_triangle(o: DVec3, d: DVec3, tri: &Triangle, t_min: f64, t_max: f64) -> Option<(f64, f64, f64)> {
    let e1 = tri.p[1] - tri.p[0];
    let e2 = tri.p[2] - tri.p[0];
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let tv = o - tri.p[0];
    let u = tv.dot(pv) * inv;
    if !(u >= 0.0 && u <= 1.0) {
        return None;
    }
    let qv = tv.cross(e1);
    let v = d.dot(qv) * inv;
    if !(v >= 0.0 && u + v <= 1.0) {
        return None;
    }
    let t = e2.dot(qv) * inv;
    if !(t > t_min && t < t_max) {
        return None;
    }
    Some((t, u, v))
}

enum Hit {
    Sphere(usize),
    Triangle(usize, f64, f64),
}

fn closest_hit(scene: &Scene, o: DVec3, d: DVec3) -> Option<(f64, Hit)> {
    let mut best_t = T_MAX;
    let mut best = None;
    for (i, s) in scene.spheres.iter().enumerate() {
        if let Some(t) = hit_sphere(o, d, s, 0.0, best_t) {
            best_t = t;
            best = Some(Hit::Sphere(i));
        }
    }
    for (i, tri) in scene.triangles.iter().enumerate() {
        if let Some((t, u, v)) = hit_triangle(o, d, tri, 0.0, best_t) {
            best_t = t;
            best = Some(Hit::Triangle(i, u, v));
        }
    }
    best.map(|h| (best_t, h))
}

fn occluded(scene: &Scene, o: DVec3, d: DVec3, dist: f64) -> bool {
    scene.spheres.iter().any(|s| hit_sphere(o, d, s, 0.0, dist).is_some())
        || scene.triangles.iter().any(|t| hit_triangle(o, d, t, 0.0, dist).is_some())
}

fn offset_point(scene: &Scene, p: DVec3, n: DVec3) -> DVec3 {
    let scale = p.abs().max_element().max(1.0);
    p + n * (scene.epsilon * scale)
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
    stack.push(Ray { o: origin, d: dir, w: 1.0, depth: 0 });
    let mut color = DVec3::ZERO;
    while let Some(Ray { o, d, w, depth }) = stack.pop() {
        let Some((t, hit)) = closest_hit(scene, o, d) else {
            color += w * scene.background;
            continue;
        };
        let p = o + t * d;
        let (mut ng, mut ns, mat) = match hit {
            Hit::Sphere(i) => {
                let s = &scene.spheres[i];
                let n = (p - s.center) / s.radius;
                (n, n, s.material)
            }
            Hit::Triangle(i, u, v) => {
                let tri = &scene.triangles[i];
                let ng = (tri.p[1] - tri.p[0]).cross(tri.p[2] - tri.p[0]).normalize();
                let ns = ((1.0 - u - v) * tri.n[0] + u * tri.n[1] + v * tri.n[2]).normalize();
                (ng, ns, tri.material)
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
        let p_out = offset_point(scene, p, ng);
        for light in &scene.lights {
            let to_light = light.position - p_out;
            let dist = to_light.length();
            let l = to_light / dist;
            let ndl = ns.dot(l);
            if ndl > 0.0 && ng.dot(l) > 0.0 && !occluded(scene, p_out, l, dist) {
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
                        stack.push(Ray { o: offset_point(scene, p, -ng), d: dir, w: wt, depth: depth + 1 });
                    }
                }
            }
            let wr = w * kr;
            if wr >= scene.min_weight && stack.len() < capacity {
                stack.push(Ray { o: p_out, d: reflect(d, ns), w: wr, depth: depth + 1 });
            }
        }
    }
    color
}
