//! The CPU reference: shaders/trace/*.glsl step by step in f64, one pixel per
//! rayon task. Same ray stack, same push order, same offsets and tests — the
//! shader's compile-time numerical choices (numerics.rs) are run-time branches
//! here — so the GPU images differ from it only by f32 arithmetic.
//! It traces the scene as the GPU holds it (in the local frame of
//! `camera::in_local_frame`, inputs rounded to f32, see `Scene::rounded_to_f32`).
//! Change both together. Beside the tracer: `image_io` (float images and
//! PNG files) and `metrics` (how far one image is from another).
//!
//! Rays traverse the GPU's own tree: the builder (scene/accel/build.rs) works
//! on the primitives rounded to f32, which is what the reference traces, so
//! built over the reference's scene it gives the tree the GPU walks, node for
//! node, and a 2-million-triangle mesh takes seconds, not hours. The traversal
//! keeps brute force's answer exactly: the closest hit, ties going to the
//! primitive brute force tests first.

pub mod image_io;
mod intersect;
pub mod metrics;
pub mod perturb;
pub mod sampled;
pub mod unsettled;

use crate::rays::RayKinds;
use crate::reference::image_io::FloatImage;
use crate::reference::intersect::{closest_hit, occluded, Hit, Tracer};
use crate::reference::perturb::{at, at3, scaled, Op};
use crate::scene::camera::{in_local_frame, RayFrame};
use crate::scene::numerics::{Numerics, Offset, SphereTest, TriangleTest};
use crate::scene::Scene;
use glam::{DVec2, DVec3};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Renders `scene` at width × height with the scene's own numerics. Uses the
/// generic stack (no variant pruning is needed on the CPU: absent features
/// simply never trigger).
pub fn render(scene: &Scene, width: u32, height: u32) -> FloatImage {
    render_with(scene, width, height, &scene.numerics)
}

/// Renders `scene` with the given numerical choices instead of the scene's.
pub fn render_with(scene: &Scene, width: u32, height: u32, numerics: &Numerics) -> FloatImage {
    render_counting(
        scene,
        width,
        height,
        numerics,
        Some(2),
        &AtomicUsize::new(0),
    )
}

/// `render_with`, through the BVH of `bvh_width` children a node or (None:
/// `--accel none`) testing every primitive, adding 1 to `rows_done` as each row finishes (for a progress bar).
pub fn render_counting(
    scene: &Scene,
    width: u32,
    height: u32,
    numerics: &Numerics,
    bvh_width: Option<u32>,
    rows_done: &AtomicUsize,
) -> FloatImage {
    let picture = Picture {
        scene,
        width,
        height,
        numerics,
    };
    render_turned(&picture, bvh_width, rows_done, DVec2::ZERO)
}

/// What a reference render draws: a scene at a size, with numerical choices.
struct Picture<'a> {
    scene: &'a Scene,
    width: u32,
    height: u32,
    numerics: &'a Numerics,
}

/// `render_counting` with every primary ray turned by `turn` radians
/// towards the image's right (x) and down (y) (`unsettled`); zero leaves
/// each direction as it is, bit for bit.
fn render_turned(
    picture: &Picture,
    bvh_width: Option<u32>,
    rows_done: &AtomicUsize,
    turn: DVec2,
) -> FloatImage {
    let &Picture {
        scene,
        width,
        height,
        numerics,
    } = picture;
    // The GPU's frame: positions relative to the local origin, then rounded to f32.
    let frame = RayFrame::local(scene, &scene.camera, width, height).rounded_to_f32();
    let (right, down) = (frame.step_x.normalize(), frame.step_y.normalize());
    let mut scene = in_local_frame(scene).rounded_to_f32();
    scene.numerics = *numerics;
    let tracer = match bvh_width {
        Some(width) => Tracer::with_width(&scene, width),
        None => Tracer::brute_force(&scene),
    };
    let w = width as usize;
    let mut pixels = vec![[0f32; 3]; crate::limits::pixel_count(width, height)];
    pixels.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, px) in row.iter_mut().enumerate() {
            let mut dir = frame.dir(x as f64, y as f64);
            if turn != DVec2::ZERO {
                dir = (dir + turn.x * right + turn.y * down).normalize();
            }
            let dir = scaled(Op::DirLength, at3(Op::PrimaryDir, dir));
            let c = tracer.trace(frame.eye, dir);
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
impl Tracer<'_> {
    pub fn trace(&self, origin: DVec3, dir: DVec3) -> DVec3 {
        trace_with(self, origin, dir, &mut RayKinds::default(), &mut |_| {})
    }

    /// The ray stack's entries: the most a trace ever holds, the shader's
    /// STACK_SIZE where it walks a tree (brute force declares one more).
    fn ray_capacity(&self) -> usize {
        self.scene
            .features()
            .ray_stack_entries(self.scene.max_depth) as usize
    }
}

/// How one glass or mirror hit divides the weight of the ray that arrived
/// among the rays it sends on, whether or not they are traced (`min_weight`,
/// the stack's capacity): the energy check's unit (`worst_split`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Split {
    pub incoming: f64,
    pub reflected: f64,
    pub refracted: f64,
}

impl Split {
    /// What leaves per unit that arrived; above 1 the hit made light. A
    /// negative weight is never traced, so it takes nothing away from the
    /// other ray (a Fresnel term of 19.5 gave 6.9 reflected and -6 refracted).
    pub fn gain(&self) -> f64 {
        (self.reflected.max(0.0) + self.refracted.max(0.0)) / self.incoming
    }
}

/// The hit of largest `Split::gain` in the ray trees of every pixel of
/// `scene` at width × height (the frame and scene of `render`), with its
/// pixel; `None` where no ray reaches glass or a mirror. A Fresnel term above
/// 1 is shared by the shader and this reference, so no image comparison sees
/// it; this does.
pub fn worst_split(scene: &Scene, width: u32, height: u32) -> Option<(u32, u32, Split)> {
    let frame = RayFrame::local(scene, &scene.camera, width, height).rounded_to_f32();
    let scene = in_local_frame(scene).rounded_to_f32();
    let tracer = Tracer::new(&scene);
    (0..width * height)
        .into_par_iter()
        .filter_map(|i| {
            let (x, y) = (i % width, i / width);
            let mut worst: Option<Split> = None;
            let dir = frame.dir(x as f64, y as f64);
            trace_with(
                &tracer,
                frame.eye,
                dir,
                &mut RayKinds::default(),
                &mut |s| {
                    if worst.is_none_or(|w| s.gain() > w.gain()) {
                        worst = Some(s);
                    }
                },
            );
            worst.map(|s| (x, y, s))
        })
        .max_by(|a, b| a.2.gain().total_cmp(&b.2.gain()))
}

/// The rays the GPU's counting variant would trace for `scene` at width ×
/// height, by kind: the same frame and scene as `render`, through the BVH
/// where the scene has one.
pub fn count_rays(scene: &Scene, width: u32, height: u32) -> RayKinds {
    let frame = RayFrame::local(scene, &scene.camera, width, height).rounded_to_f32();
    let scene = in_local_frame(scene).rounded_to_f32();
    let tracer = Tracer::new(&scene);
    (0..height)
        .into_par_iter()
        .map(|y| {
            let mut kinds = RayKinds::default();
            for x in 0..width {
                trace_with(
                    &tracer,
                    frame.eye,
                    frame.dir(x as f64, y as f64),
                    &mut kinds,
                    &mut |_| {},
                );
            }
            kinds
        })
        .reduce(RayKinds::default, |a, b| a + b)
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
    at3(Op::Spawn, spawn_at(scene, p, n, dir, scale))
}

fn spawn_at(scene: &Scene, p: DVec3, n: DVec3, dir: DVec3, scale: f64) -> DVec3 {
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

/// The shader's hit record: the hit point (rebuilt from the barycentrics for
/// the offsets that assume one), the geometric and shading normals as stored,
/// the material and the offset's scale, for a hit at `p` by a ray from `o`.
fn surface(scene: &Scene, hit: Hit, o: DVec3, mut p: DVec3) -> (DVec3, DVec3, DVec3, u32, f64) {
    let max_abs = |v: DVec3| v.abs().max_element();
    match hit {
        Hit::Sphere(i) => {
            let s = &scene.spheres[i];
            let n = at3(Op::Normal, (p - s.center) / s.radius);
            (p, n, n, s.material, 4.0 * max_abs(o).max(max_abs(p)))
        }
        Hit::Triangle(i, u, v) => {
            let tri = &scene.triangles[i];
            let (e1, e2) = (tri.p[1] - tri.p[0], tri.p[2] - tri.p[0]);
            if matches!(scene.numerics.offset, Offset::ScaleAware | Offset::Ulp) {
                p = at3(Op::HitPoint, tri.p[0] + u * e1 + v * e2);
            }
            let ng = at3(Op::Normal, e1.cross(e2).normalize());
            let ns = ((1.0 - u - v) * tri.n[0] + u * tri.n[1] + v * tri.n[2]).normalize();
            let prim = max_abs(tri.p[0])
                .max(max_abs(tri.p[1]))
                .max(max_abs(tri.p[2]));
            (p, ng, ns, tri.material, max_abs(o).max(prim))
        }
    }
}

/// The shader's Newton step on a sphere hit's t (|o + t d - c|^2 = r^2),
/// which takes the test's approximate division and square root out of the
/// hit point; kept only where the step is below 2^-10 radii, as there.
fn refine(scene: &Scene, hit: &Hit, o: DVec3, d: DVec3, t: f64) -> f64 {
    let Hit::Sphere(i) = *hit else {
        return t;
    };
    let s = &scene.spheres[i];
    let rel = (o - s.center) + t * d;
    let step = (rel.dot(rel) - s.radius * s.radius) / (2.0 * rel.dot(d));
    if step.abs() < s.radius / 1024.0 {
        at(Op::RefinedT, t - step)
    } else {
        t
    }
}

/// One pixel: the shader's `trace`, with its ray stack's capacity,
/// adding its rays to `kinds` where the counting variant counts them and
/// telling `split` how each glass or mirror hit divides its ray's weight.
fn trace_with(
    tracer: &Tracer,
    origin: DVec3,
    dir: DVec3,
    kinds: &mut RayKinds,
    split: &mut dyn FnMut(Split),
) -> DVec3 {
    trace_within(tracer, origin, dir, tracer.ray_capacity(), kinds, split)
}

/// `trace_with` with room for `capacity` pending rays (a test gives it more).
fn trace_within(
    tracer: &Tracer,
    origin: DVec3,
    dir: DVec3,
    capacity: usize,
    kinds: &mut RayKinds,
    split: &mut dyn FnMut(Split),
) -> DVec3 {
    kinds.primary += 1;
    let scene = tracer.scene;
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
        let t = refine(scene, &hit, o, d, t);
        let (p, mut ng, mut ns, mat, scale) = surface(scene, hit, o, at3(Op::HitPoint, o + t * d));
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
            let dist = at(Op::ShadowDir, to_light.length());
            let l = scaled(Op::DirLength, at3(Op::ShadowDir, to_light / dist));
            let ndl = ns.dot(l);
            let faces = ndl > 0.0 && ng.dot(l) > 0.0;
            kinds.shadow += u64::from(faces);
            if faces && !occluded(tracer, p_out, l, dist * SHADOW_REACH) {
                let r = reflect(-l, ns);
                let spec = r.dot(-d).max(0.0).powf(m.shininess);
                local += light.color * (m.diffuse * ndl + m.specular * spec);
            }
        }
        color += w * local;

        if depth + 1 < scene.max_depth {
            let mut kr = m.reflectivity;
            let kt = m.transparency;
            let mut refracted = 0.0;
            if kt > 0.0 {
                let eta = if inside { m.ior } else { 1.0 / m.ior };
                // The shader's choice: where the interpolated normal faces away
                // from the ray, Fresnel and the bend take the geometric normal.
                let nt = if d.dot(ns) > 0.0 { ng } else { ns };
                let cos_i = at(Op::CosI, -d.dot(nt));
                let k = at(Op::TirK, 1.0 - eta * eta * (1.0 - cos_i * cos_i));
                if k < 0.0 {
                    kr += kt;
                } else {
                    let cos_t = k.sqrt();
                    let f = fresnel(cos_i, cos_t, eta);
                    kr += kt * f;
                    let wt = w * kt * (1.0 - f);
                    refracted = wt;
                    if wt >= scene.min_weight && stack.len() < capacity {
                        let dir = (eta * d + (eta * cos_i - cos_t) * nt).normalize();
                        let dir = scaled(Op::DirLength, at3(Op::RefractDir, dir));
                        stack.push(Ray {
                            o: spawn_point(scene, p, -ng, dir, scale),
                            d: dir,
                            w: wt,
                            depth: depth + 1,
                        });
                        kinds.glass_refracted += 1;
                    }
                }
            }
            let wr = w * kr;
            if kr > 0.0 || kt > 0.0 {
                split(Split {
                    incoming: w,
                    reflected: wr,
                    refracted,
                });
            }
            if wr >= scene.min_weight && stack.len() < capacity {
                let dir = scaled(Op::DirLength, at3(Op::ReflectDir, reflect(d, ns)));
                stack.push(Ray {
                    o: spawn_point(scene, p, ng, dir, scale),
                    d: dir,
                    w: wr,
                    depth: depth + 1,
                });
                if kt > 0.0 {
                    kinds.glass_reflected += 1;
                } else {
                    kinds.mirror += 1;
                }
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
mod ray_stack_tests;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::layout::Bvh;

    /// Every pixel through the BVH, of each width, equals brute force, bit for bit.
    fn same_as_brute_force(scene: &Scene, width: u32, height: u32) {
        for w in crate::scene::accel::wide::WIDTHS {
            same_as_brute_force_through(scene, width, height, w);
        }
    }

    fn same_as_brute_force_through(scene: &Scene, width: u32, height: u32, bvh_width: u32) {
        let scene = scene.rounded_to_f32();
        let frame = RayFrame::new(&scene.camera, width, height).rounded_to_f32();
        // A BVH even where `Tracer::new` would not build one (under BVH_FROM primitives).
        let bvh = Tracer {
            scene: &scene,
            bvh: Some(std::borrow::Cow::Owned(Bvh::build(&scene).widen(bvh_width))),
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
            "{}, {bvh_width}-wide: pixels differ from brute force",
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

    /// The reference walks the tree the GPU walks: built over the reference's
    /// scene (local frame, rounded to f32), it equals the nodes and leaf
    /// primitives of the GPU's buffers, for a scene at the origin and for ones
    /// moved to a local origin far from it.
    #[test]
    fn the_reference_walks_the_gpus_tree() {
        let hard = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/hard");
        let far = |case: &str| {
            hard.join(format!("{case}.toml"))
                .to_str()
                .unwrap()
                .to_string()
        };
        for name in ["teapot".to_string(), far("far-1e6"), far("closed-mesh")] {
            let scene = Scene::load(&name, &[]).unwrap();
            // As the run plan builds it (plan::build_bvh): over the world
            // scene, less its local origin.
            let origin = crate::scene::camera::local_origin(&scene);
            let bvh = Bvh::build_at(&scene, origin);
            let gpu = crate::gpu::upload::GpuScene::new(&scene, Some(&bvh), 8, 8);
            let local = in_local_frame(&scene).rounded_to_f32();
            let reference = Tracer::new(&local);
            let tree = reference
                .bvh
                .as_deref()
                .expect("a BVH above a few primitives");
            assert!(tree.nodes == gpu.bvh_nodes(), "{name}: the nodes differ");
            let prims: Vec<crate::gpu::layout::GpuBvhPrim> = bytemuck::pod_collect_to_vec(
                &gpu.storage_vec(crate::gpu::layout::binding::BVH_PRIMS),
            );
            let codes: Vec<u32> = prims.iter().map(|p| p.code).collect();
            assert_eq!(tree.prims, codes, "{name}: the leaves differ");
            for width in [4, 8] {
                let wide = bvh.clone().widen(width);
                let gpu = crate::gpu::upload::GpuScene::new(&scene, Some(&wide), 8, 8);
                let reference = Tracer::with_width(&local, width);
                let tree = reference.bvh.as_deref().expect("a BVH");
                assert!(
                    tree.wide == gpu.bvh_wide_nodes(),
                    "{name}: the {width}-wide nodes differ"
                );
                assert!(tree.nodes.is_empty() && gpu.bvh_nodes().is_empty());
            }
        }
    }
}
