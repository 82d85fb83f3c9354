//! The device-side steps a plan may ask for after its timed rounds, which
//! the investigation scripts did by hand: `shaders = true` runs each cell
//! once more with `--dump-shaders` (under `shaders/`), and its report's
//! statistics (registers, local and shared memory, as each driver names
//! them) go to sweep.jsonl and a table; `images = "..."` has that run write
//! its image (under `images/`) and compares it, as `twinray diff` does, with
//! the first build's, the first app's, the f64 reference's or the truth's.
//! Against another build the `--json` reports are compared too, timings
//! aside, so that a plan can prove a change leaves the output alone. The
//! extra runs are one frame each and kept out of the timed rounds: dumping
//! and reading back change nothing a timing should see.

use super::plan::{Cell, Images, Plan};
use crate::apps::{self, api_name, Api, Launch};
use std::path::{Path, PathBuf};
use twinray_common::cli::RenderArgs;
use twinray_common::reference::image_io::load_png;
use twinray_common::reference::metrics::{compare, Metrics};

/// The fields of a report that are timings (or follow from them): left out
/// when two builds' reports are compared.
const TIMINGS: [&str; 6] = [
    "frames",
    "gpu_ms",
    "wall_ms",
    "setup_ms",
    "bvh_ms",
    "grays_per_s",
];

/// One cell's device-side run.
struct Ran {
    image: Option<PathBuf>,
    report: Option<serde_json::Value>,
    variant: String,
    figures: String,
}

/// A file name's part for a name the plan chose.
fn slug(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || ".-".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// A report without its timings, for comparing two builds' output.
fn untimed(report: &serde_json::Value) -> serde_json::Value {
    let mut r = report.clone();
    if let Some(map) = r.as_object_mut() {
        for key in TIMINGS {
            map.remove(key);
        }
    }
    r
}

/// Runs the steps and returns sweep.md's sections for them; each run and
/// each comparison is a line of sweep.jsonl (through `append`) as it ends.
pub fn run(
    plan: &Plan,
    cells: &[Cell],
    out: &Path,
    stop: &crate::interrupt::Stop,
    append: &mut dyn FnMut(&serde_json::Value) -> anyhow::Result<()>,
    failed: &mut Vec<String>,
) -> anyhow::Result<String> {
    if stop.stopped() || (!plan.shaders && plan.images.is_none()) {
        return Ok(String::new());
    }
    let mut ran: Vec<Option<Ran>> = Vec::new();
    for (i, cell) in cells.iter().enumerate() {
        if stop.stopped() {
            return Ok(String::new());
        }
        let (build, set) = (&plan.builds[cell.build], &plan.sets[cell.set]);
        let name = format!("{}-{}-{}", build.name, api_name(cell.app), set.name);
        let mut args = RenderArgs {
            frames: Some(1),
            settle: None,
            ..set.args.clone()
        };
        if plan.images.is_some() {
            std::fs::create_dir_all(out.join("images"))?;
            args.out = Some(out.join("images").join(format!("{}.png", slug(&name))));
        }
        if plan.shaders {
            args.dump_shaders = Some(out.join("shaders").join(slug(&name)));
        }
        eprintln!("twinray sweep: device-side run of {name}");
        let launch = Launch {
            bin_dir: Some(build.dir.clone()),
            extra: set.extra.clone(),
            env: set.env.clone(),
        };
        let mut line = serde_json::json!({
            "step": "device",
            "build": build.name,
            "app": api_name(cell.app),
            "set": set.name,
            "cell": i,
        });
        match apps::run_json_with(cell.app, &args, &launch) {
            Err(e) if crate::supervisor::is_interrupted(&e) => return Ok(String::new()),
            Err(e) => {
                let message = format!("{e:#}");
                eprintln!("twinray sweep: that run failed: {message}");
                line["error"] = message.clone().into();
                failed.push(message);
                ran.push(None);
            }
            Ok(r) => {
                line["pid"] = r.pid.into();
                line["image"] = serde_json::json!(args.out);
                line["report"] = r.json.clone();
                ran.push(Some(Ran {
                    image: args.out.clone(),
                    report: Some(r.json),
                    variant: r.report.variant.clone(),
                    figures: crate::compare::shaders::figures(&r.report.shader_stats),
                }));
            }
        }
        append(&line)?;
    }
    let mut md = String::new();
    if plan.shaders {
        md += &shader_table(plan, cells, &ran);
    }
    if let Some(images) = plan.images {
        md += &image_table(plan, cells, &ran, images, out, append, failed)?;
    }
    Ok(md)
}

fn shader_table(plan: &Plan, cells: &[Cell], ran: &[Option<Ran>]) -> String {
    let mut md = String::from("\n## What the drivers compiled\n\nEach cell once more, one frame, with `--dump-shaders` (the dumps under `shaders/`): the registers and memory each driver reports of the tracer.\n\n| build | app | set | variant | statistics |\n|---|---|---|---|---|\n");
    for (cell, r) in cells.iter().zip(ran) {
        let (variant, figures) = match r {
            Some(r) => (r.variant.as_str(), r.figures.as_str()),
            None => ("–", "the run failed"),
        };
        md += &format!(
            "| {} | {} | {} | {variant} | {figures} |\n",
            plan.builds[cell.build].name,
            api_name(cell.app),
            plan.sets[cell.set].name.replace('|', "\\|")
        );
    }
    md
}

/// Where the image a cell is compared with comes from.
enum Against {
    Cell(usize),
    Cpu { truth: bool },
}

fn image_table(
    plan: &Plan,
    cells: &[Cell],
    ran: &[Option<Ran>],
    images: Images,
    out: &Path,
    append: &mut dyn FnMut(&serde_json::Value) -> anyhow::Result<()>,
    failed: &mut Vec<String>,
) -> anyhow::Result<String> {
    let mut md =
        String::from("\n## Images\n\nEach cell's image (one frame, under `images/`) against ");
    md += match images {
        Images::Builds => "the first build's, same app and set, with the two `--json` reports compared too, timings aside (`report`)",
        Images::Apps => "the first app's, same build and set",
        Images::Reference => "the f64 reference of its scene, size, `--set` and `--accel`",
        Images::Truth => "the f64 truth of its scene, size and `--set`",
    };
    md += ". Max abs in 1/255 steps; the shares are of pixels off by more than 1/255 and 8/255.\n\n| build | app | set | against | bytes | max abs | >1/255 | >8/255 | PSNR dB | report |\n|---|---|---|---|---|---|---|---|---|---|\n";
    let mut cpu: Vec<Option<Result<PathBuf, String>>> = vec![None; plan.sets.len()];
    for (i, cell) in cells.iter().enumerate() {
        let against = match images {
            Images::Builds if cell.build > 0 => Against::Cell(
                cells
                    .iter()
                    .position(|c| c.build == 0 && c.app == cell.app && c.set == cell.set)
                    .expect("every build has every cell"),
            ),
            Images::Apps if cell.app != plan.apps[0] => Against::Cell(
                cells
                    .iter()
                    .position(|c| {
                        c.build == cell.build && c.app == plan.apps[0] && c.set == cell.set
                    })
                    .expect("every app has every cell"),
            ),
            Images::Reference => Against::Cpu { truth: false },
            Images::Truth => Against::Cpu { truth: true },
            _ => continue,
        };
        let Some(Some(this)) = ran.get(i) else {
            continue;
        };
        let (label, other, other_report) = match against {
            Against::Cell(j) => {
                let c = cells[j];
                let label = match images {
                    Images::Builds => format!("build {}", plan.builds[c.build].name),
                    _ => api_name(c.app).to_string(),
                };
                match &ran[j] {
                    Some(r) => (label, r.image.clone(), r.report.as_ref()),
                    None => (label, None, None),
                }
            }
            Against::Cpu { truth } => {
                let slot = &mut cpu[cell.set];
                if slot.is_none() {
                    *slot = Some(render_cpu(&plan.sets[cell.set].args, truth, out, cell.set));
                }
                let label = if truth { "truth" } else { "reference" }.to_string();
                match slot.as_ref().expect("just filled") {
                    Ok(path) => (label, Some(path.clone()), None),
                    Err(e) => {
                        failed.push(e.clone());
                        (label, None, None)
                    }
                }
            }
        };
        let (Some(a), Some(b)) = (other, this.image.clone()) else {
            continue;
        };
        let same_bytes = std::fs::read(&a)? == std::fs::read(&b)?;
        let metrics: Metrics = compare(&load_png(&a)?, &load_png(&b)?)?;
        let same_report = match (other_report, &this.report) {
            (Some(x), Some(y)) if images == Images::Builds => Some(untimed(x) == untimed(y)),
            _ => None,
        };
        let (build, set) = (&plan.builds[cell.build].name, &plan.sets[cell.set].name);
        append(&serde_json::json!({
            "step": "images",
            "build": build,
            "app": api_name(cell.app),
            "set": set,
            "against": label,
            "a": a,
            "b": b,
            "same_bytes": same_bytes,
            "same_report": same_report,
            "diff": metrics,
        }))?;
        md += &format!(
            "| {build} | {} | {} | {label} | {} | {} | {:.4} % | {:.4} % | {:.2} | {} |\n",
            api_name(cell.app),
            set.replace('|', "\\|"),
            if same_bytes { "identical" } else { "differ" },
            metrics.max_abs,
            100.0 * metrics.above_1,
            100.0 * metrics.above_8,
            metrics.psnr_db,
            match same_report {
                Some(true) => "identical",
                Some(false) => "differs",
                None => "–",
            }
        );
    }
    Ok(md)
}

/// The f64 reference (or truth) image of set `index`, rendered in-process
/// from the options the CPU can honour: scene, size, `--set` and, but for
/// the truth, `--accel`.
fn render_cpu(args: &RenderArgs, truth: bool, out: &Path, index: usize) -> Result<PathBuf, String> {
    let kind = if truth { "truth" } else { "reference" };
    let path = out
        .join("images")
        .join(format!("{kind}-set{}.png", index + 1));
    let cpu_default = RenderArgs::headless(&args.scene, args.size);
    let cpu = RenderArgs {
        set: args.set.clone(),
        accel: if truth { cpu_default.accel } else { args.accel },
        out: Some(path.clone()),
        ..cpu_default.clone()
    };
    eprintln!(
        "twinray sweep: the f64 {kind} of {} at {}",
        args.scene, args.size
    );
    apps::render(Api::Reference, &cpu, truth)
        .map(|()| path)
        .map_err(|e| format!("the f64 {kind} of {}: {e:#}", args.scene))
}
