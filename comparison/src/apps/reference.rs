//! `render --api reference`: the f64 CPU reference, in-process, taking the
//! apps' options and refusing those that only a GPU run can honour.

use std::time::Instant;
use twinray_common::cli::{RenderArgs, RenderPath};
use twinray_common::error::bad_input;
use twinray_common::report::{DeviceInfo, FrameTime, RunReport};
use twinray_common::scene::accel::Accel;
use twinray_common::scene::Scene;

/// The f64 CPU reference, in-process. With `--json` it prints a report in the
/// apps' format (api "reference", CPU time as wall time). With `truth`, the
/// f64 truth (`reference::render_truth`, what the hard cases are measured
/// against) instead of the scene's own numerics.
pub fn render_reference(args: &RenderArgs, truth: bool) -> anyhow::Result<()> {
    let start = Instant::now();
    if !args.json && args.out.is_none() {
        return Err(bad_input(
            "render --api reference needs --out FILE.png or --json",
        ));
    }
    // The reference takes the apps' options; one that cannot apply is refused as they refuse it.
    args.compute_workgroup()?;
    let ignored = gpu_only_options(args);
    if !ignored.is_empty() {
        return Err(bad_input(format!(
            "render --api reference does not take {}: the f64 reference renders one frame on the CPU, with no shader or GPU path to apply them to",
            ignored.join(", ")
        )));
    }
    // The truth always traces every primitive with its own numerics: a tree
    // asked for, or rays counted with the scene's numerics, would not be it.
    if truth && (args.accel != Accel::Auto || args.count_rays) {
        return Err(bad_input(
            "render --truth takes neither --accel nor --count-rays: the f64 truth tests every primitive with its own numerics",
        ));
    }
    args.check_outputs()?;
    let scene = Scene::load(&args.scene, &args.overrides()?)?;
    let (w, h) = (args.size.width, args.size.height);
    let t = Instant::now();
    // --accel none: brute force, a reference independent of the BVH code;
    // else through the tree of the width asked for, as the apps trace it.
    let bvh_width = (args.accel != Accel::None).then(|| args.accel.width());
    let img = if truth {
        twinray_common::reference::render_truth(&scene, w, h)
    } else {
        render_with_progress(&scene, w, h, bvh_width)
    };
    let ms = t.elapsed().as_secs_f64() * 1e3;
    if let Some(out) = &args.out {
        img.save_png_for("--out", out)?;
    }
    if args.json {
        let info = DeviceInfo {
            device: format!("CPU, {} threads", rayon_threads()),
            driver: "twinray f64 reference".into(),
            api_version: String::new(),
        };
        let frames = vec![FrameTime {
            warmup: false,
            gpu_ms: None,
            wall_ms: ms,
        }];
        let setup_ms = (t - start).as_secs_f64() * 1e3;
        let mut report = RunReport::builder("reference", info, scene.stats(), "f64".into())
            .size(w, h)
            .frames(frames, setup_ms)
            .nonfinite_pixels(img.nonfinite_pixels())
            .build();
        // Counted in a pass of its own, like the apps' untimed counting frame.
        if args.count_rays {
            report.add_rays(twinray_common::reference::count_rays(&scene, w, h));
        }
        report.print_json()?;
    }
    Ok(())
}

/// The options given that the reference cannot honour (it honours the scene,
/// size, output, JSON, ray counts, `--set` and `--accel`). Destructured field
/// by field, like `super::app_args`, so that a new option is sorted here before it compiles.
fn gpu_only_options(args: &RenderArgs) -> Vec<&'static str> {
    let RenderArgs {
        scene: _,
        size: _,
        headless: _,
        frames,
        settle,
        out: _,
        json: _,
        count_rays: _,
        set: _,
        validate,
        generic,
        specialize,
        accel: _,
        gl_spirv,
        vsync,
        explain,
        path,
        workgroup,
        shared_pad,
        experiment,
        ulp_op,
        experiments,
        dump_shaders,
    } = args;
    [
        (frames.is_some_and(|f| f > 1), "--frames above 1"),
        (settle.is_some(), "--settle"),
        (*validate, "--validate"),
        (*generic, "--generic"),
        (*specialize, "--specialize"),
        (*gl_spirv, "--gl-spirv"),
        (*vsync, "--vsync"),
        (*explain, "--explain"),
        (*path == RenderPath::Compute, "--path compute"),
        (workgroup.is_some(), "--workgroup"),
        (shared_pad.is_some(), "--shared-pad"),
        (!experiment.is_empty(), "--experiment"),
        (ulp_op.is_some(), "--ulp-op"),
        (*experiments, "--experiments"),
        (dump_shaders.is_some(), "--dump-shaders"),
    ]
    .into_iter()
    .filter_map(|(given, name)| given.then_some(name))
    .collect()
}

/// The reference render, with a progress bar on stderr once it has run for a
/// second (short renders stay quiet; indicatif draws nothing when stderr is not
/// a terminal, so logs and pipes get no bar).
fn render_with_progress(
    scene: &twinray_common::scene::Scene,
    w: u32,
    h: u32,
    bvh_width: Option<u32>,
) -> twinray_common::reference::image_io::FloatImage {
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    let rows = AtomicUsize::new(0);
    let finished = AtomicBool::new(false);
    std::thread::scope(|s| {
        s.spawn(|| {
            let started = Instant::now();
            let mut bar: Option<indicatif::ProgressBar> = None;
            while !finished.load(Ordering::Relaxed) {
                std::thread::sleep(std::time::Duration::from_millis(100));
                if bar.is_none() && started.elapsed().as_secs_f64() >= 1.0 {
                    let b = indicatif::ProgressBar::with_draw_target(
                        Some(h as u64),
                        indicatif::ProgressDrawTarget::stderr(),
                    );
                    if let Ok(style) = indicatif::ProgressStyle::with_template(
                        "reference {bar:40} {pos}/{len} rows, {elapsed} elapsed, about {eta} left",
                    ) {
                        b.set_style(style);
                    }
                    bar = Some(b);
                }
                if let Some(b) = &bar {
                    b.set_position(rows.load(Ordering::Relaxed) as u64);
                }
            }
            if let Some(b) = bar {
                b.finish_and_clear();
            }
        });
        let img = twinray_common::reference::render_counting(
            scene,
            w,
            h,
            &scene.numerics,
            bvh_width,
            &rows,
        );
        finished.store(true, Ordering::Relaxed);
        img
    })
}

fn rayon_threads() -> usize {
    rayon::current_num_threads()
}
