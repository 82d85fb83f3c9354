//! report.md's opening: the title, one line per experiment saying who is
//! faster on each path and why, the summary by path with the two paths side
//! by side, and how the figures were measured.

use super::cells::{f, first_report, paths_in, range, ratio, ratio_interval, report_of, who};
use crate::apps::Api;
use crate::compare::runs::{Interruption, Outcome, Results, EXPERIMENTS};
use crate::compare::study::{self, StudyRow};
use std::fmt::Write as _;
use twinray_common::cli::RenderPath;
use twinray_common::report::RunReport;
use twinray_common::stats::Summary;

/// report.md's title line, naming the device: Vulkan's where a Vulkan run
/// succeeded, the driver's plain name ("NVIDIA H100 80GB HBM3"), else OpenGL's
/// renderer string, which carries the bus and CPU extensions ("…/PCIe/SSE2").
pub fn title(vulkan: Option<&str>, opengl: Option<&str>) -> String {
    format!(
        "# twinray compare — {}",
        vulkan.or(opengl).unwrap_or("no device")
    )
}

/// The title's tail for a run a signal stopped: read before any number below.
pub fn interrupted_suffix(interrupted: Option<Interruption>) -> String {
    match interrupted {
        Some(i) => format!(" (interrupted by {} during {})", i.signal, i.step),
        None => String::new(),
    }
}

/// The summary's line for a run a signal stopped: what is in and what is not.
pub fn interrupted_note(interrupted: Option<Interruption>) -> String {
    match interrupted {
        Some(i) => format!(
            "> Interrupted by {} during {}: only the runs that finished are below, and the steps \
             after it did not run.\n\n",
            i.signal, i.step
        ),
        None => String::new(),
    }
}

/// The title and the three-line summary: one line per experiment, computed
/// from the rows of the tables below it.
pub fn headline(
    outcomes: &[Outcome],
    study: &[StudyRow],
    interrupted: Option<Interruption>,
) -> String {
    let mut s = String::new();
    let device = |api| first_report(outcomes, api).map(|r| r.device.as_str());
    let _ = writeln!(
        s,
        "{}{}\n",
        title(device(Api::Vulkan), device(Api::Opengl)),
        interrupted_suffix(interrupted)
    );
    let _ = write!(s, "{}", interrupted_note(interrupted));

    let paths = paths_in(outcomes);
    let med = |v: &[f64]| range(v).map(|(_, m, _)| m);
    for exp in EXPERIMENTS {
        let mut parts = Vec::new();
        let mut why = String::new();
        for &path in &paths {
            let r = ratios(exp, path, outcomes, study);
            let (what, m, who) = match (med(&r.gpu), med(&r.wall)) {
                (Some(g), _) => ("GPU", g, verdict(&r.gpu, &r.gpu_iv)),
                (None, Some(w)) => ("wall", w, verdict(&r.wall, &r.wall_iv)),
                _ => continue,
            };
            parts.push(format!("{path} {m:.2}× ({what}, {who})"));
            if path == RenderPath::Fragment {
                if let Some(st) = med(&r.study) {
                    parts.push(format!("the study {st:.2}×"));
                }
                why = match (med(&r.gpu), med(&r.spirv), med(&r.wall)) {
                    (Some(g), Some(sp), _) if (g - 1.0).abs() >= 0.03 && (sp - 1.0).abs() < 0.03 => {
                        "OpenGL running Vulkan's very SPIR-V is as slow as Vulkan, so the gap is naga's SPIR-V through the driver's SPIR-V compiler, not the API".into()
                    }
                    (Some(g), Some(sp), _) if (g - 1.0).abs() >= 0.03 => format!(
                        "OpenGL running Vulkan's very SPIR-V closes {:.0} % of the gap: that part is the shader-compiler path, the rest stays with the API",
                        100.0 * ((g - sp) / (g - 1.0)).clamp(0.0, 1.0)
                    ),
                    (Some(g), _, Some(w)) if (w - g).abs() < 0.05 => {
                        "wall and GPU ratios agree: any gap is in executing the shader, not in per-frame API overhead".into()
                    }
                    (Some(_), _, Some(_)) => "the wall and GPU ratios differ: part of the gap is per-frame overhead outside the draw".into(),
                    _ => "this driver has no usable GPU timer: wall time only".into(),
                };
            }
        }
        if !parts.is_empty() {
            let _ = writeln!(
                s,
                "- **{exp}** — Vulkan/OpenGL: {}. Why: {why}.",
                parts.join(", ")
            );
        }
    }
    let _ = writeln!(s);
    s
}

/// "Summary by path": the ratios' ranges per experiment and path, the two
/// paths compared, and the paragraph on method.
pub fn by_path(results: &Results, study: &[StudyRow]) -> String {
    let Results { plan, outcomes, .. } = results;
    let mut s = String::new();
    let paths = paths_in(outcomes);
    let _ = writeln!(s, "## Summary by path\n");
    for exp in EXPERIMENTS {
        for &path in &paths {
            let r = ratios(exp, path, outcomes, study);
            if r.wall.is_empty() && r.gpu.is_empty() {
                continue;
            }
            let why = match (range(&r.wall), range(&r.gpu)) {
            (Some((_, w, _)), Some((_, g, _))) if (w - g).abs() < 0.05 => {
                "wall and GPU ratios agree, so the gap (if any) is in executing the shader, not in API overhead"
            }
            (Some((_, w, _)), Some((_, g, _))) if w > g => "Vulkan's wall ratio exceeds its GPU ratio: per-frame overhead outside the draw",
            (Some(_), Some(_)) => "OpenGL's per-frame overhead outside the draw exceeds Vulkan's",
            _ => "GPU timers unavailable on this driver: wall time only",
        };
            let spirv = match (range(&r.gpu), range(&r.spirv)) {
                (Some((_, g, _)), Some((_, sp, _))) => {
                    let verdict = if (sp - 1.0).abs() < 0.03 && (g - 1.0).abs() >= 0.03 {
                        "so the gap comes with naga's SPIR-V through the driver's SPIR-V compiler, not with the Vulkan API"
                    } else if (sp - g).abs() < 0.03 {
                        "so the gap is not the shader binary: it stays with the API"
                    } else {
                        "so part of the gap is the shader path and part the API"
                    };
                    format!(
                        " With OpenGL running the very same SPIR-V, {}, {verdict}.",
                        describe("Vulkan/OpenGL-SPIR-V GPU", &r.spirv)
                    )
                }
                _ => String::new(),
            };
            let _ = writeln!(
            s,
            "- **{exp}, {path} path**: Vulkan/OpenGL {}; {}; study (fragment) {}. {why}.{spirv}",
            describe_with("wall", &r.wall, &r.wall_iv),
            describe_with("GPU", &r.gpu, &r.gpu_iv),
            describe("", &r.study).trim_start()
        );
        }
    }
    if paths.len() == 2 {
        let _ = writeln!(s);
        for line in path_summary(outcomes, study) {
            let _ = writeln!(s, "{line}");
        }
        let _ = writeln!(
            s,
            "\nEach experiment's largest point on both paths, median GPU ms / wall ms:\n"
        );
        let _ = write!(s, "{}", four_numbers(outcomes));
    }
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "Ratios are Vulkan time / OpenGL time (above 1: OpenGL faster). Wall time is one render-loop iteration \
         (submit + wait), as the study measured; GPU time comes from Vulkan timestamps and GL_TIME_ELAPSED queries \
         around the draw (fragment path) or the dispatch (compute path); the study measured the fragment path only. Preset: {}; {}. \
         Medians carry their 95 % confidence interval (±% of the median; from the order statistics), ratios the interval \
         the two medians' intervals give; a ratio whose interval holds 1.00 is a tie. Each API runs in its own process, the order \
         alternating from point to point. The study's times are seconds per frame; ours are milliseconds.\n",
        plan.preset,
        plan.describe()
    );
    if let Some((runs, seconds, steps)) = &results.cost {
        let _ = writeln!(
            s,
            "This comparison made {runs} app runs, every step included, in {seconds:.0} s ({steps}).\n"
        );
    }
    s
}

struct ExpRatios {
    wall: Vec<f64>,
    gpu: Vec<f64>,
    /// Each ratio's interval from its two medians' 95 % intervals.
    wall_iv: Vec<Option<(f64, f64)>>,
    gpu_iv: Vec<Option<(f64, f64)>>,
    study: Vec<f64>,
    /// Vulkan GPU time / OpenGL-on-the-same-SPIR-V GPU time.
    spirv: Vec<f64>,
}

fn ratios(exp: &str, path: RenderPath, outcomes: &[Outcome], study: &[StudyRow]) -> ExpRatios {
    let rows: Vec<&Outcome> = outcomes
        .iter()
        .filter(|o| o.point.experiment == exp && o.path == path)
        .collect();
    let mut values: Vec<String> = rows.iter().map(|o| o.point.param_value.clone()).collect();
    values.dedup();
    let mut r = ExpRatios {
        wall: vec![],
        gpu: vec![],
        wall_iv: vec![],
        gpu_iv: vec![],
        study: vec![],
        spirv: vec![],
    };
    for v in &values {
        let vk = report_of(&rows, v, Api::Vulkan, path);
        let gl = report_of(&rows, v, Api::Opengl, path);
        let wall = |r: &RunReport| r.wall_ms;
        push_ratio((vk, gl), wall, &mut r.wall, &mut r.wall_iv);
        let gpu = |r: &RunReport| r.gpu_ms;
        push_ratio((vk, gl), gpu, &mut r.gpu, &mut r.gpu_iv);
        let glspv = report_of(&rows, v, Api::OpenglSpirv, path);
        if let Some(x) = ratio(
            vk.and_then(|r| r.gpu_ms).map(|s| s.median),
            glspv.and_then(|r| r.gpu_ms).map(|s| s.median),
        ) {
            r.spirv.push(x);
        }
        if let Some(s) = study::find(study, exp, v) {
            r.study.push(s.vulkan_median_s / s.opengl_median_s);
        }
    }
    r
}

/// Vulkan's median of `time` over OpenGL's, where both have one, pushed to
/// the ratios with its interval (from the two medians' intervals) beside it.
fn push_ratio(
    (vk, gl): (Option<&RunReport>, Option<&RunReport>),
    time: impl Fn(&RunReport) -> Option<Summary>,
    ratios: &mut Vec<f64>,
    intervals: &mut Vec<Option<(f64, f64)>>,
) {
    let (vk, gl) = (vk.and_then(&time), gl.and_then(&time));
    if let Some(x) = ratio(vk.map(|s| s.median), gl.map(|s| s.median)) {
        ratios.push(x);
        intervals.push(ratio_interval(vk, gl));
    }
}

/// Who is faster over a sweep: the verdict at its median point, a tie where
/// that point's interval holds 1.00 ([`who`]).
fn verdict(values: &[f64], intervals: &[Option<(f64, f64)>]) -> &'static str {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    match order.get(order.len() / 2) {
        Some(&i) => who(values[i], intervals.get(i).copied().flatten()),
        None => "–",
    }
}

fn describe(label: &str, v: &[f64]) -> String {
    describe_with(label, v, &[])
}

fn describe_with(label: &str, v: &[f64], intervals: &[Option<(f64, f64)>]) -> String {
    match range(v) {
        Some((lo, med, hi)) => {
            let who = verdict(v, intervals);
            format!("{label} {lo:.2}–{hi:.2}× (median {med:.2}×, {who})")
        }
        None => format!("{label} –"),
    }
}

/// How Vulkan vs OpenGL changes between the paths, one line per experiment:
/// the median Vulkan/OpenGL ratio on each path (GPU time where both paths have
/// it, else wall time), and each API's speed-up from fragment to compute.
fn path_summary(outcomes: &[Outcome], study: &[StudyRow]) -> Vec<String> {
    let mut lines = Vec::new();
    for exp in EXPERIMENTS {
        let frag = ratios(exp, RenderPath::Fragment, outcomes, study);
        let comp = ratios(exp, RenderPath::Compute, outcomes, study);
        let (what, f, c) = if !frag.gpu.is_empty() && !comp.gpu.is_empty() {
            ("GPU", range(&frag.gpu), range(&comp.gpu))
        } else {
            ("wall", range(&frag.wall), range(&comp.wall))
        };
        let (Some((_, f, _)), Some((_, c, _))) = (f, c) else {
            continue;
        };
        let verdict = if (c - f).abs() < 0.03 * f {
            "the API gap does not depend on the entry point".to_string()
        } else if c < f {
            format!(
                "Vulkan gains {:.0} % on OpenGL when the tracer runs as a compute shader",
                100.0 * (1.0 - c / f)
            )
        } else {
            format!(
                "Vulkan loses {:.0} % to OpenGL when the tracer runs as a compute shader",
                100.0 * (c / f - 1.0)
            )
        };
        // Each API's fragment time / compute time, median over the points.
        let rows: Vec<&Outcome> = outcomes
            .iter()
            .filter(|o| o.point.experiment == exp)
            .collect();
        let mut values: Vec<String> = rows.iter().map(|o| o.point.param_value.clone()).collect();
        values.dedup();
        let speedup = |api: Api| {
            let v: Vec<f64> = values
                .iter()
                .filter_map(|v| {
                    let t = |path| {
                        report_of(&rows, v, api, path)
                            .and_then(|r| if what == "GPU" { r.gpu_ms } else { r.wall_ms })
                            .map(|x| x.median)
                    };
                    ratio(t(RenderPath::Fragment), t(RenderPath::Compute))
                })
                .collect();
            range(&v)
                .map(|(_, m, _)| format!("{m:.2}×"))
                .unwrap_or_else(|| "–".into())
        };
        lines.push(format!(
            "- **{exp}, fragment → compute**: Vulkan/OpenGL {what} median {f:.2}× on the fragment path, {c:.2}× on the compute path: {verdict}. \
             Fragment time / compute time ({what}, median; above 1: compute faster): Vulkan {}, OpenGL {}.",
            speedup(Api::Vulkan),
            speedup(Api::Opengl)
        ));
    }
    lines
}

/// The four numbers per experiment at its largest point (teapot and box at
/// 1000² in the full preset): VK-frag, VK-comp, GL-frag, GL-comp, GPU and wall medians.
fn four_numbers(outcomes: &[Outcome]) -> String {
    let mut s = String::from(
        "| experiment | point | VK fragment | VK compute | GL fragment | GL compute |\n|---|---|---|---|---|---|\n",
    );
    let mut any = false;
    for exp in EXPERIMENTS {
        let rows: Vec<&Outcome> = outcomes
            .iter()
            .filter(|o| o.point.experiment == exp)
            .collect();
        let Some(last) = rows.last().map(|o| o.point.param_value.clone()) else {
            continue;
        };
        let cell = |api: Api, path: RenderPath| {
            let r = report_of(&rows, &last, api, path);
            let med = |gpu: bool| {
                r.and_then(|r| if gpu { r.gpu_ms } else { r.wall_ms })
                    .map(|x| x.median)
            };
            format!("{} / {}", f(med(true), 3), f(med(false), 3))
        };
        any = true;
        let _ = writeln!(
            s,
            "| {exp} | {last} | {} | {} | {} | {} |",
            cell(Api::Vulkan, RenderPath::Fragment),
            cell(Api::Vulkan, RenderPath::Compute),
            cell(Api::Opengl, RenderPath::Fragment),
            cell(Api::Opengl, RenderPath::Compute)
        );
    }
    if any {
        s
    } else {
        String::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compare::runs::test_outcome;

    #[test]
    fn the_summary_compares_paths() {
        let rows = [
            test_outcome(Api::Vulkan, RenderPath::Fragment, 10.0),
            test_outcome(Api::Opengl, RenderPath::Fragment, 10.0),
            test_outcome(Api::Vulkan, RenderPath::Compute, 1.0),
            test_outcome(Api::Opengl, RenderPath::Compute, 2.0),
        ];
        let summary = path_summary(&rows, &[]);
        assert_eq!(summary.len(), 1, "{summary:?}");
        assert!(
            summary[0].contains("1.00× on the fragment path, 0.50× on the compute path"),
            "{}",
            summary[0]
        );
        assert!(
            summary[0].contains("Vulkan 10.00×, OpenGL 5.00×"),
            "{}",
            summary[0]
        );
        let four = four_numbers(&rows);
        assert!(
            four.contains(
                "| box | 8x8 | 10.000 / 10.000 | 1.000 / 1.000 | 10.000 / 10.000 | 2.000 / 2.000 |"
            ),
            "{four}"
        );
    }
}
