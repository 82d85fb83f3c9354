//! The greedy collapse (`--experiment greedy-collapse`) against the optimal
//! one (`--accel bvh4`, `bvh8`) on one scene, at both widths: SAH cost,
//! depth, stack entries and collapse time (best of the rounds), one Markdown
//! row each: `cargo run --release -p twinray-common --example wide_collapse -- teapot tessellation=160x120 [rounds]`.
mod support {
    pub mod args;
}
use std::io::Write as _;
use twinray_common::gpu::layout::Bvh;
use twinray_common::scene::Scene;

/// A collapse of the binary tree to a width.
type Widen = fn(Bvh, u32) -> Bvh;

fn main() {
    let args = support::args::parse();
    let (name, set, rounds) = (&args.scene, &args.set, args.rounds);
    let scene = Scene::load(name, &args.sets).unwrap_or_else(|e| panic!("{e:#}"));
    let binary = Bvh::build(&scene);
    // Written, not println!: a closed pipe (`| head`) ends the output, not the process with a panic.
    let mut out = std::io::stdout().lock();
    let _ = writeln!(
        out,
        "{} {}: {} primitives, {} binary nodes, depth {}, built in {:.0} ms ({} threads)",
        name,
        set,
        scene.primitive_count(),
        binary.node_count(),
        binary.depth,
        binary.build_ms,
        rayon::current_num_threads()
    );
    let _ = writeln!(out, "| width | collapse | SAH cost | nodes | depth | stack entries | ms |\n|---|---|---|---|---|---|---|");
    for width in [4, 8] {
        let collapses: [(&str, Widen); 2] =
            [("greedy", Bvh::widen_greedy), ("optimal", Bvh::widen)];
        for (name, widen) in collapses {
            let (mut best, mut tree) = (f64::INFINITY, None);
            for _ in 0..rounds {
                let t = widen(binary.clone(), width);
                best = best.min(t.build_ms - binary.build_ms);
                tree = Some(t);
            }
            let t = tree.expect("a round or more");
            let _ = writeln!(
                out,
                "| {width} | {name} | {:.4} | {} | {} | {} | {best:.1} |",
                t.sah_cost(),
                t.node_count(),
                t.depth,
                t.stack_entries()
            );
        }
    }
}
