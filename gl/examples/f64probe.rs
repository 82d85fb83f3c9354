//! Throwaway: follows one pixel's primary and first reflection ray in F on
//! the uploaded G data, to tell shader precision from GL plumbing.
use twinray_common::scene::Scene;
type F = f64;
type V = [F; 3];
#[derive(Debug)] struct T { p0: V, p1: V, p2: V, n0: V, n1: V, n2: V }
struct G { triangles: Vec<T> }

fn sub(a: V, b: V) -> V { [a[0]-b[0], a[1]-b[1], a[2]-b[2]] }
fn add(a: V, b: V) -> V { [a[0]+b[0], a[1]+b[1], a[2]+b[2]] }
fn mul(a: V, s: F) -> V { [a[0]*s, a[1]*s, a[2]*s] }
fn dot(a: V, b: V) -> F { a[0]*b[0]+a[1]*b[1]+a[2]*b[2] }
fn cross(a: V, b: V) -> V { [a[1]*b[2]-a[2]*b[1], a[2]*b[0]-a[0]*b[2], a[0]*b[1]-a[1]*b[0]] }
fn norm(a: V) -> V { mul(a, 1.0 / dot(a, a).sqrt()) }
fn closest(g: &G, o: V, d: V) -> Option<(F, usize, F, F)> {
    let mut best = None; let mut tmax = 1e30;
    for (i, t) in g.triangles.iter().enumerate() {
        let e1 = sub(t.p1, t.p0); let e2 = sub(t.p2, t.p0);
        let pv = cross(d, e2); let det = dot(e1, pv);
        if det == 0.0 { continue; }
        let inv = 1.0 / det; let tv = sub(o, t.p0); let u = dot(tv, pv) * inv;
        if !(u >= 0.0 && u <= 1.0) { continue; }
        let qv = cross(tv, e1); let v = dot(d, qv) * inv;
        if !(v >= 0.0 && u + v <= 1.0) { continue; }
        let tt = dot(e2, qv) * inv;
        if !(tt > 0.0 && tt < tmax) { continue; }
        tmax = tt; best = Some((tt, i, u, v));
    }
    best
}


fn occl(g: &G, o: V, d: V, dist: F) -> Option<usize> {
    for (i, t) in g.triangles.iter().enumerate() {
        let e1 = sub(t.p1, t.p0); let e2 = sub(t.p2, t.p0);
        let pv = cross(d, e2); let det = dot(e1, pv);
        if det == 0.0 { continue; }
        let inv = 1.0 / det; let tv = sub(o, t.p0); let u = dot(tv, pv) * inv;
        if !(u >= 0.0 && u <= 1.0) { continue; }
        let qv = cross(tv, e1); let v = dot(d, qv) * inv;
        if !(v >= 0.0 && u + v <= 1.0) { continue; }
        let tt = dot(e2, qv) * inv;
        if tt > 0.0 && tt < dist { return Some(i); }
    }
    None
}
fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let (w, h, x, y): (u32, u32, F, F) = (a[1].parse().unwrap(), a[2].parse().unwrap(), a[3].parse().unwrap(), a[4].parse().unwrap());
    let scene = Scene::load(&a[0], &[]).unwrap();
    let c = |v: &[f64; 3]| -> V { *v };
    let g = G { triangles: scene.triangles.iter().map(|t| T { p0: c(&t.p[0].to_array()), p1: c(&t.p[1].to_array()), p2: c(&t.p[2].to_array()), n0: c(&t.n[0].to_array()), n1: c(&t.n[1].to_array()), n2: c(&t.n[2].to_array()) }).collect() };
    let rf = twinray_common::camera::RayFrame::new(&scene.camera, w, h);
    let mut o: V = rf.eye.to_array(); let mut d: V = rf.dir(x, y).to_array();
    let eps = scene.epsilon;
    for bounce in 0..3 {
        match closest(&g, o, d) {
            None => { println!("bounce {bounce}: miss (dir {d:?})"); break; }
            Some((t, i, u, v)) => {
                let tri = &g.triangles[i];
                let p = add(o, mul(d, t));
                let mut ng = norm(cross(sub(tri.p1, tri.p0), sub(tri.p2, tri.p0)));
                let mut ns = norm(add(add(mul(tri.n0, 1.0 - u - v), mul(tri.n1, u)), mul(tri.n2, v)));
                let inside = dot(d, ng) > 0.0;
                if inside { ng = mul(ng, -1.0); }
                if dot(ns, ng) < 0.0 { ns = mul(ns, -1.0); }
                println!("bounce {bounce}: tri {i} t {t} p {p:?} ng {ng:?} ns {ns:?} inside {inside}");
                let scale_ = p.iter().fold(1.0 as F, |m, c| m.max(c.abs()));
                let po = add(p, mul(ng, eps * scale_));
                for (li, lp) in scene.lights.iter().map(|l| l.position.to_array()).collect::<Vec<V>>().iter().enumerate() {
                    let tl = sub(*lp, po); let dist = dot(tl, tl).sqrt(); let ld = mul(tl, 1.0 / dist);
                    println!("   light {li}: ndl {} ngl {} occluded by {:?}", dot(ns, ld), dot(ng, ld), occl(&g, po, ld, dist));
                }
                let scale = p.iter().fold(1.0 as F, |m, c| m.max(c.abs()));
                o = add(p, mul(ng, eps * scale));
                d = sub(d, mul(ns, 2.0 * dot(ns, d)));
            }
        }
    }
}
