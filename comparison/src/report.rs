//! The comparison's outputs: results.csv (one row per API × experiment × point),
//! report.md (the study's tables with ours beside them, ratios, machine info,
//! a summary derived from the numbers) and one SVG plot per experiment. Each
//! section of report.md is written by its own module, in the order it appears.

mod accel_table;
pub mod cells;
pub mod plots;
mod summary;
mod tables;
pub mod why_table;

pub use summary::{interrupted_note, interrupted_suffix, title};

use crate::compare::runs::{Outcome, Results, EXPERIMENTS};
use crate::compare::study::{self, StudyRow};
use anyhow::Context;
use std::path::Path;

/// The CPU's model name and thread count, for the machine table and the
/// CSVs (the drivers' reports do not say what a software rasteriser ran on).
pub fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines().find_map(|l| {
                l.strip_prefix("model name")
                    .map(|v| v.trim_start_matches([' ', '\t', ':']).to_string())
            })
        })
        .map(|m| {
            format!(
                "{m} ({} threads)",
                std::thread::available_parallelism()
                    .map(|n| n.get())
                    .unwrap_or(1)
            )
        })
        .unwrap_or_else(|| "unknown CPU".into())
}

/// Writes results.csv, the plots and report.md into `out`.
pub fn write_all(out: &Path, results: &Results) -> anyhow::Result<()> {
    let cpu = cpu_model();
    std::fs::write(
        out.join("results.csv"),
        crate::csv::marked(
            crate::csv::results::results(results.outcomes, &cpu)?,
            results
                .interrupted
                .map(|i| format!("interrupted by {} during {}", i.signal, i.step))
                .as_deref(),
        ),
    )
    .context("writing results.csv")?;
    let study = study::rows();
    let mut plots: Vec<String> = Vec::new();
    for exp in EXPERIMENTS {
        let rows: Vec<&Outcome> = results
            .outcomes
            .iter()
            .filter(|o| o.point.experiment == exp)
            .collect();
        if rows.is_empty() {
            continue;
        }
        let file = format!("{exp}.svg");
        plots::plot(&out.join(&file), exp, &rows, &study)
            .with_context(|| format!("plotting {file}"))?;
        plots.push(file);
        let file = format!("{exp}-grays.svg");
        if plots::plot_grays(&out.join(&file), exp, &rows)
            .with_context(|| format!("plotting {file}"))?
        {
            plots.push(file);
        }
    }
    if results.accel.iter().any(|r| r.result.is_ok()) {
        plots::plot_scaling(&out.join("scaling.svg"), results.outcomes, results.accel)
            .context("plotting scaling.svg")?;
        plots.push("scaling.svg".to_string());
    }
    std::fs::write(
        out.join("report.md"),
        markdown(results, &study, &cpu, &plots),
    )
    .context("writing report.md")?;
    Ok(())
}

/// report.md, section by section.
pub fn markdown(results: &Results, study: &[StudyRow], cpu: &str, plots: &[String]) -> String {
    [
        summary::headline(results.outcomes, study, results.interrupted),
        summary::by_path(results, study),
        tables::machine(results.outcomes, cpu),
        tables::experiments(results.outcomes, study, plots),
        accel_table::section(results.accel, plots),
        tables::agreement(results.agreement),
        tables::failures(results.outcomes),
        tables::not_run(results),
        "Full statistics (mean, median, min, max of wall and GPU time) are in `results.csv`.\n"
            .to_string(),
    ]
    .concat()
}
