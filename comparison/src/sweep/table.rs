//! sweep.md: one row per cell with its median GPU and wall times, and the
//! ratios the plan asks for. A cell's figure is its median round's: the
//! round whose median is the median of the rounds' medians (the lower of the
//! middle two for an even count), so that the interval shown is that run's
//! own 95 % interval, and the cells are written by compare's own
//! `median_cell` and `ratio_cell`.

use super::plan::{Cell, Done, Plan, Ratio};
use crate::apps::api_name;
use crate::report::cells::{median_cell, ratio_cell};
use twinray_common::report::RunReport;
use twinray_common::stats::Summary;

/// Which of a report's clocks.
#[derive(Clone, Copy)]
pub enum Clock {
    Gpu,
    Wall,
}

fn summary(report: &RunReport, clock: Clock) -> Option<Summary> {
    match clock {
        Clock::Gpu => report.gpu_ms,
        Clock::Wall => report.wall_ms,
    }
}

/// The median round of `cell` in `clock`, and how many rounds it had.
pub fn median_round(done: &[Done], cell: usize, clock: Clock) -> (Option<Summary>, usize) {
    let mut rounds: Vec<Summary> = done
        .iter()
        .filter(|d| d.cell == cell)
        .filter_map(|d| summary(&d.report, clock))
        .collect();
    rounds.sort_by(|a, b| a.median.total_cmp(&b.median));
    let n = rounds.len();
    let pick = (n > 0).then(|| rounds[(n - 1) / 2]);
    (pick, n)
}

/// Markdown cells never hold a bare `|`.
fn escape(s: &str) -> String {
    s.replace('|', "\\|")
}

pub fn markdown(plan: &Plan, cells: &[Cell], done: &[Done], interrupted: Option<&str>) -> String {
    let mut md = format!("# Sweep: {}", plan.file.display());
    if let Some(signal) = interrupted {
        md += &format!(" (interrupted by {signal}: the finished runs are kept)");
    }
    md += "\n\n";
    let builds: Vec<String> = plan
        .builds
        .iter()
        .map(|b| format!("{} (`{}`)", b.name, b.dir.display()))
        .collect();
    md += &format!(
        "Builds {}; {} round{}{}, frames {}{}.\n\n",
        builds.join(", "),
        plan.rounds,
        if plan.rounds == 1 { "" } else { "s" },
        match plan.warmup {
            0 => String::new(),
            w => format!(
                " after {w} warm-up round{} (left out)",
                if w == 1 { "" } else { "s" }
            ),
        },
        plan.frames
            .map_or("the apps' default".to_string(), |f| f.to_string()),
        plan.settle
            .map_or(String::new(), |p| format!(", settling to ±{p} %")),
    );
    md += "Milliseconds per frame. Each cell is its median round: the round whose median is the median of the rounds' medians (the lower of the middle two for an even count), with that round's own 95 % interval where it had frames enough for one.\n\n";
    md += "| build | app | set | rounds | GPU ms | wall ms |\n|---|---|---|---|---|---|\n";
    for (i, cell) in cells.iter().enumerate() {
        let (gpu, n) = median_round(done, i, Clock::Gpu);
        let (wall, n_wall) = median_round(done, i, Clock::Wall);
        md += &format!(
            "| {} | {} | {} | {} | {} | {} |\n",
            escape(&plan.builds[cell.build].name),
            api_name(cell.app),
            escape(&plan.sets[cell.set].name),
            n.max(n_wall),
            median_cell(gpu, 3),
            median_cell(wall, 3),
        );
    }
    if !plan.ratios.is_empty() {
        md += "\n## Ratios\n\nThe first's median over the second's, of the median rounds above, with the interval their 95 % intervals give (\"tie\" where it holds 1.00).\n\n";
        md += "| ratio | of | set | GPU | wall |\n|---|---|---|---|---|\n";
        let find = |build: usize, app: crate::apps::Api, set: usize| {
            cells
                .iter()
                .position(|c| c.build == build && c.app == app && c.set == set)
        };
        let both = |a: Option<usize>, b: Option<usize>, clock: Clock| {
            let get = |c: Option<usize>| c.and_then(|c| median_round(done, c, clock).0);
            ratio_cell(get(a), get(b))
        };
        for ratio in &plan.ratios {
            for set in 0..plan.sets.len() {
                let rows: Vec<(String, String, Option<usize>, Option<usize>)> = match *ratio {
                    Ratio::Apps(x, y) => plan
                        .builds
                        .iter()
                        .enumerate()
                        .map(|(b, build)| {
                            (
                                format!("{} / {}", api_name(x), api_name(y)),
                                format!("build {}", build.name),
                                find(b, x, set),
                                find(b, y, set),
                            )
                        })
                        .collect(),
                    Ratio::Builds(x, y) => plan
                        .apps
                        .iter()
                        .map(|&app| {
                            (
                                format!("{} / {}", plan.builds[x].name, plan.builds[y].name),
                                api_name(app).to_string(),
                                find(x, app, set),
                                find(y, app, set),
                            )
                        })
                        .collect(),
                };
                for (name, of, a, b) in rows {
                    md += &format!(
                        "| {} | {} | {} | {} | {} |\n",
                        escape(&name),
                        escape(&of),
                        escape(&plan.sets[set].name),
                        both(a, b, Clock::Gpu),
                        both(a, b, Clock::Wall),
                    );
                }
            }
        }
    }
    md
}
