//! Throwaway: follows one pixel's primary and first reflection ray in f32 on
//! the uploaded GpuScene data, to tell shader precision from GL plumbing.
use twinray_common::{gpu::GpuScene, scene::Scene};
type V = [f32; 3];
fn sub(a: V, b: V) -> V { [a[0]-b[0], a[1]-b[1], a[2]-b[2]] }
fn add(a: V, b: V) -> V { [a[0]+b[0], a[1]+b[1], a[2]+b[2]] }
fn mul(a: V, s: f32) -> V { [a[0]*s, a[1]*s, a[2]*s] }
fn dot(a: V, b: V) -> f32 { a[0]*b[0]+a[1]*b[1]+a[2]*b[2] }
fn cross(a: V, b: V) -> V { [a[1]*b[2]-a[2]*b[1], a[2]*b[0]-a[0]*b[2], a[0]*b[1]-a[1]*b[0]] }
fn norm(a: V) -> V { mul(a, 1.0 / dot(a, a).sqrt()) }
fn closest(g: &GpuScene, o: V, d: V) -> Option<(f32, usize, f32, f32)> {
    let mut best = None; let mut tmax = 1e30f32;
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

fn occl(g: &GpuScene, o: V, d: V, dist: f32) -> bool {
    for t in &g.triangles {
        let e1 = sub(t.p1, t.p0); let e2 = sub(t.p2, t.p0);
        let pv = cross(d, e2); let det = dot(e1, pv);
        if det == 0.0 { continue; }
        let inv = 1.0 / det; let tv = sub(o, t.p0); let u = dot(tv, pv) * inv;
        if !(u >= 0.0 && u <= 1.0) { continue; }
        let qv = cross(tv, e1); let v = dot(d, qv) * inv;
        if !(v >= 0.0 && u + v <= 1.0) { continue; }
        let tt = dot(e2, qv) * inv;
        if tt > 0.0 && tt < dist { return true; }
    }
    false
}
fn occl_i(g: &GpuScene, o: V, d: V, dist: f32) -> Option<usize> {
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
fn trace(g: &GpuScene, o0: V, d0: V) -> V {
    let f = g.frame;
    let mut st = vec![(o0, d0, 1.0f32, 0u32)];
    let mut color = [0.0f32; 3];
    while let Some((o, d, w, depth)) = st.pop() {
        let Some((t, i, u, v)) = closest(g, o, d) else { color = add(color, mul(f.background, w)); continue };
        let tri = &g.triangles[i];
        let p = add(o, mul(d, t));
        let mut ng = norm(cross(sub(tri.p1, tri.p0), sub(tri.p2, tri.p0)));
        let mut ns = norm(add(add(mul(tri.n0, 1.0 - u - v), mul(tri.n1, u)), mul(tri.n2, v)));
        if dot(d, ng) > 0.0 { ng = mul(ng, -1.0); }
        if dot(ns, ng) < 0.0 { ns = mul(ns, -1.0); }
        let m = &g.materials[tri.material as usize];
        let scale = p.iter().fold(1.0f32, |m, c| m.max(c.abs()));
        let p_out = add(p, mul(ng, f.epsilon * scale));
        let mut local = m.ambient;
        for l in &g.lights {
            let tl = sub(l.position, p_out); let dist = dot(tl, tl).sqrt(); let ld = mul(tl, 1.0 / dist);
            let ndl = dot(ns, ld);
            if ndl > 0.0 && dot(ng, ld) > 0.0 && !occl(g, p_out, ld, dist) {
                let r = sub(mul(ld, -1.0), mul(ns, 2.0 * dot(ns, mul(ld, -1.0))));
                let spec = dot(r, mul(d, -1.0)).max(0.0).powf(m.shininess);
                for c in 0..3 { local[c] += l.color[c] * (m.diffuse[c] * ndl + m.specular[c] * spec); }
            }
        }
        color = add(color, mul(local, w));
        if depth + 1 < f.max_depth {
            let wr = w * m.reflectivity;
            if wr >= f.min_weight { st.push((p_out, sub(d, mul(ns, 2.0 * dot(ns, d))), wr, depth + 1)); }
        }
    }
    color
}
fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    if a.len() == 4 {
        let (w, h): (u32, u32) = (a[1].parse().unwrap(), a[2].parse().unwrap());
        let scene = Scene::load(&a[0], &[]).unwrap();
        let g = GpuScene::new(&scene, w, h);
        let f = g.frame;
        let mut rgb = Vec::new();
        for y in 0..h { for x in 0..w {
            let target = add(add(f.top_left, mul(f.step_x, x as f32)), mul(f.step_y, y as f32));
            let c = trace(&g, f.eye, norm(sub(target, f.eye)));
            rgb.extend(c.iter().map(|&v| twinray_common::image_io::quantize(v)));
        }}
        let img = twinray_common::image_io::FloatImage { width: w, height: h, pixels: rgb.chunks(3).map(|c| [c[0] as f32 / 255.0, c[1] as f32 / 255.0, c[2] as f32 / 255.0]).collect() };
        img.save_png(std::path::Path::new(&a[3])).unwrap();
        return;
    }
    let a: Vec<String> = std::env::args().skip(1).collect();
    let (w, h, x, y): (u32, u32, f32, f32) = (a[1].parse().unwrap(), a[2].parse().unwrap(), a[3].parse().unwrap(), a[4].parse().unwrap());
    let scene = Scene::load(&a[0], &[]).unwrap();
    let g = GpuScene::new(&scene, w, h);
    let f = g.frame;
    let fx = x + 0.5; let fy = y + 0.5;
    let target = add(add(f.top_left, mul(f.step_x, fx - 0.5)), mul(f.step_y, fy - 0.5));
    let mut o = f.eye; let mut d = norm(sub(target, f.eye));
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
                println!("bounce {bounce}: tri {i} t {t} p {p:?} ng {ng:?} ns {ns:?} inside {inside} tri {tri:?}");
                let scale_ = p.iter().fold(1.0 as f32, |m, c| m.max(c.abs()));
                let po = add(p, mul(ng, f.epsilon * scale_));
                for (li, lp) in g.lights.iter().map(|l| l.position).collect::<Vec<V>>().iter().enumerate() {
                    let tl = sub(*lp, po); let dist = dot(tl, tl).sqrt(); let ld = mul(tl, 1.0 / dist);
                    println!("   light {li}: ndl {} ngl {} occluded by {:?}", dot(ns, ld), dot(ng, ld), occl_i(&g, po, ld, dist));
                }
                let scale = p.iter().fold(1.0f32, |m, c| m.max(c.abs()));
                o = add(p, mul(ng, f.epsilon * scale));
                d = sub(d, mul(ns, 2.0 * dot(ns, d)));
            }
        }
    }
}
