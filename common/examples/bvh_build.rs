//! Times the BVH builder on a scene and prints its figures, and where the
//! memory of a run goes: `cargo run --release -p twinray-common --example bvh_build -- teapot tessellation=160x120 [rounds]`.
//! Build rate (primitives per second, best of the rounds), node count, depth,
//! SAH cost, bytes, and whether every round gave the same tree; then the
//! resident memory each step of a run's preparation peaks at and keeps
//! (loading the scene, building the BVH, collapsing it to the 4-wide tree the
//! apps trace, making the GPU's bytes a chunk at a time as an upload does).
mod support {
    pub mod args;
}
use std::io::Write as _;
use twinray_common::gpu::layout::{binding, Bvh};
use twinray_common::gpu::upload::{GpuScene, UPLOAD_CHUNK_BYTES};
use twinray_common::plan::build_bvh;
use twinray_common::scene::Scene;

fn main() {
    let args = support::args::parse();
    let (name, set, rounds) = (&args.scene, &args.set, args.rounds);
    let mut memory = Memory::new();
    let t = std::time::Instant::now();
    let scene = Scene::load(name, &args.sets).unwrap_or_else(|e| panic!("{e:#}"));
    let load_ms = t.elapsed().as_secs_f64() * 1e3;
    memory.step("Scene::load");
    let n = scene.primitive_count();
    let mut best = f64::INFINITY;
    let mut first: Option<Bvh> = None;
    let mut same = true;
    let cpu_before = cpu_seconds();
    for _ in 0..rounds {
        let b = Bvh::build(&scene);
        best = best.min(b.build_ms);
        match &first {
            None => first = Some(b),
            Some(f) => same &= f.nodes == b.nodes && f.prims == b.prims,
        }
    }
    let cpu_ms = (cpu_seconds() - cpu_before) * 1e3 / rounds as f64;
    let b = first.expect("at least one round");
    memory.step("Bvh::build (the tree kept, rounds-1 dropped)");
    // Written, not println!: a closed pipe (`| head`) ends the output, not the process with a panic.
    let mut out = std::io::stdout().lock();
    let _ = writeln!(
        out,
        "{} {}: {n} primitives, load {load_ms:.0} ms, build {best:.1} ms ({:.2} M prims/s, {} threads; {cpu_ms:.0} ms of CPU a build), {} nodes, depth {}, SAH {:.3}, {:.1} MB, same tree every round: {same}",
        name,
        set,
        n as f64 / best / 1e3,
        rayon::current_num_threads(),
        b.node_count(),
        b.depth,
        b.sah_cost(),
        b.bytes() as f64 / 1e6,
    );
    drop(b);
    memory.step("the bench's tree dropped");
    let binary = build_bvh(&scene);
    memory.step("plan::build_bvh (the run's binary tree)");
    // The run's tree is this one collapsed to 4 children a node (`--accel auto`).
    let built_ms = binary.build_ms;
    let tree = binary.widen(4);
    let _ = writeln!(
        out,
        "collapsed to 4-wide in {:.1} ms ({} threads): {} nodes, depth {}, stack {}",
        tree.build_ms - built_ms,
        rayon::current_num_threads(),
        tree.node_count(),
        tree.depth,
        tree.stack_entries()
    );
    memory.step("Bvh::widen(4) (the binary tree replaced)");
    // What an upload does, less the driver: every storage buffer converted
    // a chunk at a time into one reused chunk of memory.
    let t = std::time::Instant::now();
    let gpu = GpuScene::new(&scene, Some(&tree), 64, 48);
    let chunk_bytes = UPLOAD_CHUNK_BYTES.min(gpu.largest_storage().1);
    let mut chunk = vec![0u32; chunk_bytes.div_ceil(4)];
    let chunk: &mut [u8] = bytemuck::cast_slice_mut(&mut chunk);
    let mut bytes = 0;
    for b in binding::STORAGE {
        for c in gpu.chunks(b, chunk_bytes) {
            gpu.write_storage(b, c.start, &mut chunk[..c.len()]);
            bytes += c.len();
        }
    }
    let upload_ms = t.elapsed().as_secs_f64() * 1e3;
    memory.step(&format!(
        "GpuScene's {:.0} MB made in chunks ({upload_ms:.0} ms)",
        bytes as f64 / 1e6
    ));
    memory.print(&mut out, n);
}

/// Resident memory between steps, from /proc/self/status: VmRSS now and
/// VmHWM, the peak, which writing 5 to /proc/self/clear_refs resets so that
/// each step's own peak shows.
struct Memory {
    rows: Vec<(String, f64, f64)>,
}

impl Memory {
    fn new() -> Memory {
        reset_peak();
        Memory { rows: Vec::new() }
    }

    fn step(&mut self, what: &str) {
        let (now, peak) = rss_kb();
        self.rows.push((what.to_string(), peak, now));
        reset_peak();
    }

    fn print(&self, out: &mut impl std::io::Write, n: usize) {
        let _ = writeln!(
            out,
            "resident memory (MB, and bytes per primitive), step by step:"
        );
        let mut before = 0.0;
        for (what, peak, now) in &self.rows {
            let b = |kb: f64| kb * 1024.0 / n.max(1) as f64;
            let _ = writeln!(
                out,
                "  {what}: peak {:.0} MB ({:.0} B), after {:.0} MB ({:.0} B, {:+.0} B)",
                peak / 1024.0,
                b(*peak),
                now / 1024.0,
                b(*now),
                b(now - before),
            );
            before = *now;
        }
    }
}

fn reset_peak() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

fn rss_kb() -> (f64, f64) {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let field = |name: &str| {
        status
            .lines()
            .find_map(|l| l.strip_prefix(name))
            .and_then(|v| v.split_whitespace().next())
            .and_then(|v| v.parse().ok())
            .unwrap_or(0.0)
    };
    (field("VmRSS:"), field("VmHWM:"))
}

/// User and system CPU time of this process so far, all threads (Linux
/// /proc/self/stat, in clock ticks of 10 ms): on a shared machine the wall
/// time also counts the time other processes held the cores.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the command name (which may hold spaces) in parentheses.
    let rest = stat.rsplit_once(')').map_or("", |r| r.1);
    let f: Vec<f64> = rest
        .split_whitespace()
        .map(|x| x.parse().unwrap_or(0.0))
        .collect();
    // utime and stime are fields 14 and 15 of the line, 12 and 13 after the name.
    (f.get(11).copied().unwrap_or(0.0) + f.get(12).copied().unwrap_or(0.0)) / 100.0
}
