//! The comparison's image check: each built-in scene rendered once by both
//! apps and the f64 reference (PNGs under images/), and, with the compute path
//! measured, each API's compute image against its fragment image.

use crate::apps::{api_name, overrides};
use crate::apps::{run_json, Api};
use crate::compare::runs::{Agreement, Plan, EXPERIMENTS};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use twinray_common::cli::{RenderArgs, RenderPath, Size, Workgroup};
use twinray_common::reference::image_io::load_png;
use twinray_common::reference::metrics::{self, Metrics};
use twinray_common::scene::accel::Accel;

/// Renders each built-in scene once with both apps and the reference, keeps the
/// PNGs under images/, and measures how far apart they are.
pub fn agreement(
    out: &Path,
    plan: &Plan,
    paths: &[RenderPath],
    workgroup: Option<Workgroup>,
    stop: &AtomicBool,
) -> Vec<Agreement> {
    let dir = out.join("images");
    let mut rows = Vec::new();
    if std::fs::create_dir_all(&dir).is_err() {
        return rows;
    }
    let size = if plan.preset == "quick" {
        Size {
            width: 160,
            height: 120,
        }
    } else {
        Size {
            width: 400,
            height: 300,
        }
    };
    eprintln!(
        "twinray compare: checking image agreement at {size} (Vulkan, OpenGL, f64 reference)"
    );
    for scene in EXPERIMENTS {
        if stop.load(Ordering::SeqCst) {
            break;
        }
        let set = if scene == "spherelist" {
            vec!["extra_spheres=100".to_string()]
        } else {
            vec![]
        };
        let result = apis_and_reference(&dir, scene, size, &set).map_err(|e| format!("{e:#}"));
        if stop.load(Ordering::SeqCst) && result.is_err() {
            // Stopped by the signal, not failed: not a row of the table.
            break;
        }
        if let Ok(m) = &result {
            let label = |w: &str| format!("{scene} {w}");
            crate::diff::print_table(&[
                (&label("vulkan vs opengl"), m[0]),
                (&label("vulkan vs reference"), m[1]),
                (&label("opengl vs reference"), m[2]),
            ]);
        } else if let Err(e) = &result {
            eprintln!("  {scene}: agreement check failed: {e}");
        }
        // The compute path against the fragment path, API by API: the same tracer
        // through another entry point must give the same image.
        let compute = paths.contains(&RenderPath::Compute) && result.is_ok();
        let paths = compute
            .then(|| {
                compute_and_fragment(&dir, scene, size, &set, workgroup)
                    .map_err(|e| format!("{e:#}"))
            })
            // A comparison the signal stopped is left out, not failed.
            .filter(|p| p.is_ok() || !stop.load(Ordering::SeqCst));
        if let Some(Ok(m)) = &paths {
            let label = |w: &str| format!("{scene} {w}");
            crate::diff::print_table(&[
                (&label("vulkan compute vs fragment"), m[0]),
                (&label("opengl compute vs fragment"), m[1]),
            ]);
        } else if let Some(Err(e)) = &paths {
            eprintln!("  {scene}: compute agreement check failed: {e}");
        }
        rows.push(Agreement {
            scene,
            size,
            result,
            paths,
        });
    }
    rows
}

/// One frame of `scene` saved to `png`, with the JSON report.
fn one_frame(scene: &str, size: Size, set: &[String], png: &Path) -> RenderArgs {
    RenderArgs {
        frames: Some(1),
        out: Some(png.to_path_buf()),
        json: true,
        set: set.to_vec(),
        ..RenderArgs::headless(scene, size)
    }
}

/// Vulkan vs OpenGL, Vulkan vs reference and OpenGL vs reference on the
/// fragment path, each with the NaN/Inf pixels of the images it compares.
fn apis_and_reference(
    dir: &Path,
    scene: &'static str,
    size: Size,
    set: &[String],
) -> anyhow::Result<[Metrics; 3]> {
    let mut imgs = Vec::new();
    let mut nan = Vec::new();
    for api in [Api::Vulkan, Api::Opengl] {
        let png = dir.join(format!("{scene}-{}.png", api_name(api)));
        let ra = RenderArgs {
            accel: Accel::None,
            ..one_frame(scene, size, set, &png)
        };
        let r = run_json(api, &ra)?;
        nan.push(r.nonfinite_pixels);
        imgs.push(load_png(&png)?);
    }
    let sc = twinray_common::scene::Scene::load(scene, &overrides(set))?;
    let reference = twinray_common::reference::render(&sc, size.width, size.height);
    let ref_png = dir.join(format!("{scene}-reference.png"));
    reference.save_png(&ref_png)?;
    let reference = reference.to_rgb8();
    let mut vk_gl = metrics::compare(&imgs[0], &imgs[1])?;
    vk_gl.nan_pixels = nan[0] + nan[1];
    let mut vk_ref = metrics::compare(&imgs[0], &reference)?;
    vk_ref.nan_pixels = nan[0];
    let mut gl_ref = metrics::compare(&imgs[1], &reference)?;
    gl_ref.nan_pixels = nan[1];
    Ok([vk_gl, vk_ref, gl_ref])
}

/// Each API's compute image against its own fragment image (which
/// `apis_and_reference` left in `dir`).
fn compute_and_fragment(
    dir: &Path,
    scene: &'static str,
    size: Size,
    set: &[String],
    workgroup: Option<Workgroup>,
) -> anyhow::Result<[Metrics; 2]> {
    let mut m = Vec::new();
    for api in [Api::Vulkan, Api::Opengl] {
        let frag = dir.join(format!("{scene}-{}.png", api_name(api)));
        let png = dir.join(format!("{scene}-{}-compute.png", api_name(api)));
        let ra = RenderArgs {
            path: RenderPath::Compute,
            workgroup,
            ..one_frame(scene, size, set, &png)
        };
        let r = run_json(api, &ra)?;
        let mut metrics = metrics::compare(&load_png(&png)?, &load_png(&frag)?)?;
        metrics.nan_pixels = r.nonfinite_pixels;
        m.push(metrics);
    }
    Ok([m[0], m[1]])
}
