//! The comparison's outputs: results.csv (one row per API × experiment × point),
//! report.md (the study's tables with ours beside them, ratios, machine info,
//! a summary derived from the numbers) and one SVG plot per experiment.

use crate::apps::Api;
use crate::compare::{api_name, AccelRun, Agreement, Outcome, Plan, EXPERIMENTS};
use crate::study::{self, StudyRow};
use anyhow::Context;
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::Path;
use twinray_common::cli::RenderPath;
use twinray_common::report::RunReport;

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

pub fn write_all(
    out: &Path,
    plan: &Plan,
    outcomes: &[Outcome],
    accel: &[AccelRun],
    agreement: &[Agreement],
    interrupted: bool,
) -> anyhow::Result<()> {
    let cpu = cpu_model();
    std::fs::write(out.join("results.csv"), csv(outcomes, &cpu)).context("writing results.csv")?;
    let study = study::rows();
    let mut plots: Vec<String> = Vec::new();
    for exp in EXPERIMENTS {
        let rows: Vec<&Outcome> = outcomes
            .iter()
            .filter(|o| o.point.experiment == exp)
            .collect();
        if rows.is_empty() {
            continue;
        }
        let file = format!("{exp}.svg");
        plot(&out.join(&file), exp, &rows, &study).with_context(|| format!("plotting {file}"))?;
        plots.push(file);
    }
    if accel.iter().any(|r| r.result.is_ok()) {
        plot_scaling(&out.join("scaling.svg"), outcomes, accel).context("plotting scaling.svg")?;
        plots.push("scaling.svg".to_string());
    }
    std::fs::write(
        out.join("report.md"),
        markdown(
            plan,
            outcomes,
            accel,
            agreement,
            &study,
            &cpu,
            &plots,
            interrupted,
        ),
    )
    .context("writing report.md")?;
    Ok(())
}

const CSV_HEADER: &str = "experiment,param_name,param_value,api,path,workgroup,status,frames,wall_mean_ms,wall_median_ms,wall_min_ms,wall_max_ms,gpu_mean_ms,gpu_median_ms,gpu_min_ms,gpu_max_ms,setup_ms,nonfinite_pixels,variant,width,height,device,driver,api_version,os,cpu";

fn q(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

pub fn csv(outcomes: &[Outcome], cpu: &str) -> String {
    let mut s = String::from(CSV_HEADER);
    s.push('\n');
    for o in outcomes {
        let p = &o.point;
        let workgroup = o
            .result
            .as_ref()
            .ok()
            .and_then(|r| r.workgroup.clone())
            .unwrap_or_default();
        let head = format!(
            "{},{},{},{},{},{workgroup}",
            p.experiment,
            p.param_name,
            p.param_value,
            api_name(o.api),
            o.path
        );
        match &o.result {
            Ok(r) => {
                let st = |x: Option<twinray_common::stats::Summary>| match x {
                    Some(x) => format!("{:.6},{:.6},{:.6},{:.6}", x.mean, x.median, x.min, x.max),
                    None => ",,,".into(),
                };
                let _ = writeln!(
                    s,
                    "{head},ok,{},{},{},{:.3},{},{},{},{},{},{},{},{},{}",
                    r.frames.len(),
                    st(r.wall_ms),
                    st(r.gpu_ms),
                    r.setup_ms,
                    r.nonfinite_pixels,
                    q(&r.variant),
                    r.width,
                    r.height,
                    q(&r.device),
                    q(&r.driver),
                    q(&r.api_version),
                    q(&r.os),
                    q(cpu)
                );
            }
            Err(e) => {
                let _ = writeln!(
                    s,
                    "{head},{},0,,,,,,,,,,,,{},{},,,,,{}",
                    q(&format!("failed: {e}")),
                    p.size.width,
                    p.size.height,
                    q(cpu)
                );
            }
        }
    }
    s
}

fn report_of<'a>(
    outcomes: &'a [&Outcome],
    value: &str,
    api: Api,
    path: RenderPath,
) -> Option<&'a RunReport> {
    outcomes
        .iter()
        .find(|o| o.point.param_value == value && o.api == api && o.path == path)
        .and_then(|o| o.result.as_ref().ok())
}

/// The paths that have at least one row, fragment first.
fn paths_in(outcomes: &[Outcome]) -> Vec<RenderPath> {
    [RenderPath::Fragment, RenderPath::Compute]
        .into_iter()
        .filter(|p| outcomes.iter().any(|o| o.path == *p))
        .collect()
}

/// The sphere-list crossover runs of one API as (primitives, brute-force ms,
/// BVH ms), fewest primitives first: every count measured both ways.
pub fn crossover(accel: &[AccelRun], api: Api) -> Vec<(usize, f64, f64)> {
    let ms = |r: &AccelRun| {
        r.result.as_ref().ok().and_then(|rep| {
            let t = rep.gpu_ms.or(rep.wall_ms)?.median;
            Some((rep.scene.spheres + rep.scene.triangles, t))
        })
    };
    let mut v: Vec<(usize, f64, f64)> = accel
        .iter()
        .filter(|r| r.api == api && r.scene == "spherelist" && r.config == "variant, brute force")
        .filter_map(|brute| {
            let bvh = accel.iter().find(|o| {
                o.api == api
                    && o.scene == brute.scene
                    && o.size == brute.size
                    && o.set == brute.set
                    && o.config == "variant, BVH"
            })?;
            let ((n, b), (_, t)) = (ms(brute)?, ms(bvh)?);
            Some((n, b, t))
        })
        .collect();
    v.sort_by_key(|x| x.0);
    v
}

/// "brute force faster up to N primitives, the BVH from M on" for `crossover` rows.
pub fn crossover_sentence(rows: &[(usize, f64, f64)]) -> String {
    if rows.is_empty() {
        return "no crossover runs".into();
    }
    let last_brute = rows.iter().filter(|r| r.1 <= r.2).map(|r| r.0).max();
    // The BVH counts as ahead from the smallest count after which it never loses.
    let first_bvh = rows
        .iter()
        .map(|r| r.0)
        .filter(|&n| rows.iter().filter(|r| r.0 >= n).all(|r| r.2 < r.1))
        .min();
    let counts = rows
        .iter()
        .map(|r| format!("{} ({:.3} / {:.3} ms)", r.0, r.1, r.2))
        .collect::<Vec<_>>()
        .join(", ");
    let verdict = match (last_brute, first_bvh) {
        (Some(b), Some(v)) => {
            format!("brute force is faster up to {b} primitives, the BVH from {v} on")
        }
        (None, Some(v)) => format!("the BVH is faster from the smallest count measured, {v}"),
        (Some(b), None) => format!("brute force is faster at every count measured, up to {b}"),
        (None, None) => "no count was measured both ways".into(),
    };
    format!("{verdict} (primitives (brute force / BVH): {counts}).")
}

fn ratio(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(a), Some(b)) if b > 0.0 => Some(a / b),
        _ => None,
    }
}

fn f(v: Option<f64>, digits: usize) -> String {
    v.map(|v| format!("{v:.digits$}"))
        .unwrap_or_else(|| "–".into())
}

fn range(v: &[f64]) -> Option<(f64, f64, f64)> {
    if v.is_empty() {
        return None;
    }
    let mut s = v.to_vec();
    s.sort_by(|a, b| a.total_cmp(b));
    Some((s[0], s[s.len() / 2], s[s.len() - 1]))
}

struct ExpRatios {
    wall: Vec<f64>,
    gpu: Vec<f64>,
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
        study: vec![],
        spirv: vec![],
    };
    for v in &values {
        let vk = report_of(&rows, v, Api::Vulkan, path);
        let gl = report_of(&rows, v, Api::Opengl, path);
        if let Some(x) = ratio(
            vk.and_then(|r| r.wall_ms).map(|s| s.median),
            gl.and_then(|r| r.wall_ms).map(|s| s.median),
        ) {
            r.wall.push(x);
        }
        if let Some(x) = ratio(
            vk.and_then(|r| r.gpu_ms).map(|s| s.median),
            gl.and_then(|r| r.gpu_ms).map(|s| s.median),
        ) {
            r.gpu.push(x);
        }
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

fn describe(label: &str, v: &[f64]) -> String {
    match range(v) {
        Some((lo, med, hi)) => {
            let who = if med > 1.02 {
                "OpenGL faster"
            } else if med < 0.98 {
                "Vulkan faster"
            } else {
                "a tie"
            };
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

pub fn markdown(
    plan: &Plan,
    outcomes: &[Outcome],
    accel: &[AccelRun],
    agreement: &[Agreement],
    study: &[StudyRow],
    cpu: &str,
    plots: &[String],
    interrupted: bool,
) -> String {
    let mut s = String::new();
    let any = |api: Api| {
        outcomes
            .iter()
            .find(|o| o.api == api)
            .and_then(|o| o.result.as_ref().ok())
    };
    let device = any(Api::Vulkan)
        .or(any(Api::Opengl))
        .map(|r| r.device.clone())
        .unwrap_or_else(|| "no device".into());
    let _ = writeln!(s, "# twinray compare — {device}\n");

    // The three-line summary: one line per experiment, computed from the rows below.
    let paths = paths_in(outcomes);
    let med = |v: &[f64]| range(v).map(|(_, m, _)| m);
    for exp in EXPERIMENTS {
        let mut parts = Vec::new();
        let mut why = String::new();
        for &path in &paths {
            let r = ratios(exp, path, outcomes, study);
            let (what, m) = match (med(&r.gpu), med(&r.wall)) {
                (Some(g), _) => ("GPU", g),
                (None, Some(w)) => ("wall", w),
                _ => continue,
            };
            let who = if m > 1.02 {
                "OpenGL faster"
            } else if m < 0.98 {
                "Vulkan faster"
            } else {
                "a tie"
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
            describe("wall", &r.wall),
            describe("GPU", &r.gpu),
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
    if interrupted {
        let _ = writeln!(
            s,
            "> Interrupted with Ctrl-C: only the points that finished are below.\n"
        );
    }
    let _ = writeln!(
        s,
        "Ratios are Vulkan time / OpenGL time (above 1: OpenGL faster). Wall time is one render-loop iteration \
         (submit + wait), as the study measured; GPU time comes from Vulkan timestamps and GL_TIME_ELAPSED queries \
         around the draw (fragment path) or the dispatch (compute path); the study measured the fragment path only. Preset: {}; up to {} frames per point (fewer for slow points, about {} s per app per point), \
         statistics over the last 30 (or the last half of shorter runs). Each API runs in its own process, the order \
         alternating from point to point. The study's times are seconds per frame; ours are milliseconds.\n",
        plan.preset, plan.frames, plan.seconds_per_point
    );

    let _ = writeln!(s, "## Machine\n\n| | Vulkan | OpenGL |\n|---|---|---|");
    let field =
        |api: Api, g: &dyn Fn(&RunReport) -> String| any(api).map(g).unwrap_or_else(|| "–".into());
    for (name, g) in [
        (
            "device",
            &(|r: &RunReport| r.device.clone()) as &dyn Fn(&RunReport) -> String,
        ),
        ("driver", &|r: &RunReport| r.driver.clone()),
        ("API version", &|r: &RunReport| r.api_version.clone()),
        ("OS", &|r: &RunReport| r.os.clone()),
    ] {
        let _ = writeln!(
            s,
            "| {name} | {} | {} |",
            field(Api::Vulkan, g),
            field(Api::Opengl, g)
        );
    }
    let _ = writeln!(s, "| CPU | {cpu} | {cpu} |\n");

    for exp in EXPERIMENTS {
        let rows: Vec<&Outcome> = outcomes
            .iter()
            .filter(|o| o.point.experiment == exp)
            .collect();
        if rows.is_empty() {
            continue;
        }
        let first = &rows[0].point;
        let title = match exp {
            "teapot" => "Teapot: 19,200 triangles, resolution sweep".to_string(),
            "box" => "Box: 30 triangles, mirror + glass sphere, resolution sweep".to_string(),
            _ => format!("Sphere list: extra spheres sweep at {}", first.size),
        };
        let _ = writeln!(s, "## {title}\n");
        if plots.contains(&format!("{exp}.svg")) {
            let _ = writeln!(s, "![{exp}]({exp}.svg)\n");
        }
        let all_rows = rows;
        for &path in &paths {
            let rows: Vec<&Outcome> = all_rows
                .iter()
                .copied()
                .filter(|o| o.path == path)
                .collect();
            if rows.is_empty() {
                continue;
            }
            if paths.len() > 1 {
                let _ = writeln!(s, "### {} path\n", path);
            }
            let has_spirv = rows.iter().any(|o| o.api == Api::OpenglSpirv);
            let _ = writeln!(
            s,
            "| {} | study VK mean / median (s) | study GL mean / median (s) | study VK/GL | VK wall (ms) | GL wall (ms) | VK/GL wall | VK GPU (ms) | GL GPU (ms) | VK/GL GPU | frames VK/GL |{}",
            first.param_name,
            if has_spirv { " GL SPIR-V GPU (ms) | VK/GL-SPIR-V GPU |" } else { "" }
        );
            let _ = writeln!(
                s,
                "|---|---|---|---|---|---|---|---|---|---|---|{}",
                if has_spirv { "---|---|" } else { "" }
            );
            let mut values: Vec<String> =
                rows.iter().map(|o| o.point.param_value.clone()).collect();
            values.dedup();
            for v in &values {
                let st = study::find(study, exp, v);
                let vk = report_of(&rows, v, Api::Vulkan, path);
                let gl = report_of(&rows, v, Api::Opengl, path);
                let med = |r: Option<&RunReport>, gpu: bool| {
                    r.and_then(|r| if gpu { r.gpu_ms } else { r.wall_ms })
                        .map(|x| x.median)
                };
                let frames = |r: Option<&RunReport>| {
                    r.map(|r| r.frames.len().to_string())
                        .unwrap_or_else(|| "failed".into())
                };
                let glspv = report_of(&rows, v, Api::OpenglSpirv, path);
                let extra = if has_spirv {
                    format!(
                        " {} | {} |",
                        f(med(glspv, true), 3),
                        f(ratio(med(vk, true), med(glspv, true)), 2)
                    )
                } else {
                    String::new()
                };
                let _ = writeln!(
                    s,
                    "| {v} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {}/{} |{extra}",
                    st.map(|x| format!("{:.5} / {:.5}", x.vulkan_mean_s, x.vulkan_median_s))
                        .unwrap_or_else(|| "–".into()),
                    st.map(|x| format!("{:.5} / {:.5}", x.opengl_mean_s, x.opengl_median_s))
                        .unwrap_or_else(|| "–".into()),
                    f(st.map(|x| x.vulkan_median_s / x.opengl_median_s), 2),
                    f(med(vk, false), 3),
                    f(med(gl, false), 3),
                    f(ratio(med(vk, false), med(gl, false)), 2),
                    f(med(vk, true), 3),
                    f(med(gl, true), 3),
                    f(ratio(med(vk, true), med(gl, true)), 2),
                    frames(vk),
                    frames(gl)
                );
            }
            let _ = writeln!(s);
        }
    }

    if !accel.is_empty() {
        let _ = writeln!(
            s,
            "## Model only what a scene needs\n\nThe same scenes with the all-features shader (`--generic`, brute force, as the study's \
             tracer), with the scene's own shader variant (features it lacks compiled out), with the one all-features source \
             specialised to the scene through specialization constants (`--specialize`: constant_id overrides fixed by naga's \
             process_overrides, so the driver sees constant branches and the deepest ray stack), and with the variant tracing through \
             a BVH (`--accel bvh`; binned SAH over spheres and triangles, built on the CPU). Median GPU ms (wall ms where the driver \
             has no GPU timer); speed-up against the generic brute-force shader of the same API.\n"
        );
        let _ = writeln!(s, "| scene | size | configuration | VK (ms) | GL (ms) | VK speed-up | GL speed-up | BVH nodes / bytes / build ms |\n|---|---|---|---|---|---|---|---|");
        let time = |r: &AccelRun| {
            r.result
                .as_ref()
                .ok()
                .and_then(|r| r.gpu_ms.or(r.wall_ms))
                .map(|x| x.median)
        };
        let mut keys: Vec<(&str, String, String, &str)> = Vec::new();
        for r in accel {
            let k = (r.scene, r.size.to_string(), r.set.join(" "), r.config);
            if !keys.contains(&k) {
                keys.push(k);
            }
        }
        for (scene, size, set, config) in &keys {
            let find = |api: Api, cfg: &str| {
                accel.iter().find(|r| {
                    r.scene == *scene
                        && r.size.to_string() == *size
                        && r.set.join(" ") == *set
                        && r.config == cfg
                        && r.api == api
                })
            };
            let vk = find(Api::Vulkan, config).and_then(time);
            let gl = find(Api::Opengl, config).and_then(time);
            let base = |api: Api| find(api, "generic, brute force").and_then(time);
            let bvh = find(Api::Vulkan, config)
                .and_then(|r| r.bvh)
                .map(|(n, b, ms)| format!("{n} / {:.1} KiB / {ms:.1}", b as f64 / 1024.0))
                .unwrap_or_else(|| "–".into());
            let label = if set.is_empty() {
                scene.to_string()
            } else {
                format!("{scene} ({set})")
            };
            let _ = writeln!(
                s,
                "| {label} | {size} | {config} | {} | {} | {} | {} | {bvh} |",
                f(vk, 3),
                f(gl, 3),
                ratio(base(Api::Vulkan), vk)
                    .map(|x| format!("{x:.1}×"))
                    .unwrap_or_else(|| "–".into()),
                ratio(base(Api::Opengl), gl)
                    .map(|x| format!("{x:.1}×"))
                    .unwrap_or_else(|| "–".into()),
            );
        }
        if plots.iter().any(|p| p == "scaling.svg") {
            let _ = writeln!(s, "\n![frame time against primitive count](scaling.svg)\n");
        }
        let _ = writeln!(
            s,
            "\n**Where `--accel auto` switches.** `auto` traces through a BVH from {} primitives on \
             (`AUTO_BVH_MIN_PRIMITIVES`, common/src/scene/accel.rs), one threshold for both APIs so that both always run the \
             same shader. It was set from the sphere-list crossover rows above, measured on an NVIDIA H200 and on Mesa \
             llvmpipe (comparison/results/). Here:",
            twinray_common::scene::accel::AUTO_BVH_MIN_PRIMITIVES
        );
        for api in [Api::Vulkan, Api::Opengl] {
            let _ = writeln!(
                s,
                "- {}: {}",
                api_name(api),
                crossover_sentence(&crossover(accel, api))
            );
        }
        let _ = writeln!(s);
        let failed: Vec<&AccelRun> = accel.iter().filter(|r| r.result.is_err()).collect();
        for r in failed {
            let _ = writeln!(
                s,
                "\n- {} {} {} {}: {}",
                r.scene,
                r.config,
                api_name(r.api),
                r.size,
                r.result.as_ref().err().map(String::as_str).unwrap_or("")
            );
        }
        let _ = writeln!(s);
    }

    if !agreement.is_empty() {
        let _ = writeln!(
            s,
            "## Image agreement\n\nOne frame per scene from each app (PNGs in `images/`) against each other and the f64 CPU \
             reference (spherelist with 100 extra spheres). Share of pixels within 1/255 on every channel, the largest \
             channel difference in 1/255 steps, and pixels that were NaN/Inf before quantisation.\n"
        );
        let with_paths = agreement.iter().any(|a| a.paths.is_some());
        if with_paths {
            let _ = writeln!(
                s,
                "The last two columns compare each API's compute-path image with its fragment-path image (`images/*-compute.png`).\n"
            );
        }
        let _ = writeln!(
            s,
            "| scene | size | VK vs GL | VK vs reference | GL vs reference | max abs VK/GL/ref | NaN |{}\n|---|---|---|---|---|---|---|{}",
            if with_paths { " VK compute vs fragment | GL compute vs fragment |" } else { "" },
            if with_paths { "---|---|" } else { "" }
        );
        for a in agreement {
            let paths = match &a.paths {
                Some(Ok(m)) => format!(
                    " {:.4}% (max {}) | {:.4}% (max {}) |",
                    100.0 * m[0].within_1(),
                    m[0].max_abs,
                    100.0 * m[1].within_1(),
                    m[1].max_abs
                ),
                Some(Err(e)) => format!(" failed: {} | |", e.replace('|', "/")),
                None if with_paths => " – | – |".into(),
                None => String::new(),
            };
            match &a.result {
                Ok(m) => {
                    let _ = writeln!(
                        s,
                        "| {} | {} | {:.4}% | {:.4}% | {:.4}% | {} / {} / {} | {} |{paths}",
                        a.scene,
                        a.size,
                        100.0 * m[0].within_1(),
                        100.0 * m[1].within_1(),
                        100.0 * m[2].within_1(),
                        m[0].max_abs,
                        m[1].max_abs,
                        m[2].max_abs,
                        m[0].nan_pixels
                    );
                }
                Err(e) => {
                    let _ = writeln!(
                        s,
                        "| {} | {} | failed: {} | | | | |",
                        a.scene,
                        a.size,
                        e.replace('|', "/")
                    );
                }
            }
        }
        let _ = writeln!(s);
    }

    let failures: Vec<&Outcome> = outcomes.iter().filter(|o| o.result.is_err()).collect();
    if !failures.is_empty() {
        let _ = writeln!(s, "## Failed points\n");
        for o in failures {
            let _ = writeln!(
                s,
                "- {} {} {} {}: {}",
                o.point.experiment,
                o.point.param_value,
                api_name(o.api),
                o.path,
                o.result.as_ref().err().map(String::as_str).unwrap_or("")
            );
        }
        let _ = writeln!(s);
    }
    let _ = writeln!(
        s,
        "Full statistics (mean, median, min, max of wall and GPU time) are in `results.csv`."
    );
    s
}

fn x_of(exp: &str, value: &str) -> f64 {
    if exp == "spherelist" {
        value.parse().unwrap_or(1.0)
    } else {
        value
            .split('x')
            .next()
            .and_then(|w| w.parse().ok())
            .unwrap_or(1.0)
    }
}

fn plot(path: &Path, exp: &str, rows: &[&Outcome], study: &[StudyRow]) -> anyhow::Result<()> {
    let mut series: Vec<(String, RGBColor, Vec<(f64, f64)>)> = Vec::new();
    // Fragment in the full colour, compute in a lighter shade of it.
    let colours = [
        (Api::Vulkan, RenderPath::Fragment, RGBColor(200, 30, 30)),
        (Api::Opengl, RenderPath::Fragment, RGBColor(30, 80, 200)),
        (
            Api::OpenglSpirv,
            RenderPath::Fragment,
            RGBColor(120, 60, 160),
        ),
        (Api::Vulkan, RenderPath::Compute, RGBColor(250, 120, 110)),
        (Api::Opengl, RenderPath::Compute, RGBColor(100, 170, 250)),
        (
            Api::OpenglSpirv,
            RenderPath::Compute,
            RGBColor(190, 140, 220),
        ),
    ];
    for (api, path, colour) in colours {
        for gpu in [false, true] {
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .filter(|o| o.api == api && o.path == path)
                .filter_map(|o| {
                    let r = o.result.as_ref().ok()?;
                    let v = if gpu { r.gpu_ms } else { r.wall_ms }?.median;
                    Some((x_of(exp, &o.point.param_value), v))
                })
                .collect();
            if !pts.is_empty() {
                series.push((
                    format!(
                        "ours {} {path} {}",
                        api_name(api),
                        if gpu { "GPU" } else { "wall" }
                    ),
                    colour,
                    pts,
                ));
            }
        }
    }
    let st: Vec<&StudyRow> = study.iter().filter(|r| r.experiment == exp).collect();
    series.push((
        "study vulkan".into(),
        RGBColor(240, 140, 40),
        st.iter()
            .map(|r| (x_of(exp, &r.param_value), r.vulkan_median_s * 1e3))
            .collect(),
    ));
    series.push((
        "study opengl".into(),
        RGBColor(40, 170, 170),
        st.iter()
            .map(|r| (x_of(exp, &r.param_value), r.opengl_median_s * 1e3))
            .collect(),
    ));

    let all: Vec<(f64, f64)> = series
        .iter()
        .flat_map(|s| s.2.iter().copied())
        .filter(|p| p.0 > 0.0 && p.1 > 0.0)
        .collect();
    let root = SVGBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let xlabel = if exp == "spherelist" {
        "extra spheres"
    } else {
        "image width = height (pixels)"
    };
    let caption = format!("{exp}: time per frame (log scale)");
    let mut chart = log_log_chart(&root, &caption, &all, xlabel, "milliseconds")?;
    for (name, colour, pts) in series {
        let dashed = name.contains("GPU");
        let style = if name.starts_with("study") {
            colour.stroke_width(1)
        } else {
            colour.stroke_width(2)
        };
        let mut pts = pts;
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        chart
            .draw_series(LineSeries::new(pts.clone(), style))?
            .label(name.clone())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        if dashed {
            chart.draw_series(
                pts.iter()
                    .map(|p| Cross::new(*p, 4, colour.stroke_width(1))),
            )?;
        } else {
            chart.draw_series(pts.iter().map(|p| Circle::new(*p, 3, colour.filled())))?;
        }
    }
    finish_chart(&mut chart, &root, SeriesLabelPosition::UpperLeft)
}

/// The chart every plot here draws on: log scales on both axes, padded around
/// `points` (which must not be empty), a caption and labelled axes.
pub fn log_log_chart<'a, 'b>(
    root: &'a DrawingArea<SVGBackend<'b>, plotters::coord::Shift>,
    caption: &str,
    points: &[(f64, f64)],
    x_desc: &str,
    y_desc: &str,
) -> anyhow::Result<ChartContext<'a, SVGBackend<'b>, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>> {
    let (xmin, xmax) = points
        .iter()
        .fold((f64::MAX, f64::MIN), |a, p| (a.0.min(p.0), a.1.max(p.0)));
    let (ymin, ymax) = points
        .iter()
        .fold((f64::MAX, f64::MIN), |a, p| (a.0.min(p.1), a.1.max(p.1)));
    let mut chart = ChartBuilder::on(root)
        .caption(caption, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d(
            (xmin * 0.8..xmax * 1.25).log_scale(),
            (ymin * 0.5..ymax * 2.0).log_scale(),
        )?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .draw()?;
    Ok(chart)
}

/// Draws the legend at `position` and writes the SVG.
pub fn finish_chart<'a, 'b: 'a>(
    chart: &mut ChartContext<'a, SVGBackend<'b>, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>,
    root: &DrawingArea<SVGBackend<'b>, plotters::coord::Shift>,
    position: SeriesLabelPosition,
) -> anyhow::Result<()> {
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(position)
        .draw()?;
    root.present()?;
    Ok(())
}

/// Primitives in a run (spheres + triangles), from its own report.
fn primitives(r: &RunReport) -> f64 {
    (r.scene.spheres + r.scene.triangles) as f64
}

/// Frame time against primitive count on log-log axes, brute force and BVH.
fn plot_scaling(path: &Path, outcomes: &[Outcome], accel: &[AccelRun]) -> anyhow::Result<()> {
    let ms = |r: &RunReport| r.gpu_ms.or(r.wall_ms).map(|x| x.median);
    let mut series: Vec<(String, RGBColor, Vec<(f64, f64)>)> = Vec::new();
    let palette = [
        (
            Api::Vulkan,
            [
                RGBColor(200, 30, 30),
                RGBColor(240, 130, 40),
                RGBColor(150, 0, 90),
            ],
        ),
        (
            Api::Opengl,
            [
                RGBColor(30, 80, 200),
                RGBColor(40, 170, 170),
                RGBColor(90, 40, 160),
            ],
        ),
    ];
    for (api, [colour, sphere_bvh, teapot_bvh]) in palette {
        // Brute force: the study's sphere-list sweep plus the crossover runs.
        let mut brute: Vec<(f64, f64)> = outcomes
            .iter()
            // The BVH runs are fragment-path runs: compare like with like.
            .filter(|o| {
                o.api == api && o.point.experiment == "spherelist" && o.path == RenderPath::Fragment
            })
            .filter_map(|o| o.result.as_ref().ok())
            .filter_map(|r| Some((primitives(r), ms(r)?)))
            .collect();
        brute.extend(
            accel
                .iter()
                .filter(|a| {
                    a.api == api && a.scene == "spherelist" && a.config == "variant, brute force"
                })
                .filter_map(|a| a.result.as_ref().ok())
                .filter_map(|r| Some((primitives(r), ms(r)?))),
        );
        let bvh = |scene: &str| -> Vec<(f64, f64)> {
            accel
                .iter()
                .filter(|a| a.api == api && a.scene == scene && a.config == "variant, BVH")
                .filter_map(|a| a.result.as_ref().ok())
                .filter_map(|r| Some((primitives(r), ms(r)?)))
                .collect()
        };
        series.push((
            format!("spherelist brute force, {}", api_name(api)),
            colour,
            brute,
        ));
        series.push((
            format!("spherelist BVH, {}", api_name(api)),
            sphere_bvh,
            bvh("spherelist"),
        ));
        series.push((
            format!("teapot BVH, {}", api_name(api)),
            teapot_bvh,
            bvh("teapot"),
        ));
    }
    series.retain(|s| !s.2.is_empty());
    let all: Vec<(f64, f64)> = series
        .iter()
        .flat_map(|s| s.2.iter().copied())
        .filter(|p| p.0 > 0.0 && p.1 > 0.0)
        .collect();
    if all.is_empty() {
        return Ok(());
    }
    let root = SVGBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = log_log_chart(
        &root,
        "frame time against primitives (log-log)",
        &all,
        "spheres + triangles",
        "milliseconds",
    )?;
    for (name, colour, mut pts) in series {
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        chart
            .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))?
            .label(name)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        chart.draw_series(pts.iter().map(|p| Circle::new(*p, 3, colour.filled())))?;
    }
    finish_chart(&mut chart, &root, SeriesLabelPosition::UpperLeft)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_crossover_is_where_the_bvh_stops_losing() {
        let rows = [
            (8, 0.2, 0.4),
            (32, 0.4, 0.5),
            (57, 0.6, 0.5),
            (107, 1.0, 1.1),
            (207, 2.0, 1.5),
            (507, 5.0, 1.6),
        ];
        let s = crossover_sentence(&rows);
        assert!(
            s.starts_with("brute force is faster up to 107 primitives, the BVH from 207 on"),
            "{s}"
        );
        assert!(crossover_sentence(&[]).contains("no crossover"));
        assert!(
            crossover_sentence(&[(8, 0.5, 0.1)]).contains("from the smallest count measured, 8")
        );
    }
    use crate::compare::Point;
    use twinray_common::cli::Size;

    fn outcome(api: Api, path: RenderPath, ms: f64) -> Outcome {
        let json = format!(
            r#"{{"api":"x","device":"d","driver":"v","api_version":"1","os":"o","scene":{{"name":"box","triangles":30,"spheres":2,"lights":1,"materials":3,"max_depth":5}},
               "variant":"v","width":8,"height":8,{}"frames":[{{"gpu_ms":{ms},"wall_ms":{ms}}}],"gpu_ms":null,"wall_ms":null,
               "nonfinite_pixels":0,"setup_ms":1.0,"validation_messages":0}}"#,
            if path == RenderPath::Compute {
                r#""path":"compute","workgroup":"16x8","#
            } else {
                ""
            }
        );
        let mut r: RunReport =
            serde_json::from_str(&json).expect("a report without `path` still parses");
        r.summarise();
        let point = Point {
            experiment: "box",
            param_name: "resolution",
            param_value: "8x8".into(),
            scene: "box",
            size: Size {
                width: 8,
                height: 8,
            },
            set: vec![],
            work: 1.0,
        };
        Outcome {
            point,
            api,
            path,
            result: Ok(r),
        }
    }

    #[test]
    fn csv_has_a_path_column_and_the_summary_compares_paths() {
        let rows = [
            outcome(Api::Vulkan, RenderPath::Fragment, 10.0),
            outcome(Api::Opengl, RenderPath::Fragment, 10.0),
            outcome(Api::Vulkan, RenderPath::Compute, 1.0),
            outcome(Api::Opengl, RenderPath::Compute, 2.0),
        ];
        let text = csv(&rows, "cpu");
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
        let body: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
        assert_eq!(body.len(), 4);
        assert_eq!(
            body.iter().map(|r| r[col("path")]).collect::<Vec<_>>(),
            ["fragment", "fragment", "compute", "compute"]
        );
        assert_eq!(body[2][col("workgroup")], "16x8");
        assert_eq!(body[0][col("workgroup")], "");
        assert!(body.iter().all(|r| r.len() == header.len()));
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
