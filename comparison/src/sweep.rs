//! `twinray sweep PLAN.toml --out DIR`: the laboratory's one measuring loop.
//! It owns running a plan (`plan` reads and checks it, `options` turns an
//! option set's values into command-line tokens): every cell (build ×
//! app × option set) in a fresh process per round, the cell order reversed on
//! odd rounds so that no build or app always runs first (warm caches, clocks
//! and thermals favour a fixed order); `sweep.jsonl`, each run's own `--json`
//! with the cell's labels, appended as each run ends; and `sweep.md`, the
//! median table and the ratios the plan asks for (`table`). The apps are
//! started, supervised and read exactly as `compare` does (`apps::run_json_with`,
//! `supervisor`), and the cells are those of compare's report (`report::cells`).
//! After the rounds come the plan's device-side steps (`steps`: shader
//! statistics, images against a reference or another build), and `env`
//! checks the plan's environment variables when it is read.

mod axes;
mod env;
mod options;
mod plan;
mod sets;
mod steps;
mod table;

use crate::apps::{self, Launch};
use anyhow::Context;
use std::io::Write;
use std::path::{Path, PathBuf};

#[derive(clap::Args, Debug)]
pub struct SweepArgs {
    /// The plan (TOML): builds, apps, option sets, rounds; see comparison/plans/example.toml.
    #[arg(value_name = "PLAN.toml", value_hint = clap::ValueHint::FilePath)]
    pub plan: PathBuf,
    /// The folder for sweep.jsonl and sweep.md.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Read and check the plan, print its cells, and run nothing (what CI
    /// does to every committed plan, so that a stale one fails there).
    #[arg(long)]
    pub dry_run: bool,
}

/// The order of round `round`'s runs, as indices into the cells: reversed
/// on odd rounds, so each build and app runs first as often as last.
pub fn round_order(cells: usize, round: u32) -> Vec<usize> {
    if round % 2 == 0 {
        (0..cells).collect()
    } else {
        (0..cells).rev().collect()
    }
}

pub fn run(args: &SweepArgs) -> anyhow::Result<()> {
    // The whole plan is checked first: a bad one creates nothing and runs nothing.
    let plan = plan::load(&args.plan)?;
    if args.dry_run {
        print_cells(&plan);
        return Ok(());
    }
    twinray_common::reference::image_io::prepare_output_dir("--out", &args.out)?;
    let stop = crate::interrupt::Stop::install()?;
    let started = std::time::Instant::now();
    let cells = plan.cells();
    let jsonl_path = args.out.join("sweep.jsonl");
    let mut jsonl = std::io::BufWriter::new(
        std::fs::File::create(&jsonl_path)
            .with_context(|| format!("creating {}", jsonl_path.display()))?,
    );
    let rounds = plan.warmup.saturating_add(plan.rounds);
    let total = (rounds as usize).saturating_mul(cells.len());
    let mut done = Vec::new();
    let mut failed = Vec::new();
    let mut seq = 0usize;
    'rounds: for round in 0..rounds {
        for (order, cell_index) in round_order(cells.len(), round).into_iter().enumerate() {
            if stop.stopped() {
                break 'rounds;
            }
            let cell = cells[cell_index];
            let (build, set) = (&plan.builds[cell.build], &plan.sets[cell.set]);
            // The set's arguments already carry the plan's frames and settle (`plan`).
            let args = &set.args;
            let launch = Launch {
                bin_dir: Some(build.dir.clone()),
                extra: set.extra.clone(),
                env: set.env.clone(),
            };
            eprintln!(
                "twinray sweep: run {}/{total}: build {}, {}, '{}', round {round}",
                seq + 1,
                build.name,
                apps::api_name(cell.app),
                set.name
            );
            let result = apps::run_json_with(cell.app, args, &launch);
            let mut line = serde_json::json!({
                "build": build.name,
                "app": apps::api_name(cell.app),
                "set": set.name,
                "options": set.options,
                "env": set.env.iter().cloned().collect::<std::collections::BTreeMap<_, _>>(),
                "round": round,
                "warmup": round < plan.warmup,
                "cell": cell_index,
                "order": order,
                "run": seq,
            });
            match result {
                // Not a result: the run that a signal cut short is left out.
                Err(e) if crate::supervisor::is_interrupted(&e) => break 'rounds,
                Ok(ran) => {
                    line["pid"] = ran.pid.into();
                    line["report"] = ran.json;
                    if round >= plan.warmup {
                        done.push(plan::Done {
                            cell: cell_index,
                            report: ran.report,
                        });
                    }
                }
                Err(e) => {
                    let message = format!("{e:#}");
                    eprintln!("twinray sweep: that run failed: {message}");
                    line["error"] = message.clone().into();
                    failed.push(message);
                }
            }
            append(&mut jsonl, &line, &jsonl_path)?;
            seq += 1;
        }
    }
    // The device-side steps follow the measured rounds, so that dumping and
    // writing images never share a GPU with a timed run.
    let mut write = |line: &serde_json::Value| append(&mut jsonl, line, &jsonl_path);
    let steps_md = steps::run(&plan, &cells, &args.out, &stop, &mut write, &mut failed)?;
    let interrupted = stop.signal();
    if let Some((signal, _)) = interrupted {
        let mark = serde_json::json!({ "interrupted": signal, "runs": seq, "of": total });
        append(&mut jsonl, &mark, &jsonl_path)?;
    }
    let md_path = args.out.join("sweep.md");
    let mut md = table::markdown(&plan, &cells, &done, interrupted.map(|(s, _)| s));
    md += &steps_md;
    if !failed.is_empty() {
        // A failed run is missing from its cell's rounds: say so beside the figures.
        md += &format!(
            "\n{} of {seq} runs failed and are left out; sweep.jsonl has each error.\n",
            failed.len()
        );
    }
    std::fs::write(&md_path, md).with_context(|| format!("writing {}", md_path.display()))?;
    eprintln!(
        "twinray sweep: {seq} of {total} runs in {:.0} s{}; table: {}",
        started.elapsed().as_secs_f64(),
        match interrupted {
            Some((signal, _)) => format!(" (interrupted by {signal}: the finished runs are kept)"),
            None => String::new(),
        },
        md_path.display()
    );
    if let Some((_, code)) = interrupted {
        std::process::exit(code);
    }
    match failed.as_slice() {
        [] => Ok(()),
        [first, ..] => Err(anyhow::anyhow!(
            "{} of {seq} runs failed (sweep.jsonl has each error); the first: {first}",
            failed.len()
        )),
    }
}

/// `--dry-run`'s output: one line a cell, build, app, set and its options.
fn print_cells(plan: &plan::Plan) {
    for cell in plan.cells() {
        let set = &plan.sets[cell.set];
        println!(
            "{}\t{}\t{}\t{}",
            plan.builds[cell.build].name,
            apps::api_name(cell.app),
            set.name,
            set.options.join(" ")
        );
    }
}

/// One line of sweep.jsonl, flushed at once: a run that ended is on disk
/// even if the sweep is then killed outright.
fn append(
    jsonl: &mut std::io::BufWriter<std::fs::File>,
    line: &serde_json::Value,
    path: &Path,
) -> anyhow::Result<()> {
    writeln!(jsonl, "{line}")
        .and_then(|_| jsonl.flush())
        .with_context(|| format!("writing {}", path.display()))
}

#[cfg(test)]
mod tests {
    #[test]
    fn odd_rounds_run_the_cells_backwards() {
        assert_eq!(super::round_order(3, 0), [0, 1, 2]);
        assert_eq!(super::round_order(3, 1), [2, 1, 0]);
        assert_eq!(super::round_order(3, 2), [0, 1, 2]);
    }
}
