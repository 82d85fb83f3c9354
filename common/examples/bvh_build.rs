//! Times the BVH builder on a scene and prints its figures: `cargo run --release -p twinray-common --example bvh_build -- teapot tessellation=160x120 [rounds]`.
//! Build rate (primitives per second, best of the rounds), node count, depth,
//! SAH cost, bytes, and whether every round gave the same tree.
use twinray_common::gpu::layout::Bvh;
use twinray_common::scene::Scene;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let sets: Vec<(String, String)> = a
        .get(2)
        .filter(|s| !s.is_empty())
        .map(|s| {
            let (k, v) = s.split_once('=').expect("KEY=VALUE");
            vec![(k.to_string(), v.to_string())]
        })
        .unwrap_or_default();
    let rounds: usize = a.get(3).map_or(3, |r| r.parse().expect("rounds"));
    let t = std::time::Instant::now();
    let scene = Scene::load(&a[1], &sets).unwrap_or_else(|e| panic!("{e:#}"));
    let load_ms = t.elapsed().as_secs_f64() * 1e3;
    let n = scene.primitive_count();
    let mut best = f64::INFINITY;
    let mut first: Option<Bvh> = None;
    let mut same = true;
    for _ in 0..rounds {
        let b = Bvh::build(&scene);
        best = best.min(b.build_ms);
        match &first {
            None => first = Some(b),
            Some(f) => same &= f.nodes == b.nodes && f.prims == b.prims,
        }
    }
    let b = first.expect("at least one round");
    println!(
        "{} {}: {n} primitives, load {load_ms:.0} ms, build {best:.1} ms ({:.2} M prims/s, {} threads), {} nodes, depth {}, SAH {:.3}, {:.1} MB, same tree every round: {same}",
        a[1],
        a.get(2).map_or("", |s| s.as_str()),
        n as f64 / best / 1e3,
        rayon::current_num_threads(),
        b.node_count(),
        b.depth,
        b.sah_cost(),
        b.bytes() as f64 / 1e6,
    );
}
