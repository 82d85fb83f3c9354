//! `twinray ulp`: the GPU's f32 arithmetic, measured. For every operation of
//! the tracer (`UlpOp`), API and path, it runs the app with the laboratory's
//! arithmetic probe (`--experiment ulp --ulp-op OP`, shaders/lab/ulp.glsl),
//! decodes the PNG into one f32 per result, recomputes each result's inputs
//! (`inputs`) and its f64 reference (`ops`), and writes the largest and mean
//! ULP error per operation, API, path and driver (`measure`) as ulp.md and
//! ulp.csv (`report`), beside the same figures for IEEE f32 done one step at
//! a time on the CPU.

mod inputs;
mod measure;
mod ops;
mod report;

use crate::apps::{self, Api};
use anyhow::Context;
use measure::ByClass;
use std::path::{Path, PathBuf};
use std::time::Instant;
use twinray_common::cli::{RenderArgs, RenderPath, Size};
use twinray_common::error::bad_input;
use twinray_common::lab::experiment::{Experiment, UlpOp};
use twinray_common::reference::image_io::{load_png, prepare_output_dir};

#[derive(clap::Args, Debug, Clone)]
pub struct UlpArgs {
    /// Inputs per operation and run (a vector operation gives three results
    /// per input, one per component).
    #[arg(long, default_value_t = 1 << 20, value_parser = clap::value_parser!(u32).range(1..=16_000_000))]
    pub inputs: u32,
    /// Output folder: ulp.md and ulp.csv.
    #[arg(long, default_value = "ulp-out", value_name = "DIR")]
    pub out: PathBuf,
    /// The operations, comma-separated [default: all].
    #[arg(long, value_enum, value_delimiter = ',', value_name = "OPS")]
    pub ops: Vec<UlpOp>,
    /// The APIs, comma-separated: vulkan, opengl, opengl-spirv [default: vulkan,opengl].
    #[arg(long, value_enum, value_delimiter = ',', value_name = "APIS")]
    pub apis: Vec<Api>,
    /// The paths, comma-separated [default: fragment,compute].
    #[arg(long, value_enum, value_delimiter = ',', value_name = "PATHS")]
    pub paths: Vec<RenderPath>,
}

/// One run of the probe: one operation, API and path.
pub struct Run {
    pub op: UlpOp,
    pub api: Api,
    pub path: RenderPath,
    pub device: String,
    pub driver: String,
    pub seconds: f64,
    pub stats: Result<ByClass, String>,
}

impl Run {
    pub fn label(&self) -> String {
        format!("{:?} {} {}", self.op, apps::api_name(self.api), self.path).to_lowercase()
    }
}

/// The image that holds `results` results at two pixels each: 2048 wide
/// (or narrower for a small run), even, as many rows as needed.
pub fn image_size(results: u64) -> Size {
    let pixels = 2 * results;
    let width = pixels.min(2048) as u32;
    Size {
        width,
        height: pixels.div_ceil(u64::from(width)) as u32,
    }
}

/// The tallest probe image: 16384 rows (of 2048 pixels), the largest 2D
/// image lavapipe and llvmpipe accept and GL 4.5's least GL_MAX_TEXTURE_SIZE,
/// so a run that needs more would only fail in the app, after the others.
const MAX_ROWS: u32 = 16384;

/// Refuses `--inputs` that some chosen operation cannot fit in one probe
/// image, before any run, naming the operation and the largest count that fits.
fn check_inputs(inputs: u32, ops: &[UlpOp]) -> anyhow::Result<()> {
    use twinray_common::value_name::ValueName;
    for &op in ops {
        let results = u64::from(inputs) * u64::from(ops::components(op));
        let size = image_size(results);
        if size.height > MAX_ROWS {
            let fits = u64::from(MAX_ROWS) * 2048 / 2 / u64::from(ops::components(op));
            return Err(bad_input(format!(
                "--inputs {inputs}: {} gives {results} results, a {size} image, taller than the {MAX_ROWS} rows every driver renders; give --inputs at most {fits} or leave {} out of --ops",
                op.name(),
                op.name()
            )));
        }
    }
    Ok(())
}

fn or_default<T: Clone>(chosen: &[T], default: &[T]) -> Vec<T> {
    if chosen.is_empty() { default } else { chosen }.to_vec()
}

pub fn run(args: &UlpArgs) -> anyhow::Result<()> {
    use clap::ValueEnum;
    let apis = or_default(&args.apis, &[Api::Vulkan, Api::Opengl]);
    if apis.contains(&Api::Reference) {
        return Err(bad_input(
            "--apis reference: the probe measures a GPU driver; the CPU's IEEE f32 column is always there",
        ));
    }
    let ops = or_default(&args.ops, UlpOp::value_variants());
    let paths = or_default(&args.paths, &[RenderPath::Fragment, RenderPath::Compute]);
    check_inputs(args.inputs, &ops)?;
    apps::check_present()?;
    prepare_output_dir("--out", &args.out)?;
    // SIGINT, SIGTERM and SIGHUP end the runs (the supervisor stops the
    // running app); the finished runs are measured and written, marked.
    let stop = crate::interrupt::Stop::install()?;
    let scratch = std::env::temp_dir().join(format!("twinray-ulp-{}", std::process::id()));
    std::fs::create_dir_all(&scratch).with_context(|| format!("creating {}", scratch.display()))?;
    let started = Instant::now();
    let mut runs: Vec<Run> = Vec::new();
    // The CPU's column, op by op as each op's runs end, so that a signal
    // leaves at most one to compute (all 17 at 2^20 inputs take seconds).
    let mut baseline: Vec<(UlpOp, ByClass)> = Vec::new();
    'runs: for &op in &ops {
        for &api in &apis {
            for &path in &paths {
                if stop.stopped() {
                    break 'runs;
                }
                let run = probe(op, api, path, args.inputs, &scratch);
                if stop.stopped() && run.stats.is_err() {
                    // Stopped by the signal, not failed: not a run of the report.
                    break 'runs;
                }
                match &run.stats {
                    Ok(s) => eprintln!(
                        "twinray ulp: {}: max {:.3} ULP ({:.1} s)",
                        run.label(),
                        s[0].1.max,
                        run.seconds
                    ),
                    Err(e) => eprintln!("twinray ulp: {}: failed: {e}", run.label()),
                }
                runs.push(run);
            }
        }
        baseline.push((op, measure::baseline(op, args.inputs)));
    }
    let _ = std::fs::remove_dir_all(&scratch);
    // An op the signal cut short keeps the runs it finished, and its column.
    if let Some(last) = runs.last().map(|r| r.op) {
        if !baseline.iter().any(|(op, _)| *op == last) {
            baseline.push((last, measure::baseline(last, args.inputs)));
        }
    }
    let seconds = started.elapsed().as_secs_f64();
    let interrupted = stop
        .signal()
        .map(|(signal, _)| format!("interrupted by {signal}"));
    let at = (args.inputs, seconds, interrupted.as_deref());
    report::write(&args.out, &runs, &baseline, at)?;
    eprintln!(
        "twinray ulp: {} runs in {seconds:.0} s{}; {} and {}",
        runs.len(),
        interrupted.as_deref().map_or(String::new(), |i| format!(
            " ({i}: the finished runs are kept)"
        )),
        args.out.join("ulp.md").display(),
        args.out.join("ulp.csv").display()
    );
    if let Some((_, code)) = stop.signal() {
        std::process::exit(code);
    }
    let failed: Vec<(String, String)> = runs
        .iter()
        .filter_map(|r| r.stats.as_ref().err().map(|e| (r.label(), e.clone())))
        .collect();
    // A run that failed is not a success, as in compare and accuracy: the
    // report says why, and so does the exit code.
    crate::failures::check(&failed)
}

/// One run: the app renders the probe, the PNG is decoded and measured.
fn probe(op: UlpOp, api: Api, path: RenderPath, inputs: u32, scratch: &Path) -> Run {
    let started = Instant::now();
    let results = u64::from(inputs) * u64::from(ops::components(op));
    let png = scratch.join(format!("{op:?}-{}-{path}.png", apps::api_name(api)));
    let mut render = RenderArgs::headless("box", image_size(results));
    render.frames = Some(1);
    render.out = Some(png.clone());
    render.path = path;
    render.experiment = vec![Experiment::Ulp];
    render.ulp_op = Some(op);
    let mut run = Run {
        op,
        api,
        path,
        device: String::new(),
        driver: String::new(),
        seconds: 0.0,
        stats: Err(String::new()),
    };
    run.stats = (|| {
        let report = apps::run_json(api, &render)?;
        run.device = report.device.clone();
        run.driver = report.driver.clone();
        let image = load_png(&png)?;
        let _ = std::fs::remove_file(&png);
        let mut bits = measure::decode(image.as_raw())?;
        bits.truncate(results as usize);
        Ok::<_, anyhow::Error>(measure::measure(op, &bits))
    })()
    .map_err(|e| format!("{e:#}"));
    run.seconds = started.elapsed().as_secs_f64();
    run
}
