//! Builds one scene's BVH with twinray's binned-SAH builder and with obvhs's
//! PLOC builder (at three of its presets), flattens obvhs's tree into twinray's layout
//! and prints, for each, the build rate and the SAH cost that
//! `Bvh::sah_cost` gives: the same formula and costs for both trees, so the
//! numbers compare. Usage (README.md):
//! `cargo run --release -- SCENE [KEY=VALUE] [ROUNDS]`.
use glam::Vec3A;
use obvhs::aabb::Aabb;
use obvhs::bvh2::builder::build_bvh2;
use obvhs::bvh2::Bvh2;
use obvhs::BvhBuildParams;
use rayon::prelude::*;
use std::time::{Duration, Instant};
use twinray_common::gpu::layout::{child_ref, Bvh, GpuBvhNode, PRIM_SPHERE_BIT};
use twinray_common::scene::accel::MAX_LEAF;
use twinray_common::scene::Scene;

fn main() -> anyhow::Result<()> {
    let a: Vec<String> = std::env::args().collect();
    let Some(name) = a.get(1) else {
        anyhow::bail!("usage: bvh-builders SCENE [KEY=VALUE] [ROUNDS]");
    };
    let sets: Vec<(String, String)> = match a.get(2).filter(|s| !s.is_empty()) {
        Some(s) => {
            let (k, v) = s
                .split_once('=')
                .ok_or_else(|| anyhow::anyhow!("the second argument '{s}' is not KEY=VALUE"))?;
            vec![(k.to_string(), v.to_string())]
        }
        None => Vec::new(),
    };
    let rounds: usize = match a.get(3) {
        Some(r) => r
            .parse()
            .map_err(|_| anyhow::anyhow!("ROUNDS '{r}' is not a count"))?,
        None => 3,
    };
    let scene = Scene::load(name, &sets)?;
    let n = scene.primitive_count();
    println!(
        "{name} {}: {n} primitives ({} spheres), {} threads",
        a.get(2).map_or("", |s| s.as_str()),
        scene.spheres.len(),
        rayon::current_num_threads()
    );
    println!("| builder | best build ms | M tris/s | interior nodes | depth | SAH cost |");
    println!("|---|---|---|---|---|---|");

    let mut ours: Option<Bvh> = None;
    let mut best = f64::INFINITY;
    for _ in 0..rounds {
        let b = Bvh::build(&scene);
        best = best.min(b.build_ms);
        ours = Some(b);
    }
    let ours = ours.expect("at least one round");
    row("twinray binned SAH", best, n, &ours);

    let ntri = scene.triangles.len();
    for (preset, mut params) in [
        ("obvhs fast_build", BvhBuildParams::fast_build()),
        ("obvhs medium_build", BvhBuildParams::medium_build()),
        ("obvhs slow_build", BvhBuildParams::slow_build()),
    ] {
        // twinray's leaf limit and cost ratio, so the trees answer the same question.
        params.max_prims_per_leaf = MAX_LEAF as u32;
        params.collapse_traversal_cost = 1.0;
        params.pre_split = false;
        let mut best = f64::INFINITY;
        let mut tree = None;
        for _ in 0..rounds {
            let t = Instant::now();
            let boxes = primitive_boxes(&scene);
            let mut core = Duration::ZERO;
            let b = build_bvh2(&boxes, params, &mut core);
            best = best.min(t.elapsed().as_secs_f64() * 1e3);
            tree = Some(b);
        }
        let flat = flatten(&tree.expect("at least one round"), ntri)?;
        row(preset, best, n, &flat);
    }
    Ok(())
}

/// Every primitive's box in f32, as the GPU sees the scene: triangles first,
/// then spheres (`flatten` maps the indices back).
fn primitive_boxes(scene: &Scene) -> Vec<Aabb> {
    let tri = scene.triangles.par_iter().map(|t| {
        let p = t.p.map(|v| Vec3A::from(v.as_vec3()));
        Aabb::new(p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]))
    });
    let sph = scene.spheres.par_iter().map(|s| {
        let c = Vec3A::from(s.center.as_vec3());
        let r = Vec3A::splat(s.radius as f32);
        Aabb::new(c - r, c + r)
    });
    tri.chain(sph).collect()
}

fn row(builder: &str, ms: f64, n: usize, b: &Bvh) {
    println!(
        "| {builder} | {ms:.1} | {:.2} | {} | {} | {:.3} |",
        n as f64 / ms / 1e3,
        b.node_count(),
        b.depth,
        b.sah_cost()
    );
}

/// obvhs's tree in twinray's layout: interior nodes hold both children's
/// boxes, leaves live in their parent's child reference, primitives in leaf order.
fn flatten(b: &Bvh2, ntri: usize) -> anyhow::Result<Bvh> {
    let mut out = Bvh {
        nodes: Vec::new(),
        prims: Vec::new(),
        build_ms: 0.0,
        depth: 0,
    };
    let root = &b.nodes[0];
    anyhow::ensure!(root.prim_count == 0, "obvhs built a single leaf");
    out.nodes.push(GpuBvhNode::default());
    // (obvhs node, twinray node slot, depth of that slot)
    let mut todo = vec![(0usize, 0usize, 1u32)];
    while let Some((i, slot, depth)) = todo.pop() {
        let first = b.nodes[i].first_index as usize;
        let mut refs = [0u32; 2];
        for (side, c) in [first, first + 1].into_iter().enumerate() {
            let node = &b.nodes[c];
            let (lo, hi) = (node.aabb.min, node.aabb.max);
            let bounds = ([lo.x, lo.y, lo.z], [hi.x, hi.y, hi.z]);
            let n = &mut out.nodes[slot];
            if side == 0 {
                (n.left_min, n.left_max) = bounds;
            } else {
                (n.right_min, n.right_max) = bounds;
            }
            if node.prim_count > 0 {
                let count = node.prim_count as usize;
                anyhow::ensure!(count <= MAX_LEAF, "a leaf of {count} primitives");
                let start = out.prims.len() as u32;
                let at = node.first_index as usize;
                out.prims
                    .extend(b.primitive_indices[at..at + count].iter().map(|&i| {
                        let i = i as usize;
                        if i < ntri {
                            i as u32
                        } else {
                            (i - ntri) as u32 | PRIM_SPHERE_BIT
                        }
                    }));
                refs[side] = child_ref::leaf(start, count as u32);
                out.depth = out.depth.max(depth + 1);
            } else {
                let child_slot = out.nodes.len();
                out.nodes.push(GpuBvhNode::default());
                refs[side] = child_slot as u32;
                todo.push((c, child_slot, depth + 1));
            }
        }
        out.nodes[slot].left = refs[0];
        out.nodes[slot].right = refs[1];
    }
    Ok(out)
}
