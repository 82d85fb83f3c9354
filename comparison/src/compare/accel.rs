//! The comparison's runs of "model only what a scene needs": each scene with
//! the all-features shader, its own variant, specialization constants and a
//! BVH; the sphere-list crossover behind `--accel auto`; and the BVH scaled up.

use crate::apps::overrides;
use crate::apps::{run_json, Api};
use crate::compare::runs::{AccelRun, BvhStats, Plan, ACCEL_CONFIGS};
use std::sync::atomic::{AtomicBool, Ordering};
use twinray_common::cli::{RenderArgs, RenderPath, Size};
use twinray_common::scene::accel::Accel;

/// One scene setting and the ACCEL_CONFIGS it runs in.
struct Case {
    scene: &'static str,
    size: Size,
    set: Vec<String>,
    configs: Vec<&'static str>,
}

/// Each scene with the all-features brute-force shader, its own variant, and
/// its variant with a BVH; then the sphere list scaled up with the BVH alone.
pub fn acceleration(plan: &Plan, stop: &AtomicBool) -> Vec<AccelRun> {
    let quick = plan.preset == "quick";
    let cases = cases(quick);
    eprintln!(
        "twinray compare: measuring shader variants and the BVH ({} runs)",
        cases.iter().map(|c| c.configs.len() * 2).sum::<usize>()
    );
    let mut runs = Vec::new();
    for Case {
        scene,
        size,
        set,
        configs,
    } in cases
    {
        for config in configs {
            let bvh = config.ends_with("BVH");
            let stats = bvh.then(|| {
                twinray_common::scene::Scene::load(scene, &overrides(&set))
                    .ok()
                    .map(|sc| {
                        let b = twinray_common::gpu::layout::Bvh::build(&sc);
                        BvhStats {
                            nodes: b.nodes.len(),
                            bytes: b.bytes(),
                            build_ms: b.build_ms,
                        }
                    })
            });
            for api in [Api::Vulkan, Api::Opengl] {
                if stop.load(Ordering::SeqCst) {
                    return runs;
                }
                let ra = RenderArgs {
                    frames: Some(if quick { 4 } else { 12 }),
                    settle: (!quick).then_some(1.0),
                    // The full preset's configurations run as compute shaders:
                    // the same tracer, 25-30x cheaper on a GPU than a fragment
                    // frame, so the brute-force teapot at 1000² costs
                    // milliseconds instead of seconds a frame.
                    path: if quick {
                        RenderPath::Fragment
                    } else {
                        RenderPath::Compute
                    },
                    json: true,
                    set: set.clone(),
                    generic: config.starts_with("generic"),
                    specialize: config.starts_with("specialized"),
                    accel: if bvh { Accel::Bvh } else { Accel::None },
                    ..RenderArgs::headless(scene, size)
                };
                let result = run_json(api, &ra).map_err(|e| format!("{e:#}"));
                if stop.load(Ordering::SeqCst) && result.is_err() {
                    // Stopped by the signal, not failed: not a run of the table.
                    return runs;
                }
                runs.push(AccelRun {
                    scene,
                    size,
                    set: set.clone(),
                    config,
                    api,
                    result,
                    bvh: stats.flatten(),
                });
            }
        }
    }
    runs
}

fn square(side: u32) -> Size {
    Size {
        width: side,
        height: side,
    }
}

/// The cases in run order: the three scenes in every configuration, the
/// sphere-list crossover, the sphere list scaled up, the teapot made finer.
fn cases(quick: bool) -> Vec<Case> {
    let big = square(if quick { 100 } else { 1000 });
    let sl = square(if quick { 100 } else { 300 });
    let teapot = if quick { square(40) } else { big };
    let case = |scene, size, set: Vec<String>, configs: &[&'static str]| Case {
        scene,
        size,
        set,
        configs: configs.to_vec(),
    };
    let mut cases = vec![
        case("teapot", teapot, vec![], &ACCEL_CONFIGS),
        case("box", big, vec![], &ACCEL_CONFIGS),
        case(
            "spherelist",
            sl,
            vec![format!(
                "extra_spheres={}",
                if quick { 1000 } else { 10000 }
            )],
            &ACCEL_CONFIGS,
        ),
    ];
    // Where the BVH starts to pay: the crossover behind AUTO_BVH_MIN_PRIMITIVES.
    let crossover: &[u32] = if quick {
        &[1, 50, 200]
    } else {
        &[1, 10, 25, 50, 100, 200, 500]
    };
    for &n in crossover {
        cases.push(case(
            "spherelist",
            sl,
            vec![format!("extra_spheres={n}")],
            &["variant, brute force", "variant, BVH"],
        ));
    }
    let scaling: &[u32] = if quick {
        &[10_000]
    } else {
        &[1_000, 10_000, 100_000]
    };
    for &n in scaling {
        cases.push(case(
            "spherelist",
            sl,
            vec![format!("extra_spheres={n}")],
            &["variant, BVH"],
        ));
    }
    // The teapot from 19.2k to 1.2M triangles: the same generator, finer.
    let detail: &[&str] = if quick {
        &["40x30"]
    } else {
        &["40x30", "80x60", "160x120"]
    };
    for t in detail {
        cases.push(case(
            "teapot",
            teapot,
            vec![format!("tessellation={t}")],
            &["variant, BVH"],
        ));
    }
    cases
}
