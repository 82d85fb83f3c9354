//! `twinray ulp`'s report: ulp.md (the largest and mean ULP error per
//! operation for each API and path beside the CPU's IEEE f32, over all inputs
//! and over the random class alone; what was counted apart; failed runs) and
//! ulp.csv (one row per operation, run and class of input, with the worst
//! input's bits, so that any figure can be reproduced).

use super::inputs::CLASS_TEXT;
use super::measure::{ByClass, Stats};
use super::Run;
use crate::apps::api_name;
use crate::csv::Num;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;
use twinray_common::lab::experiment::UlpOp;
use twinray_common::reference::image_io::write_file;
use twinray_common::value_name::ValueName;

/// A ULP figure for a table: 0, three significant digits, or an exponent.
fn ulps(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v < 1000.0 {
        format!("{:.3}", v)
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    } else {
        format!("{v:.2e}")
    }
}

fn cell(s: Option<&Stats>) -> String {
    match s {
        Some(s) => match s.mean() {
            Some(mean) => format!("{} / {}", ulps(s.max), ulps(mean)),
            None => "none measured".into(),
        },
        None => "failed".into(),
    }
}

fn class<'a>(by: &'a ByClass, name: &str) -> Option<&'a Stats> {
    by.iter().find(|(c, _)| *c == name).map(|(_, s)| s)
}

/// The runs' columns, in order of first appearance: (api, path).
fn columns(runs: &[Run]) -> Vec<(crate::apps::Api, twinray_common::cli::RenderPath)> {
    let mut cols = Vec::new();
    for r in runs {
        if !cols.contains(&(r.api, r.path)) {
            cols.push((r.api, r.path));
        }
    }
    cols
}

fn table(out: &mut String, runs: &[Run], baseline: &[(UlpOp, ByClass)], class_name: &str) {
    let cols = columns(runs);
    out.push_str("| operation |");
    for (api, path) in &cols {
        let _ = write!(out, " {} {path} |", api_name(*api));
    }
    out.push_str(" CPU, IEEE f32 step by step |\n|---|");
    out.push_str(&"---|".repeat(cols.len() + 1));
    out.push('\n');
    for (op, base) in baseline {
        let _ = write!(out, "| `{}` |", op.name());
        for (api, path) in &cols {
            let run = runs
                .iter()
                .find(|r| r.op == *op && r.api == *api && r.path == *path);
            let stats = run.and_then(|r| r.stats.as_ref().ok());
            let _ = write!(out, " {} |", cell(stats.and_then(|s| class(s, class_name))));
        }
        let _ = writeln!(out, " {} |", cell(class(base, class_name)));
    }
}

fn machines(runs: &[Run]) -> String {
    let mut seen: Vec<String> = Vec::new();
    for r in runs.iter().filter(|r| r.stats.is_ok()) {
        let line = format!(
            "- {} {}: {} ({})",
            api_name(r.api),
            r.path,
            r.device,
            r.driver
        );
        if !seen.contains(&line) {
            seen.push(line);
        }
    }
    seen.join("\n")
}

fn markdown(runs: &[Run], baseline: &[(UlpOp, ByClass)], inputs: u32, seconds: f64) -> String {
    let mut s = format!(
        "# The GPU's f32 arithmetic: ULP error per operation\n\n\
         Written by `twinray ulp --inputs {inputs}` in {seconds:.0} s; how it measures: \
         the section \"The GPU's arithmetic\" of docs/architecture.md.\n\n{}\n\n\
         Each cell is *largest / mean* error in ULPs of f32 at the correctly rounded result, over \
         {inputs} inputs per operation and run (a vector operation's three components are three \
         results). 0.5 or less is correctly rounded. The last column is the same operation done \
         in IEEE f32 on the CPU, one rounding per step, by the spec's formula (no fused \
         multiply-add): what any f32 implementation of a composite operation may lose. \
         Flushed denormals, refract's other branch and non-finite mismatches are counted apart \
         (last table), not as ULPs. `bits` is the transport check: 0 means every result came \
         back bit for bit. Inputs: {CLASS_TEXT}; sqrt, inversesqrt and pow take |x|; pow's \
         exponent is in [1/8, 128) and refract's eta in [1/2, 2) whatever the class; vectors are \
         not normalised, so reflect and refract see any lengths. Where a result cancels \
         (cross, dot, reflect, refract, fma) one absolute rounding is many ULPs of a small \
         result: compare a driver's column with the CPU's.\n\n## All inputs\n\n",
        machines(runs)
    );
    table(&mut s, runs, baseline, "all");
    s.push_str("\n## Random inputs only (|x| in [2^-20, 2^21))\n\n");
    table(&mut s, runs, baseline, "random");
    s.push_str(
        "\n## Counted apart\n\nResults whose error is explained by a flushed denormal (input or \
         result), by the other side of refract's total-internal-reflection test, or that are \
         non-finite where the reference is not (or the reverse); runs with none are left out.\n\n\
         | operation | run | results | flushed | refract branch | non-finite |\n|---|---|---|---|---|---|\n",
    );
    for r in runs {
        let Ok(by) = &r.stats else { continue };
        let Some(all) = class(by, "all") else {
            continue;
        };
        if all.flushed + all.branch + all.nonfinite > 0 {
            let _ = writeln!(
                s,
                "| `{}` | {} {} | {} | {} | {} | {} |",
                r.op.name(),
                api_name(r.api),
                r.path,
                all.results,
                all.flushed,
                all.branch,
                all.nonfinite
            );
        }
    }
    let failed: Vec<&Run> = runs.iter().filter(|r| r.stats.is_err()).collect();
    if !failed.is_empty() {
        s.push_str("\n## Failed runs\n\n");
        for r in failed {
            let _ = writeln!(s, "- {}: {}", r.label(), crate::csv::status(&r.stats));
        }
    }
    s
}

#[derive(Serialize, Default)]
struct Row {
    op: String,
    api: String,
    path: String,
    device: String,
    driver: String,
    class: String,
    results: u64,
    measured: u64,
    max_ulp: Option<Num>,
    mean_ulp: Option<Num>,
    correctly_rounded: u64,
    flushed: u64,
    refract_branch: u64,
    nonfinite: u64,
    worst_input: Option<u32>,
    worst_component: Option<usize>,
    worst_operands: String,
    worst_result: String,
    worst_reference: Option<Num>,
    seconds: Option<Num>,
    status: String,
}

fn rows(op: UlpOp, who: [&str; 4], by: &ByClass, seconds: Option<f64>) -> Vec<Row> {
    by.iter()
        .map(|(c, s)| {
            let worst = s.worst.as_ref();
            Row {
                op: op.name(),
                api: who[0].into(),
                path: who[1].into(),
                device: who[2].into(),
                driver: who[3].into(),
                class: c.to_string(),
                results: s.results,
                measured: s.measured,
                max_ulp: s.mean().map(|_| Num(s.max)),
                mean_ulp: s.mean().map(Num),
                correctly_rounded: s.rounded,
                flushed: s.flushed,
                refract_branch: s.branch,
                nonfinite: s.nonfinite,
                worst_input: worst.map(|w| w.0),
                worst_component: worst.map(|w| w.1),
                worst_operands: worst.map_or(String::new(), |w| {
                    w.2.iter()
                        .map(|b| format!("{b:08x}"))
                        .collect::<Vec<_>>()
                        .join(" ")
                }),
                worst_result: worst.map_or(String::new(), |w| format!("{:08x}", w.3)),
                worst_reference: worst.map(|w| Num(w.4)),
                seconds: seconds.map(Num),
                status: "ok".into(),
            }
        })
        .collect()
}

fn csv(runs: &[Run], baseline: &[(UlpOp, ByClass)]) -> anyhow::Result<String> {
    let mut all = Vec::new();
    for r in runs {
        let path = r.path.to_string();
        let who = [api_name(r.api), path.as_str(), &r.device, &r.driver];
        match &r.stats {
            Ok(by) => all.extend(rows(r.op, who, by, Some(r.seconds))),
            Err(_) => all.push(Row {
                op: r.op.name(),
                api: who[0].into(),
                path: path.clone(),
                device: r.device.clone(),
                driver: r.driver.clone(),
                seconds: Some(Num(r.seconds)),
                status: crate::csv::status(&r.stats),
                ..Row::default()
            }),
        }
    }
    for (op, by) in baseline {
        all.extend(rows(*op, ["cpu", "ieee-f32", "CPU", "Rust f32"], by, None));
    }
    crate::csv::to_string(all)
}

/// Writes ulp.md and ulp.csv into `out`.
pub fn write(
    out: &Path,
    runs: &[Run],
    baseline: &[(UlpOp, ByClass)],
    (inputs, seconds, interrupted): (u32, f64, Option<&str>),
) -> anyhow::Result<()> {
    write_file(
        "--out",
        &out.join("ulp.csv"),
        crate::csv::marked(csv(runs, baseline)?, interrupted).as_bytes(),
    )?;
    let mut md = markdown(runs, baseline, inputs, seconds);
    if let Some(how) = interrupted {
        // Said in the title and again before the tables, as compare and accuracy say it.
        let (title, rest) = md.split_once('\n').unwrap_or((&md, ""));
        md = format!(
            "{title} ({how})\n\n> {}: the tables hold the runs that finished.\n{rest}",
            capital(how)
        );
    }
    write_file("--out", &out.join("ulp.md"), md.as_bytes())
}

fn capital(s: &str) -> String {
    let mut c = s.chars();
    c.next()
        .map_or(String::new(), |f| f.to_uppercase().chain(c).collect())
}
