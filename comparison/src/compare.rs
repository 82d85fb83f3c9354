//! `twinray compare`: the study's three experiments (teapot and box resolution
//! sweeps, the sphere-list count sweep) with both apps, each point in fresh
//! processes with the API order alternating, then results.csv, report.md and plots.

use crate::apps::{run_json, Api};
use anyhow::Context;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use twinray_common::cli::{parse_size, parse_workgroup, RenderArgs, RenderPath, Size, Workgroup};
use twinray_common::report::RunReport;
use twinray_common::scene::accel::Accel;
use twinray_common::value_name::ValueName;

#[derive(clap::Args, Debug, Clone)]
pub struct CompareArgs {
    /// Small sizes, counts and frame numbers: minutes on software drivers.
    /// Without --quick or --full the preset follows the device: quick on a software driver.
    #[arg(long, conflicts_with = "full")]
    pub quick: bool,
    /// The study's full sweeps even on a software driver (hours there).
    #[arg(long)]
    pub full: bool,
    /// Output folder.
    #[arg(long, default_value = "comparison-out")]
    pub out: PathBuf,
    /// Frames per point (the study: 60; statistics over the last 30).
    #[arg(long)]
    pub frames: Option<u32>,
    /// Fewer frames for slow points so that one app spends at most about this long on one point.
    #[arg(long)]
    pub seconds_per_point: Option<f64>,
    /// Also run OpenGL on naga's SPIR-V (GL_ARB_gl_spirv): the same binary as Vulkan,
    /// which separates the API from the shader-compiler path.
    #[arg(long)]
    pub gl_spirv: bool,
    /// Only these experiments (teapot, box, spherelist, accel), comma-separated.
    #[arg(long, value_delimiter = ',')]
    pub only: Vec<String>,
    /// The tracer's entry points to measure, comma-separated: every point runs
    /// both APIs on each of them.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [RenderPath::Fragment, RenderPath::Compute])]
    pub paths: Vec<RenderPath>,
    /// The compute path's workgroup WxH (default: the apps' default).
    #[arg(long, value_name = "WxH", value_parser = parse_workgroup)]
    pub workgroup: Option<Workgroup>,
}

#[derive(Debug, Clone)]
pub struct Point {
    pub experiment: &'static str,
    pub param_name: &'static str,
    pub param_value: String,
    pub scene: &'static str,
    pub size: Size,
    pub set: Vec<String>,
    /// Work relative to the sweep's first point (pixels or primitives), to predict frame time.
    pub work: f64,
}

pub struct Plan {
    pub points: Vec<Point>,
    pub frames: u32,
    pub seconds_per_point: f64,
    pub preset: &'static str,
}

pub const EXPERIMENTS: [&str; 3] = ["teapot", "box", "spherelist"];
/// What `--only` can pick: the three sweeps, and "accel", the runs of "model
/// only what a scene needs" (variants, specialization constants, BVH).
pub const ONLY_CHOICES: [&str; 4] = ["teapot", "box", "spherelist", "accel"];

pub fn plan(args: &CompareArgs) -> anyhow::Result<Plan> {
    for e in &args.only {
        if !ONLY_CHOICES.contains(&e.as_str()) {
            return Err(twinray_common::error::bad_input(format!(
                "--only '{e}' is not an experiment (teapot, box, spherelist, accel)"
            )));
        }
    }
    let (res_teapot, res_box, counts, sl_size, frames, secs, preset): (
        Vec<u32>,
        Vec<u32>,
        Vec<u32>,
        u32,
        u32,
        f64,
        _,
    ) = if args.quick {
        (
            vec![40, 80],
            vec![100, 200, 300],
            vec![1, 10, 100, 1000],
            100,
            8,
            8.0,
            "quick",
        )
    } else {
        (
            (1..=10).map(|i| i * 100).collect(),
            (1..=10).map(|i| i * 100).collect(),
            vec![1, 10, 50, 100, 500, 1000, 2500, 5000, 10000],
            300,
            60,
            30.0,
            "full",
        )
    };
    let mut points = Vec::new();
    let wanted = |e: &str| args.only.is_empty() || args.only.iter().any(|o| o == e);
    for (exp, sizes) in [("teapot", &res_teapot), ("box", &res_box)] {
        if !wanted(exp) {
            continue;
        }
        for &r in sizes {
            points.push(Point {
                experiment: exp,
                param_name: "resolution",
                param_value: format!("{r}x{r}"),
                scene: exp,
                size: Size {
                    width: r,
                    height: r,
                },
                set: vec![],
                work: (r as f64 / sizes[0] as f64).powi(2),
            });
        }
    }
    if wanted("spherelist") {
        for &n in &counts {
            points.push(Point {
                experiment: "spherelist",
                param_name: "extra_spheres",
                param_value: n.to_string(),
                scene: "spherelist",
                size: parse_size(&format!("{sl_size}x{sl_size}")).expect("valid size"),
                set: vec![format!("extra_spheres={n}")],
                work: (n as f64 + 8.0) / (counts[0] as f64 + 8.0),
            });
        }
    }
    Ok(Plan {
        points,
        frames: args.frames.unwrap_or(frames),
        seconds_per_point: args.seconds_per_point.unwrap_or(secs),
        preset,
    })
}

/// One API at one point: its report, or why it failed.
#[derive(Debug, Clone)]
pub struct Outcome {
    pub point: Point,
    pub api: Api,
    pub path: RenderPath,
    pub result: Result<RunReport, String>,
}

pub fn api_name(api: Api) -> &'static str {
    match api {
        Api::Vulkan => "vulkan",
        Api::Opengl => "opengl",
        Api::OpenglSpirv => "opengl-spirv",
        Api::Reference => "reference",
    }
}

/// Software rasterisers (Mesa's lavapipe/llvmpipe, SwiftShader) get the quick preset.
fn is_software(device: &str) -> bool {
    let d = device.to_lowercase();
    ["llvmpipe", "lavapipe", "softpipe", "swiftshader"]
        .iter()
        .any(|s| d.contains(s))
}

pub fn run(args: &CompareArgs) -> anyhow::Result<()> {
    // Before the device probe and every render: a bad --out must cost nothing.
    twinray_common::reference::image_io::prepare_output_dir("--out", &args.out)?;
    let mut args = args.clone();
    if !args.quick && !args.full {
        let probe = RenderArgs {
            frames: Some(1),
            out: None,
            json: true,
            set: vec![],
            ..RenderArgs::headless(
                "spherelist",
                Size {
                    width: 8,
                    height: 8,
                },
            )
        };
        let r = run_json(Api::Vulkan, &probe).context("probing the Vulkan device")?;
        if is_software(&r.device) {
            eprintln!("twinray compare: '{}' is a software driver: running the quick preset (pass --full for the study's full sweeps)", r.device);
            args.quick = true;
        } else {
            eprintln!(
                "twinray compare: '{}' is a GPU: running the study's full sweeps",
                r.device
            );
        }
    }
    let args = &args;
    let plan = plan(args)?;
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst))
            .context("installing the Ctrl-C handler")?;
    }
    let mut paths = args.paths.clone();
    paths.dedup();
    if paths.is_empty() {
        return Err(twinray_common::error::bad_input(
            "--paths names no path; use fragment, compute or both",
        ));
    }
    let apis = if args.gl_spirv { 3 } else { 2 };
    let runs = apis * paths.len();
    eprintln!(
        "twinray compare: {} preset, {} points x {apis} APIs x {} paths ({}), up to {} frames each (about {} s per app per point at most) -> {}",
        plan.preset,
        plan.points.len(),
        paths.len(),
        paths.iter().map(|p| p.name()).collect::<Vec<_>>().join(", "),
        plan.frames,
        plan.seconds_per_point,
        args.out.display()
    );
    let bar = indicatif::ProgressBar::new((plan.points.len() * runs) as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{bar:40} {pos}/{len} [{elapsed_precise} elapsed, ETA {eta}] {msg}",
        )
        .expect("valid template"),
    );
    let mut outcomes: Vec<Outcome> = Vec::new();
    let mut interrupted = false;
    // Frame-time prediction per experiment and path (on a GPU the paths differ by
    // up to 30x): (work, wall ms) of the last finished point.
    let mut last: std::collections::HashMap<(&str, RenderPath), (f64, f64)> = Default::default();
    'points: for (i, point) in plan.points.iter().enumerate() {
        let mut apis = vec![Api::Vulkan, Api::Opengl];
        if args.gl_spirv {
            apis.push(Api::OpenglSpirv);
        }
        let mut order: Vec<(RenderPath, Api)> = paths
            .iter()
            .flat_map(|&p| apis.iter().map(move |&a| (p, a)))
            .collect();
        if i % 2 == 1 {
            order.reverse();
        }
        for (path, api) in order {
            let frames = match last.get(&(point.experiment, path)) {
                Some(&(work, ms)) if ms > 0.0 => {
                    let predicted = ms * point.work / work;
                    ((plan.seconds_per_point * 1e3 / predicted).floor() as u32)
                        .clamp(plan.frames.min(4), plan.frames)
                }
                _ => plan.frames,
            };
            if stop.load(Ordering::SeqCst) {
                interrupted = true;
                break 'points;
            }
            bar.set_message(format!(
                "{} {} {} {path}",
                point.experiment,
                point.param_value,
                api_name(api)
            ));
            let ra = RenderArgs {
                frames: Some(frames),
                out: None,
                json: true,
                set: point.set.clone(),
                // The study's tracer tests every primitive: so do the sweeps.
                accel: Accel::None,
                path,
                workgroup: if path == RenderPath::Compute {
                    args.workgroup
                } else {
                    None
                },
                ..RenderArgs::headless(point.scene, point.size)
            };
            let result = run_json(api, &ra).map_err(|e| format!("{e:#}"));
            if stop.load(Ordering::SeqCst) {
                // The child got the Ctrl-C too: this point did not finish.
                interrupted = true;
                break 'points;
            }
            if let Ok(r) = &result {
                if let Some(w) = r.wall_ms {
                    last.insert((point.experiment, path), (point.work, w.median));
                }
            } else if let Err(e) = &result {
                bar.println(format!(
                    "  {} {} {} {path}: FAILED: {e}",
                    point.experiment,
                    point.param_value,
                    api_name(api)
                ));
            }
            outcomes.push(Outcome {
                point: point.clone(),
                api,
                path,
                result,
            });
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    let accel = if interrupted || !(args.only.is_empty() || args.only.iter().any(|o| o == "accel"))
    {
        Vec::new()
    } else {
        acceleration(&plan, &stop)
    };
    let agreement = if interrupted || stop.load(Ordering::SeqCst) {
        Vec::new()
    } else {
        agreement(&args.out, &plan, &paths, args.workgroup, &stop)
    };
    let shader_rows = if interrupted || stop.load(Ordering::SeqCst) {
        Vec::new()
    } else {
        crate::shaders::collect(&args.out, &paths, &stop)
    };
    crate::report::write_all(&args.out, &plan, &outcomes, &accel, &agreement, interrupted)?;
    crate::shaders::append_to_report(&args.out.join("report.md"), &shader_rows)?;
    eprintln!(
        "twinray compare: {} of {} runs done{}; report: {}",
        outcomes.iter().filter(|o| o.result.is_ok()).count(),
        plan.points.len() * runs,
        if interrupted {
            " (interrupted: the finished points are kept)"
        } else {
            ""
        },
        args.out.join("report.md").display()
    );
    if interrupted {
        std::process::exit(130);
    }
    Ok(())
}

/// Image agreement of one scene: both APIs against each other and the f64 reference.
#[derive(Debug, Clone)]
pub struct Agreement {
    pub scene: &'static str,
    pub size: Size,
    pub result: Result<[twinray_common::reference::metrics::Metrics; 3], String>,
    /// With the compute path measured: each API's compute image against its fragment image.
    pub paths: Option<Result<[twinray_common::reference::metrics::Metrics; 2], String>>,
}

/// Renders each built-in scene once with both apps and the reference, keeps the
/// PNGs under images/, and measures how far apart they are.
pub fn agreement(
    out: &std::path::Path,
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
        let result = (|| -> anyhow::Result<[twinray_common::reference::metrics::Metrics; 3]> {
            let mut imgs = Vec::new();
            let mut nan = Vec::new();
            for api in [Api::Vulkan, Api::Opengl] {
                let png = dir.join(format!("{scene}-{}.png", api_name(api)));
                let ra = RenderArgs {
                    frames: Some(1),
                    out: Some(png.clone()),
                    json: true,
                    set: set.clone(),
                    accel: Accel::None,
                    ..RenderArgs::headless(scene, size)
                };
                let r = run_json(api, &ra)?;
                nan.push(r.nonfinite_pixels);
                imgs.push(twinray_common::reference::image_io::load_png(&png)?);
            }
            let overrides: Vec<(String, String)> = set
                .iter()
                .filter_map(|kv| kv.split_once('='))
                .map(|(k, v)| (k.into(), v.into()))
                .collect();
            let sc = twinray_common::scene::Scene::load(scene, &overrides)?;
            let reference = twinray_common::reference::render(&sc, size.width, size.height);
            let ref_png = dir.join(format!("{scene}-reference.png"));
            reference.save_png(&ref_png)?;
            let reference = reference.to_rgb8();
            let mut vk_gl = twinray_common::reference::metrics::compare(&imgs[0], &imgs[1])?;
            vk_gl.nan_pixels = nan[0] + nan[1];
            let mut vk_ref = twinray_common::reference::metrics::compare(&imgs[0], &reference)?;
            vk_ref.nan_pixels = nan[0];
            let mut gl_ref = twinray_common::reference::metrics::compare(&imgs[1], &reference)?;
            gl_ref.nan_pixels = nan[1];
            Ok([vk_gl, vk_ref, gl_ref])
        })()
        .map_err(|e| format!("{e:#}"));
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
        let paths = compute.then(|| {
            (|| -> anyhow::Result<[twinray_common::reference::metrics::Metrics; 2]> {
                let mut m = Vec::new();
                for api in [Api::Vulkan, Api::Opengl] {
                    let frag = dir.join(format!("{scene}-{}.png", api_name(api)));
                    let png = dir.join(format!("{scene}-{}-compute.png", api_name(api)));
                    let ra = RenderArgs {
                        frames: Some(1),
                        out: Some(png.clone()),
                        json: true,
                        set: set.clone(),
                        path: RenderPath::Compute,
                        workgroup,
                        ..RenderArgs::headless(scene, size)
                    };
                    let r = run_json(api, &ra)?;
                    let mut metrics = twinray_common::reference::metrics::compare(
                        &twinray_common::reference::image_io::load_png(&png)?,
                        &twinray_common::reference::image_io::load_png(&frag)?,
                    )?;
                    metrics.nan_pixels = r.nonfinite_pixels;
                    m.push(metrics);
                }
                Ok([m[0], m[1]])
            })()
            .map_err(|e| format!("{e:#}"))
        });
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

/// One run of "model only what a scene needs": a scene in one configuration.
#[derive(Debug, Clone)]
pub struct AccelRun {
    pub scene: &'static str,
    pub size: Size,
    pub set: Vec<String>,
    /// One of ACCEL_CONFIGS.
    pub config: &'static str,
    pub api: Api,
    pub result: Result<RunReport, String>,
    /// BVH nodes, bytes and build milliseconds (built here, as the apps do).
    pub bvh: Option<(usize, usize, f64)>,
}

/// The all-features shader; the scene's own variant (defines); the one
/// all-features source specialised to the scene through specialization
/// constants (`--specialize`); the scene's variant with a BVH.
pub const ACCEL_CONFIGS: [&str; 4] = [
    "generic, brute force",
    "variant, brute force",
    "specialized, brute force",
    "variant, BVH",
];

/// Each scene with the all-features brute-force shader, its own variant, and
/// its variant with a BVH; then the sphere list scaled up with the BVH alone.
pub fn acceleration(plan: &Plan, stop: &AtomicBool) -> Vec<AccelRun> {
    let quick = plan.preset == "quick";
    let big = if quick {
        Size {
            width: 100,
            height: 100,
        }
    } else {
        Size {
            width: 1000,
            height: 1000,
        }
    };
    let sl = if quick {
        Size {
            width: 100,
            height: 100,
        }
    } else {
        Size {
            width: 300,
            height: 300,
        }
    };
    let mut cases: Vec<(&'static str, Size, Vec<String>, Vec<&'static str>)> = vec![
        (
            "teapot",
            if quick {
                Size {
                    width: 40,
                    height: 40,
                }
            } else {
                big
            },
            vec![],
            ACCEL_CONFIGS.to_vec(),
        ),
        ("box", big, vec![], ACCEL_CONFIGS.to_vec()),
        (
            "spherelist",
            sl,
            vec![format!(
                "extra_spheres={}",
                if quick { 1000 } else { 10000 }
            )],
            ACCEL_CONFIGS.to_vec(),
        ),
    ];
    // Where the BVH starts to pay: the crossover behind AUTO_BVH_MIN_PRIMITIVES.
    let crossover: &[u32] = if quick {
        &[1, 50, 200]
    } else {
        &[1, 10, 25, 50, 100, 200, 500]
    };
    for &n in crossover {
        cases.push((
            "spherelist",
            sl,
            vec![format!("extra_spheres={n}")],
            vec!["variant, brute force", "variant, BVH"],
        ));
    }
    let scaling: &[u32] = if quick {
        &[10_000]
    } else {
        &[1_000, 10_000, 100_000]
    };
    for &n in scaling {
        cases.push((
            "spherelist",
            sl,
            vec![format!("extra_spheres={n}")],
            vec!["variant, BVH"],
        ));
    }
    // The teapot from 19.2k to 1.2M triangles: the same generator, finer.
    let detail: &[&str] = if quick {
        &["40x30"]
    } else {
        &["40x30", "80x60", "160x120"]
    };
    let teapot_size = if quick {
        Size {
            width: 40,
            height: 40,
        }
    } else {
        big
    };
    for t in detail {
        cases.push((
            "teapot",
            teapot_size,
            vec![format!("tessellation={t}")],
            vec!["variant, BVH"],
        ));
    }
    eprintln!(
        "twinray compare: measuring shader variants and the BVH ({} runs)",
        cases.iter().map(|c| c.3.len() * 2).sum::<usize>()
    );
    let mut runs = Vec::new();
    for (scene, size, set, configs) in cases {
        for config in configs {
            let bvh = config.ends_with("BVH");
            let stats = bvh.then(|| {
                let overrides: Vec<(String, String)> = set
                    .iter()
                    .filter_map(|kv| kv.split_once('='))
                    .map(|(k, v)| (k.into(), v.into()))
                    .collect();
                twinray_common::scene::Scene::load(scene, &overrides)
                    .ok()
                    .map(|sc| {
                        let b = twinray_common::gpu::layout::Bvh::build(&sc);
                        (b.nodes.len(), b.bytes(), b.build_ms)
                    })
            });
            for api in [Api::Vulkan, Api::Opengl] {
                if stop.load(Ordering::SeqCst) {
                    return runs;
                }
                let ra = RenderArgs {
                    frames: Some(if quick { 4 } else { 12 }),
                    json: true,
                    set: set.clone(),
                    generic: config.starts_with("generic"),
                    specialize: config.starts_with("specialized"),
                    accel: if bvh { Accel::Bvh } else { Accel::None },
                    ..RenderArgs::headless(scene, size)
                };
                let result = run_json(api, &ra).map_err(|e| format!("{e:#}"));
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
