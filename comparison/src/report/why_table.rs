//! The compare report's "Why the gaps" section and why.csv: one row per gap ×
//! experiment with the default figure, the figure with the experiment, the
//! share of the gap it closes and a verdict computed from those figures with
//! the thresholds below.

use crate::apps::api_name;
use crate::compare::runs::{Case, GapMeasure, Hold, Why, WhyRow};
use crate::csv::Num;
use anyhow::Context;
use std::fmt::Write as _;
use std::path::Path;
use twinray_common::value_name::ValueName;

/// A VK/GL ratio within this of 1 is no gap: by default, nothing to explain;
/// with the experiment, the gap is closed.
pub const RATIO_CLOSED: f64 = 0.03;
/// An experiment that moves the ratio by less than this share of itself, or
/// the disagreeing pixels by less than this share of them, has no effect
/// (timings spread by about 2 % from run to run).
pub const NO_EFFECT: f64 = 0.03;
/// Images that agree on at least this % of pixels within 1/255 have no gap
/// (the target for the two APIs).
pub const AGREEMENT_CLOSED: f64 = 99.99;

/// What an experiment did to a gap.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Verdict {
    /// The default is already within the threshold: nothing to explain.
    NoGap,
    Closes,
    NoEffect,
    /// It closes this share (0..1) of the gap, not all of it.
    Explains(f64),
    /// It opens the gap further by this share of it.
    Widens(f64),
    /// The other API is now the faster one, by more than the threshold.
    Reverses,
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match self {
            Verdict::NoGap => write!(f, "no gap to explain"),
            Verdict::Closes => write!(f, "closes the gap"),
            Verdict::NoEffect => write!(f, "no effect"),
            Verdict::Explains(s) => write!(f, "explains {:.0} %", s * 100.0),
            Verdict::Widens(s) => write!(f, "widens the gap by {:.0} %", s * 100.0),
            Verdict::Reverses => write!(f, "reverses the gap"),
        }
    }
}

/// The share of the gap `g0` that `g1` leaves closed: positive when it shrank.
fn share(g0: f64, g1: f64) -> Verdict {
    let s = (g0 - g1) / g0;
    if s > 0.0 {
        Verdict::Explains(s)
    } else {
        Verdict::Widens(-s)
    }
}

/// The verdict on a VK/GL ratio moved from `before` to `after`.
pub fn ratio_verdict(before: f64, after: f64) -> Verdict {
    let (g0, g1) = (before - 1.0, after - 1.0);
    if g0.abs() <= RATIO_CLOSED {
        Verdict::NoGap
    } else if g1.abs() <= RATIO_CLOSED {
        Verdict::Closes
    } else if (after / before - 1.0).abs() < NO_EFFECT {
        Verdict::NoEffect
    } else if g0.signum() != g1.signum() {
        Verdict::Reverses
    } else {
        share(g0.abs(), g1.abs())
    }
}

/// The verdict on the % of pixels within 1/255 moved from `before` to `after`.
pub fn agreement_verdict(before: f64, after: f64) -> Verdict {
    let (g0, g1) = (100.0 - before, 100.0 - after);
    if before >= AGREEMENT_CLOSED {
        Verdict::NoGap
    } else if after >= AGREEMENT_CLOSED {
        Verdict::Closes
    } else if (g1 - g0).abs() < NO_EFFECT * g0 {
        Verdict::NoEffect
    } else {
        share(g0, g1)
    }
}

/// The share of the gap closed, as a number (above 1 past closing; negative
/// when it widened); none where there is no gap to share.
fn closed_share(measure: GapMeasure, before: f64, after: f64) -> Option<f64> {
    if verdict(measure, before, after) == Verdict::NoGap {
        return None;
    }
    let (g0, g1) = match measure {
        GapMeasure::Ratio => (before - 1.0, after - 1.0),
        GapMeasure::Agreement => (100.0 - before, 100.0 - after),
    };
    (g0 != 0.0).then(|| (g0 - g1) / g0)
}

fn verdict(measure: GapMeasure, before: f64, after: f64) -> Verdict {
    match measure {
        GapMeasure::Ratio => ratio_verdict(before, after),
        GapMeasure::Agreement => agreement_verdict(before, after),
    }
}

/// What the case changes, in words: `vulkan: glslang`, `both: shared-bvh-stack`, `opengl-spirv`.
fn change(case: &Case) -> String {
    let names = |e: &[twinray_common::lab::experiment::Experiment]| {
        e.iter().map(|e| e.name()).collect::<Vec<_>>().join("+")
    };
    let (vk, gl) = (names(case.vulkan), names(case.opengl));
    let gl_api = api_name(case.opengl_api);
    match case.hold {
        Some(Hold::Workgroup(x, y)) => return format!("both at workgroup {x}x{y}"),
        Some(Hold::Set(kv)) => return format!("both with --set {kv}"),
        Some(Hold::Floor) => return "both less their empty frame's time".to_string(),
        Some(Hold::SecondFrame(None)) => {
            return "both: the second of two frames back to back".to_string()
        }
        Some(Hold::SecondFrame(Some((x, y)))) => {
            return format!("both at workgroup {x}x{y}: the second of two frames back to back")
        }
        None => {}
    }
    match (vk.is_empty(), gl.is_empty()) {
        (true, true) => format!("{gl_api} (as shipped)"),
        (false, true) => format!("vulkan: {vk}"),
        (true, false) => format!("{gl_api}: {gl}"),
        (false, false) if vk == gl => format!("both: {vk}"),
        (false, false) => format!("vulkan: {vk}; {gl_api}: {gl}"),
    }
}

#[derive(serde::Serialize, Default)]
struct CsvRow {
    gap: String,
    scene: String,
    accel: String,
    path: String,
    size: String,
    measure: String,
    experiment: String,
    clock: String,
    default_value: Option<Num>,
    experiment_value: Option<Num>,
    share_closed: Option<Num>,
    vulkan_ms_default: Option<Num>,
    opengl_ms_default: Option<Num>,
    vulkan_ms_experiment: Option<Num>,
    opengl_ms_experiment: Option<Num>,
    verdict: String,
    status: String,
}

fn measure_name(m: GapMeasure) -> &'static str {
    match m {
        GapMeasure::Ratio => "vk/gl time",
        GapMeasure::Agreement => "% pixels within 1/255",
    }
}

fn csv_row(r: &WhyRow) -> CsvRow {
    let g = r.case.gap;
    let fig = r.result.as_ref().ok();
    let ms = |i: usize| fig.and_then(|f| f.ms).map(|m| Num(m[i]));
    CsvRow {
        gap: g.name.into(),
        scene: g.scene.into(),
        accel: g.accel.name(),
        path: g.path.name(),
        size: r.size.to_string(),
        measure: measure_name(g.measure).into(),
        experiment: change(&r.case),
        clock: fig.map(|f| f.clock.to_string()).unwrap_or_default(),
        default_value: fig.map(|f| Num(f.before)),
        experiment_value: fig.map(|f| Num(f.after)),
        share_closed: fig.and_then(|f| closed_share(g.measure, f.before, f.after).map(Num)),
        vulkan_ms_default: ms(0),
        opengl_ms_default: ms(1),
        vulkan_ms_experiment: ms(2),
        opengl_ms_experiment: ms(3),
        verdict: fig
            .map(|f| verdict(g.measure, f.before, f.after).to_string())
            .unwrap_or_default(),
        status: match &r.result {
            Ok(_) => "ok".into(),
            Err(e) => e.clone(),
        },
    }
}

/// why.csv's text: a header even without rows.
pub fn csv(why: &Why) -> anyhow::Result<String> {
    crate::csv::to_string(why.rows.iter().map(csv_row))
}

/// The section's Markdown.
pub fn markdown(why: &Why) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "\n## Why the gaps\n\nAt each gap point the default and each experiment that isolates one candidate cause, \
         in fresh processes with the order alternating (`why.csv` has the times). Verdicts follow from the figures: \
         a VK/GL ratio within {:.0} % of 1 is no gap (by default) or a closed gap (with the experiment); an experiment \
         that moves the ratio, or the disagreeing pixels, by less than {:.0} % of itself has no effect; otherwise it \
         explains the share of the gap it closes. Images agree when at least {AGREEMENT_CLOSED} % of pixels are within 1/255. \
         Where both run less their empty frame's time, the times shown with it are each API's empty frame (the same size, \
         shader variant and workgroup, every ray missing) and its ratio is of the times less them. \
         Where both run a second frame straight after the first (`--experiment back-to-back`), the times shown with it \
         are that second frame's (two frames' time less one frame's, at the same workgroup), and its ratio is of them.\n",
        RATIO_CLOSED * 100.0,
        NO_EFFECT * 100.0
    );
    if why.software {
        let _ = writeln!(
            s,
            "Measured on a software driver: these ratios say nothing about GPUs (and the sizes are small).\n"
        );
    }
    let _ = writeln!(
        s,
        "| gap | point | experiment | default | with experiment | share closed | verdict |\n|---|---|---|---|---|---|---|"
    );
    for r in &why.rows {
        let g = r.case.gap;
        let point = format!(
            "{} {} {} {}",
            g.scene,
            r.size,
            g.accel.name(),
            g.path.name()
        );
        let cells = match &r.result {
            Ok(f) => {
                let value = |v: f64, ms: Option<(f64, f64)>| match (g.measure, ms) {
                    (GapMeasure::Ratio, Some((a, b))) => {
                        format!("{v:.3} ({} ms / {} ms, {})", sig(a), sig(b), f.clock)
                    }
                    (GapMeasure::Ratio, None) => format!("{v:.3}"),
                    (GapMeasure::Agreement, _) => format!("{v:.4} %"),
                };
                let ms = f.ms.map(|m| ((m[0], m[1]), (m[2], m[3])));
                format!(
                    "{} | {} | {} | {}",
                    value(f.before, ms.map(|m| m.0)),
                    value(f.after, ms.map(|m| m.1)),
                    closed_share(g.measure, f.before, f.after)
                        .map(|x| format!("{:.0} %", x * 100.0))
                        .unwrap_or_else(|| "–".into()),
                    verdict(g.measure, f.before, f.after)
                )
            }
            Err(e) => format!("– | – | – | {}", e.replace('|', "/")),
        };
        let _ = writeln!(
            s,
            "| {} | {point} | {} | {cells} |",
            g.name,
            change(&r.case)
        );
    }
    let _ = writeln!(s);
    s
}

/// Four significant digits, the way the report's tables print times.
fn sig(ms: f64) -> String {
    let digits = (3 - ms.abs().max(1e-9).log10().floor() as i32).clamp(0, 6) as usize;
    format!("{ms:.digits$}")
}

/// Writes why.csv (marked when the run was `interrupted`) and appends the
/// section to the written report.md.
pub fn write(
    out: &Path,
    why: &Why,
    interrupted: Option<crate::compare::runs::Interruption>,
) -> anyhow::Result<()> {
    let how = interrupted.map(|i| format!("interrupted by {} during {}", i.signal, i.step));
    let text = crate::csv::marked(csv(why)?, how.as_deref());
    std::fs::write(out.join("why.csv"), text).context("writing why.csv")?;
    let report = out.join("report.md");
    let mut text = std::fs::read_to_string(&report)
        .with_context(|| format!("reading '{}' back", report.display()))?;
    text.push_str(&markdown(why));
    std::fs::write(&report, text).with_context(|| format!("writing '{}'", report.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ratio_verdicts_follow_the_thresholds() {
        assert_eq!(ratio_verdict(1.02, 1.30), Verdict::NoGap);
        assert_eq!(ratio_verdict(0.98, 1.0), Verdict::NoGap);
        assert_eq!(ratio_verdict(1.20, 1.02), Verdict::Closes);
        assert_eq!(ratio_verdict(0.80, 0.975), Verdict::Closes);
        assert_eq!(ratio_verdict(1.20, 1.19), Verdict::NoEffect);
        assert_eq!(ratio_verdict(1.18, 1.10).to_string(), "explains 44 %");
        assert_eq!(ratio_verdict(0.75, 0.85).to_string(), "explains 40 %");
        assert_eq!(
            ratio_verdict(1.10, 1.30).to_string(),
            "widens the gap by 200 %"
        );
        assert_eq!(ratio_verdict(1.20, 0.90), Verdict::Reverses);
    }

    #[test]
    fn agreement_verdicts_follow_the_thresholds() {
        assert_eq!(agreement_verdict(99.995, 99.0), Verdict::NoGap);
        assert_eq!(agreement_verdict(99.9013, 99.995), Verdict::Closes);
        assert_eq!(agreement_verdict(99.9013, 99.9013), Verdict::NoEffect);
        assert_eq!(agreement_verdict(99.90, 99.95).to_string(), "explains 50 %");
        assert_eq!(
            agreement_verdict(99.9013, 99.7581).to_string(),
            "widens the gap by 145 %"
        );
    }

    #[test]
    fn share_closed_goes_past_one_when_the_gap_reverses() {
        let s = closed_share(GapMeasure::Ratio, 1.2, 0.9).unwrap();
        assert!((s - 1.5).abs() < 1e-12);
        assert_eq!(closed_share(GapMeasure::Agreement, 100.0, 100.0), None);
        assert_eq!(closed_share(GapMeasure::Ratio, 1.002, 0.97), None, "no gap");
    }
}
