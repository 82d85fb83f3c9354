//! `twinray accuracy`: speed against error. Renders the standard scenes with
//! both apps over the knobs that trade one for the other (maximum depth, the
//! secondary-ray offset, the triangle and sphere tests), measures every image
//! against the f64 truth (reference.rs `render_truth`, depth 16 for the depth
//! sweep), marks the Pareto front, then runs the hard cases (scenes/hard/) per
//! strategy (with the local origin's before/after columns), and last compares
//! both apps and the reference on seeded random scenes (`--random N`). Writes
//! report.md, accuracy.csv, hard_cases.csv, random.csv, one SVG per scene and
//! the images.

pub(crate) mod hard;
pub(crate) mod pareto;
mod plot;
pub(crate) mod random;
mod report;
pub(crate) mod sweeps;

use anyhow::Context;
use hard::HardRow;
use random::RandomRow;
use std::path::{Path, PathBuf};
use sweeps::Row;
use twinray_common::scene::hard::HardCase;
use twinray_common::scene::numerics::Numerics;
use twinray_common::scene::OriginMode;

#[derive(clap::Args, Debug, Clone)]
pub struct AccuracyArgs {
    /// Small images and few frames: a few minutes on software drivers.
    #[arg(long)]
    pub quick: bool,
    /// Output folder.
    #[arg(long, default_value = "accuracy-out", value_name = "DIR")]
    pub out: PathBuf,
    /// The hard-case folder (default: scenes/hard of this source tree).
    #[arg(long)]
    pub hard: Option<PathBuf>,
    /// Skip the hard cases.
    #[arg(long)]
    pub no_hard: bool,
    /// Random scenes (`--scene random:SEED`, seeds 0..N) rendered by both
    /// apps and the reference; default 100, 10 with --quick, 0 skips them.
    #[arg(long, value_name = "N")]
    pub random: Option<u64>,
}

pub fn run(args: &AccuracyArgs) -> anyhow::Result<()> {
    // Every input first: refusing one costs no sweep and creates nothing.
    let cases = if args.no_hard {
        Vec::new()
    } else {
        hard::cases(args.hard.as_deref())?
    };
    crate::apps::check_present()?;
    twinray_common::reference::image_io::prepare_output_dir("--out", &args.out)?;
    twinray_common::reference::image_io::prepare_output_dir("--out", &args.out.join("images"))?;
    let frames = if args.quick { 5 } else { 30 };
    let started = std::time::Instant::now();
    // SIGINT, SIGTERM and SIGHUP stop the run between two renders; what
    // finished is kept, the reports are written, and they say so.
    let stop = crate::interrupt::Stop::install()?;
    let mut stopped_in: Option<&'static str> = None;
    let mut step = |name: &'static str| {
        if stop.stopped() && stopped_in.is_none() {
            stopped_in = Some(name);
        }
        stopped_in.is_none()
    };
    let mut rows: Vec<Row> = Vec::new();
    for (scene_name, size, set) in sweeps::scenes(args.quick) {
        if !step("the sweeps") {
            break;
        }
        rows.extend(sweeps::run_scene(
            scene_name,
            size,
            &set,
            frames,
            &args.out,
            stop.flag(),
        )?);
    }
    let hard_rows = if step("the sweeps") && !args.no_hard {
        hard::run_all(&cases, &args.out, stop.flag())?
    } else {
        Vec::new()
    };
    let random_n = args.random.unwrap_or(if args.quick { 10 } else { 100 });
    let random_rows = if step("the hard cases") && random_n > 0 {
        let size = random::random_size(args.quick);
        eprintln!("twinray accuracy: {random_n} random scenes at {size} x (2 APIs + reference)");
        let r = random::run_random(random_n, size, &args.out, stop.flag())?;
        let how = stop
            .signal()
            .map(|(signal, _)| format!("interrupted by {signal} during the random scenes"));
        let csv = crate::csv::accuracy::random(&r)?;
        write(
            &args.out,
            "random.csv",
            crate::csv::marked(csv, how.as_deref()),
        )?;
        r
    } else {
        Vec::new()
    };
    step("the random scenes");
    let interrupted = stop.signal().map(|(signal, _)| {
        format!(
            "interrupted by {signal} during {}",
            stopped_in.unwrap_or("the report")
        )
    });
    let runs = (&mut rows[..], &hard_rows[..], &random_rows[..]);
    write_reports(args, runs, &cases, interrupted.as_deref(), started)?;
    eprintln!(
        "twinray accuracy: report: {}{}",
        args.out.join("report.md").display(),
        interrupted.as_deref().map_or(String::new(), |i| format!(
            " ({i}: the finished runs are kept)"
        ))
    );
    if let Some((_, code)) = stop.signal() {
        std::process::exit(code);
    }
    crate::failures::check(&failures(&rows, &hard_rows, &random_rows))
}

/// Every run that gave no result (an app's error, not an inaccurate image),
/// with its error line.
fn failures(
    rows: &[Row],
    hard_rows: &[HardRow],
    random_rows: &[RandomRow],
) -> Vec<(String, String)> {
    let mut failed = Vec::new();
    for r in rows {
        if let Err(e) = &r.result {
            let run = format!(
                "{} {} {}",
                r.scene,
                crate::apps::api_name(r.api),
                r.config.label()
            );
            failed.push((run, e.clone()));
        }
    }
    for r in hard_rows {
        if let Err(e) = &r.result {
            let run = format!(
                "hard case {} {} {}",
                r.case,
                r.strategy,
                crate::apps::api_name(r.api)
            );
            failed.push((run, e.clone()));
        }
    }
    for r in random_rows {
        if let Err(e) = &r.result {
            failed.push((format!("random:{} {}", r.seed, r.pair), e.clone()));
        }
    }
    failed
}

fn write(out: &Path, name: &str, text: String) -> anyhow::Result<()> {
    std::fs::write(out.join(name), text).with_context(|| format!("writing {name}"))
}

/// Marks the Pareto front (numerics that fail a hard case are off it), then
/// writes hard_cases.csv, accuracy.csv, the plots and report.md.
fn write_reports(
    args: &AccuracyArgs,
    (rows, hard_rows, random_rows): (&mut [Row], &[HardRow], &[RandomRow]),
    cases: &[HardCase],
    interrupted: Option<&str>,
    started: std::time::Instant,
) -> anyhow::Result<()> {
    let cpu = crate::report::cpu_model();
    write(
        &args.out,
        "hard_cases.csv",
        crate::csv::marked(crate::csv::accuracy::hard_cases(hard_rows)?, interrupted),
    )?;
    // With the hard cases known, numerics that fail any of them leave the front.
    // (The world-origin column is not a numerical choice of the sweeps: every
    // sweep runs with the local origin.)
    let unsound: Vec<Numerics> = hard::hard_strategies()
        .into_iter()
        .filter(|st| st.origin == OriginMode::Local)
        .filter(|st| {
            hard_rows
                .iter()
                .filter(|r| r.strategy == st.label)
                .any(|r| !r.passes())
        })
        .map(|st| st.numerics)
        .collect();
    pareto::mark_pareto(rows, &unsound);
    write(
        &args.out,
        "accuracy.csv",
        crate::csv::marked(crate::csv::accuracy::accuracy(rows)?, interrupted),
    )?;
    let mut plots = Vec::new();
    for (scene_name, _, _) in sweeps::scenes(args.quick) {
        let file = format!("accuracy-{scene_name}.svg");
        let these: Vec<&Row> = rows.iter().filter(|r| r.scene == scene_name).collect();
        plot::plot(&args.out.join(&file), scene_name, &these)
            .with_context(|| format!("plotting {file}"))?;
        plots.push(file);
    }
    let md = report::Report {
        quick: args.quick,
        out: &args.out,
        rows,
        hard_rows,
        cases,
        random: (!random_rows.is_empty()).then(|| (random_rows, random::random_size(args.quick))),
        plots: &plots,
        cpu: &cpu,
        secs: started.elapsed().as_secs_f64(),
        interrupted,
    }
    .markdown();
    write(&args.out, "report.md", md)
}
