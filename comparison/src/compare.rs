//! `twinray compare`: the study's three experiments (teapot and box resolution
//! sweeps, the sphere-list count sweep) with both apps, each point in fresh
//! processes with the API order alternating, then results.csv, report.md and
//! plots, and the why step's experiments at each remaining gap (compare/why.rs).

mod accel;
mod agreement;
pub(crate) mod gaps;
pub(crate) mod runs;
pub(crate) mod shaders;
pub(crate) mod study;
pub(crate) mod why;
pub(crate) mod why_figures;

use crate::apps::{api_name, is_software, run_json, Api};
use anyhow::Context;
use runs::{Outcome, Plan, Point};
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use twinray_common::cli::{parse_workgroup, RenderArgs, RenderPath, Size, Workgroup};
use twinray_common::scene::accel::Accel;
use twinray_common::value_name::ValueName;
use why::WhyPlan;

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
    #[arg(long, default_value = "comparison-out", value_name = "DIR")]
    pub out: PathBuf,
    /// Frames per point (the study: 60; statistics over the last 30).
    // The apps' own parser: a count they would refuse is refused here, before any run.
    #[arg(long, value_parser = twinray_common::cli::parse_frames, allow_hyphen_values = true)]
    pub frames: Option<u32>,
    /// Fewer frames for slow points so that one app spends at most about this long on one point.
    #[arg(long, value_parser = twinray_common::cli::parse_seconds, allow_hyphen_values = true)]
    pub seconds_per_point: Option<f64>,
    /// Also run OpenGL on naga's SPIR-V (GL_ARB_gl_spirv): the same binary as Vulkan,
    /// which separates the API from the shader-compiler path.
    #[arg(long)]
    pub gl_spirv: bool,
    /// Only these experiments (teapot, box, spherelist, accel, why), comma-separated.
    #[arg(long, value_delimiter = ',')]
    pub only: Vec<String>,
    /// The tracer's entry points to measure, comma-separated: each point runs both APIs on each.
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = [RenderPath::Fragment, RenderPath::Compute])]
    pub paths: Vec<RenderPath>,
    /// The compute path's workgroup WxH (default: the apps' default).
    #[arg(long, value_name = "WxH", value_parser = parse_workgroup)]
    pub workgroup: Option<Workgroup>,
    /// Count every point's rays (one untimed frame more per run) for the
    /// Grays/s columns and plots. Always on outside the quick preset; the
    /// quick one (software drivers) skips it unless asked, as the counting
    /// variant's compile doubles its time there.
    #[arg(long)]
    pub count_rays: bool,
}

/// What `--only` can pick: the three sweeps, "accel", the runs of "model
/// only what a scene needs" (variants, specialization constants, BVH), and
/// "why", the experiments at each remaining Vulkan/OpenGL gap.
pub const ONLY_CHOICES: [&str; 5] = ["teapot", "box", "spherelist", "accel", "why"];

/// A preset's sweeps: the study's in full, smaller ones for software drivers.
struct Preset {
    name: &'static str,
    teapot_sides: Vec<u32>,
    box_sides: Vec<u32>,
    extra_spheres: Vec<u32>,
    spherelist_side: u32,
    /// Frames per run at most: each stops once settled (`settle`).
    frames: u32,
    /// The half-width, in per cent, each run's median interval must reach.
    settle: f64,
    seconds_per_point: f64,
    why: WhyPlan,
}

impl Preset {
    fn of(quick: bool) -> Preset {
        if quick {
            Preset {
                name: "quick",
                // A brute-force teapot costs half a second a frame on a
                // CPU at 40², and seconds at 80²: small sizes, few frames.
                teapot_sides: vec![24, 40],
                box_sides: vec![100, 200],
                extra_spheres: vec![1, 10, 100],
                spherelist_side: 100,
                // Enough for an interval (a warm-up and 6 timed frames); a
                // CPU's frames rarely settle to ±2 %, so most runs take 8.
                frames: 8,
                settle: 2.0,
                seconds_per_point: 4.0,
                why: WhyPlan::QUICK,
            }
        } else {
            Preset {
                name: "full",
                teapot_sides: (1..=10).map(|i| i * 100).collect(),
                box_sides: (1..=10).map(|i| i * 100).collect(),
                extra_spheres: vec![1, 10, 50, 100, 500, 1000, 2500, 5000, 10000],
                spherelist_side: 300,
                frames: 60,
                settle: 1.0,
                seconds_per_point: 30.0,
                why: WhyPlan::FULL,
            }
        }
    }
}

fn square(side: u32) -> Size {
    Size {
        width: side,
        height: side,
    }
}

pub fn plan(args: &CompareArgs) -> anyhow::Result<Plan> {
    check_only(args)?;
    let preset = Preset::of(args.quick);
    let mut points = Vec::new();
    let wanted = |e: &str| args.only.is_empty() || args.only.iter().any(|o| o == e);
    for (exp, sides) in [("teapot", &preset.teapot_sides), ("box", &preset.box_sides)] {
        if !wanted(exp) {
            continue;
        }
        for &r in sides {
            points.push(Point {
                experiment: exp,
                param_name: "resolution",
                param_value: format!("{r}x{r}"),
                scene: exp,
                size: square(r),
                set: vec![],
                work: (r as f64 / sides[0] as f64).powi(2),
            });
        }
    }
    if wanted("spherelist") {
        let counts = &preset.extra_spheres;
        for &n in counts {
            points.push(Point {
                experiment: "spherelist",
                param_name: "extra_spheres",
                param_value: n.to_string(),
                scene: "spherelist",
                size: square(preset.spherelist_side),
                set: vec![format!("extra_spheres={n}")],
                work: (n as f64 + 8.0) / (counts[0] as f64 + 8.0),
            });
        }
    }
    Ok(Plan {
        points,
        frames: args.frames.unwrap_or(preset.frames),
        settle: Some(preset.settle),
        seconds_per_point: args.seconds_per_point.unwrap_or(preset.seconds_per_point),
        preset: preset.name,
    })
}

/// `--only`'s names, checked before anything is created or run.
fn check_only(args: &CompareArgs) -> anyhow::Result<()> {
    for e in &args.only {
        if !ONLY_CHOICES.contains(&e.as_str()) {
            return Err(twinray_common::error::bad_input(format!(
                "--only '{e}' is not an experiment ({})",
                ONLY_CHOICES.join(", ")
            )));
        }
    }
    Ok(())
}

pub fn run(args: &CompareArgs) -> anyhow::Result<()> {
    // Every option first: refusing one creates nothing.
    check_only(args)?;
    let mut paths = args.paths.clone();
    paths.dedup();
    if paths.is_empty() {
        return Err(twinray_common::error::bad_input(
            "--paths names no path; use fragment, compute or both",
        ));
    }
    crate::apps::check_present()?;
    // Before the device probe and every render: a bad --out must cost nothing.
    twinray_common::reference::image_io::prepare_output_dir("--out", &args.out)?;
    let stop = crate::interrupt::Stop::install()?;
    let started = std::time::Instant::now();
    let args = &with_preset(args)?;
    let plan = plan(args)?;
    let mut apis = vec![Api::Vulkan, Api::Opengl];
    if args.gl_spirv {
        apis.push(Api::OpenglSpirv);
    }
    let runs: Vec<(Api, RenderPath)> = paths
        .iter()
        .flat_map(|&p| apis.iter().map(move |&a| (a, p)))
        .collect();
    // The first step a signal stopped; the steps after it do not start.
    let mut stopped_in: Option<&'static str> = None;
    // Each step's seconds, for the log and the report.
    let mut timings: Vec<(&'static str, f64)> = Vec::new();
    let mut step_start = std::time::Instant::now();
    let mut step = |name: &'static str, stop: &crate::interrupt::Stop| {
        let seconds = step_start.elapsed().as_secs_f64();
        step_start = std::time::Instant::now();
        if seconds >= 0.5 {
            eprintln!("twinray compare: {name} took {seconds:.0} s");
            timings.push((name, seconds));
        }
        if stop.stopped() && stopped_in.is_none() {
            stopped_in = Some(name);
        }
        stopped_in.is_none()
    };
    let wanted = |e: &str| args.only.is_empty() || args.only.iter().any(|o| o == e);
    // `--only why` alone runs the why step and nothing else.
    let only_why = !args.only.is_empty() && args.only.iter().all(|o| o == "why");
    let outcomes = sweep(args, &plan, &runs, stop.flag());
    let accel = if step("the sweep", &stop) && wanted("accel") {
        accel::acceleration(&plan, stop.flag())
    } else {
        Vec::new()
    };
    let agreement = if step("the acceleration runs", &stop) && !only_why {
        agreement::agreement(&args.out, &plan, &paths, args.workgroup, stop.flag())
    } else {
        Vec::new()
    };
    let shader_rows = if step("the image agreement", &stop) && !only_why {
        shaders::collect(&args.out, &paths, stop.flag())
    } else {
        Vec::new()
    };
    let why = if step("the shader statistics", &stop) && wanted("why") {
        // The step keeps its own sizes, but --frames and --seconds-per-point
        // bound its runs too, so a short GPU lease can afford it.
        let mut why_plan = Preset::of(args.quick).why;
        why_plan.frames = args.frames.unwrap_or(why_plan.frames);
        why_plan.settle = plan.settle.unwrap_or(why_plan.settle);
        why_plan.seconds_per_point = args.seconds_per_point.unwrap_or(why_plan.seconds_per_point);
        Some(why::run(&args.out, &why_plan, &paths, stop.flag()))
    } else {
        None
    };
    // Past the why step (or the last step this run had), only the report is left.
    let last = if why.is_some() {
        "the why step"
    } else {
        "the report"
    };
    step(last, &stop);
    let interrupted = stop.signal().map(|(signal, _)| runs::Interruption {
        signal,
        step: stopped_in.unwrap_or(last),
    });
    let cost = (crate::apps::runs_started(), started.elapsed().as_secs_f64());
    let steps = timings
        .iter()
        .map(|(name, s)| format!("{name} {s:.0} s"))
        .collect::<Vec<_>>()
        .join(", ");
    let results = runs::Results {
        plan: &plan,
        outcomes: &outcomes,
        accel: &accel,
        agreement: &agreement,
        runs: &runs,
        interrupted,
        cost: Some((cost.0, cost.1, steps)),
    };
    write_report(&args.out, &results, &shader_rows, why.as_ref(), only_why)?;
    let failed = failures(&results, &shader_rows, why.as_ref());
    eprintln!("{}", done_line(&results, &args.out));
    if let Some((_, code)) = stop.signal() {
        std::process::exit(code);
    }
    crate::failures::check(&failed)
}

/// The log's last line: the app runs and seconds of every step, the sweep's
/// share done (where it ran any), an interruption, and where the report is.
fn done_line(results: &runs::Results, out: &std::path::Path) -> String {
    let (runs, seconds) = results.cost.as_ref().map_or((0, 0.0), |c| (c.0, c.1));
    // A run with no sweep (--only why) says nothing of one.
    let planned = results.plan.points.len() * results.runs.len();
    let sweep = if planned == 0 {
        String::new()
    } else {
        let done = results.outcomes.iter().filter(|o| o.result.is_ok()).count();
        format!("; the sweep's {done} of {planned} runs done")
    };
    let interrupted = match results.interrupted {
        Some(i) => format!(
            " (interrupted by {} during {}: the finished points are kept)",
            i.signal, i.step
        ),
        None => String::new(),
    };
    format!(
        "twinray compare: {runs} app runs in {seconds:.0} s{sweep}{interrupted}; report: {}",
        out.join("report.md").display()
    )
}

/// report.md (or, for `--only why`, its title alone) with results.csv and
/// the plots, the shader table and the why section; written once, after
/// every step, so that an interruption in any of them is in its title.
fn write_report(
    out: &std::path::Path,
    results: &runs::Results,
    shader_rows: &[shaders::ShaderRow],
    why: Option<&runs::Why>,
    only_why: bool,
) -> anyhow::Result<()> {
    match why {
        Some(why) if only_why => {
            // No study ran, so no study sections: a title naming the device
            // the why step measured, then its section.
            let title =
                crate::report::title(why.vulkan_device.as_deref(), why.opengl_device.as_deref());
            let report = out.join("report.md");
            let text = format!(
                "{title}{}\n{}",
                crate::report::interrupted_suffix(results.interrupted),
                crate::report::interrupted_note(results.interrupted)
            );
            std::fs::write(&report, text)
                .with_context(|| format!("writing '{}'", report.display()))?;
        }
        _ => {
            crate::report::write_all(out, results)?;
            shaders::append_to_report(&out.join("report.md"), shader_rows)?;
        }
    }
    if let Some(why) = why {
        crate::report::why_table::write(out, why, results.interrupted)?;
    }
    Ok(())
}

/// Every run that failed, in every step, with the app's own error line: a
/// comparison in which any failed is not a success. The why step's rows not
/// run (a refused experiment, a missing tool) or not measured (a figure this
/// device's clock cannot give) are not failures; they are the table's answer.
fn failures(
    results: &runs::Results,
    shader_rows: &[shaders::ShaderRow],
    why: Option<&runs::Why>,
) -> Vec<(String, String)> {
    let mut failed: Vec<(String, String)> = Vec::new();
    for o in results.outcomes {
        if let Err(e) = &o.result {
            let run = format!(
                "{} {} {} {}",
                o.point.experiment,
                o.point.param_value,
                api_name(o.api),
                o.path
            );
            failed.push((run, e.clone()));
        }
    }
    for r in results.accel {
        if let Err(e) = &r.result {
            let run = format!("{} {} {}", r.scene, r.config, api_name(r.api));
            failed.push((run, e.clone()));
        }
    }
    for a in results.agreement {
        let paths = a.paths.as_ref().and_then(|p| p.as_ref().err());
        for e in a.result.as_ref().err().into_iter().chain(paths) {
            failed.push((format!("{} image agreement", a.scene), e.clone()));
        }
    }
    for r in shader_rows {
        if let Err(e) = &r.result {
            let run = format!(
                "{} shader statistics {} {}",
                r.scene,
                api_name(r.api),
                r.path
            );
            failed.push((run, e.clone()));
        }
    }
    for r in why.map(|w| w.rows.as_slice()).unwrap_or_default() {
        if let Err(e) = &r.result {
            if !e.starts_with("not run") && !e.starts_with(runs::NOT_MEASURED) {
                let reason = e.strip_prefix("failed: ").unwrap_or(e).to_string();
                failed.push((format!("why: {}", r.case.gap.name), reason));
            }
        }
    }
    failed
}

/// The arguments with the preset decided: without --quick or --full, a probe
/// of the Vulkan device picks quick on a software driver.
fn with_preset(args: &CompareArgs) -> anyhow::Result<CompareArgs> {
    let mut args = args.clone();
    if !args.quick && !args.full {
        let probe = RenderArgs {
            frames: Some(1),
            out: None,
            json: true,
            set: vec![],
            ..RenderArgs::headless("spherelist", square(8))
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
    Ok(args)
}

/// Every point of the plan with each API on each path (`runs`), in fresh
/// processes, the order alternating from point to point, until `stop` is
/// raised (the finished points are kept).
fn sweep(
    args: &CompareArgs,
    plan: &Plan,
    runs: &[(Api, RenderPath)],
    stop: &AtomicBool,
) -> Vec<Outcome> {
    let mut paths: Vec<RenderPath> = runs.iter().map(|r| r.1).collect();
    paths.dedup();
    let apis = runs.len() / paths.len().max(1);
    eprintln!(
        "twinray compare: {} preset, {} points x {} APIs x {} paths ({}), up to {} frames each (about {} s per app per point at most) -> {}",
        plan.preset,
        plan.points.len(),
        apis,
        paths.len(),
        paths.iter().map(|p| p.name()).collect::<Vec<_>>().join(", "),
        plan.frames,
        plan.seconds_per_point,
        args.out.display()
    );
    let bar = indicatif::ProgressBar::new((plan.points.len() * runs.len()) as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{bar:40} {pos}/{len} [{elapsed_precise} elapsed, ETA {eta}] {msg}",
        )
        .expect("valid template"),
    );
    let mut outcomes: Vec<Outcome> = Vec::new();
    // Frame-time prediction per experiment and path (on a GPU the paths differ by
    // up to 30x): (work, wall ms) of the last finished point.
    let mut last: HashMap<(&str, RenderPath), (f64, f64)> = HashMap::new();
    'points: for (i, point) in plan.points.iter().enumerate() {
        let mut order = runs.to_vec();
        if i % 2 == 1 {
            order.reverse();
        }
        for (api, path) in order {
            let frames = match last.get(&(point.experiment, path)) {
                Some(&(work, ms)) if ms > 0.0 => {
                    let predicted = ms * point.work / work;
                    ((plan.seconds_per_point * 1e3 / predicted).floor() as u32)
                        .clamp(plan.frames.min(MIN_SETTLING_FRAMES), plan.frames)
                }
                _ => plan.frames,
            };
            if stop.load(Ordering::SeqCst) {
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
                settle: plan.settle,
                out: None,
                json: true,
                // One untimed frame more per point, for the Grays/s column and
                // plot, on the compute path only: both paths trace the very
                // same rays (tests/tests/rays.rs), and a brute-force fragment
                // frame costs seconds. share_rays gives the fragment runs theirs.
                count_rays: (args.count_rays || !args.quick) && path == RenderPath::Compute,
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
            if stop.load(Ordering::SeqCst) && result.is_err() {
                // The supervisor stopped the child with this process: this
                // point did not finish, and is not a failed one.
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
    share_rays(&mut outcomes);
    outcomes
}

/// The fewest frames that can settle: a warm-up frame and the 6 timed frames
/// a 95 % interval of the median needs (`stats::interval_rank`).
const MIN_SETTLING_FRAMES: u32 = 7;

/// Gives each run that did not count its rays the count of the same API at
/// the same point on the other path, and the rate it makes with its own time.
fn share_rays(outcomes: &mut [Outcome]) {
    let counted: Vec<(String, &'static str, Api, twinray_common::rays::RayCounts)> = outcomes
        .iter()
        .filter_map(|o| {
            let r = o.result.as_ref().ok()?;
            Some((
                o.point.param_value.clone(),
                o.point.experiment,
                o.api,
                r.rays?,
            ))
        })
        .collect();
    for o in outcomes.iter_mut() {
        let (value, experiment, api) = (o.point.param_value.clone(), o.point.experiment, o.api);
        if let Ok(r) = &mut o.result {
            if r.rays.is_none() {
                if let Some(c) = counted
                    .iter()
                    .find(|c| c.0 == value && c.1 == experiment && c.2 == api)
                {
                    r.set_rays(c.3);
                }
            }
        }
    }
}
