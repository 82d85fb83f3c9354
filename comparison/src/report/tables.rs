//! report.md's tables: the machine, each experiment's sweep beside the
//! study's figures, the image agreement, and the points that failed.

use super::cells::{f, first_report, median_cell, paths_in, ratio, ratio_cell, report_of, sig3};
use crate::apps::api_name;
use crate::apps::Api;
use crate::compare::runs::{Agreement, Outcome, Point, Results, EXPERIMENTS};
use crate::compare::study::{self, StudyRow};
use std::fmt::Write as _;
use twinray_common::cli::RenderPath;
use twinray_common::report::RunReport;

/// Device, driver, API version and OS of each API, and the CPU.
pub fn machine(outcomes: &[Outcome], cpu: &str) -> String {
    let mut s = String::new();
    let any = |api: Api| first_report(outcomes, api);
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
    // The default workgroup depends on the app and the tree
    // (Api::default_workgroup), so the table says which shapes the compute
    // rows ran at.
    let workgroups = |api: Api| {
        let mut shapes: Vec<&str> = outcomes
            .iter()
            .filter(|o| o.api == api)
            .filter_map(|o| o.result.as_ref().ok()?.workgroup.as_deref())
            .collect();
        shapes.sort_unstable();
        shapes.dedup();
        if shapes.is_empty() {
            "–".to_string()
        } else {
            shapes.join(", ")
        }
    };
    let _ = writeln!(
        s,
        "| compute workgroup | {} | {} |",
        workgroups(Api::Vulkan),
        workgroups(Api::Opengl)
    );
    let _ = writeln!(s, "| CPU | {cpu} | {cpu} |\n");
    s
}

/// One section per experiment: its plot, then per path the study's times and
/// ours side by side with the Vulkan/OpenGL ratios.
pub fn experiments(outcomes: &[Outcome], study: &[StudyRow], plots: &[String]) -> String {
    let mut s = String::new();
    let paths = paths_in(outcomes);
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
            // Only where the runs counted their rays: older results keep their table.
            let has_rays = rows
                .iter()
                .any(|o| o.result.as_ref().is_ok_and(|r| r.grays_per_s.is_some()));
            let _ = writeln!(
            s,
            "| {} | study VK mean / median (s) | study GL mean / median (s) | study VK/GL | VK wall (ms) | GL wall (ms) | VK/GL wall | VK GPU (ms) | GL GPU (ms) | VK/GL GPU | frames VK/GL |{}{}",
            first.param_name,
            if has_spirv { " GL SPIR-V GPU (ms) | VK/GL-SPIR-V GPU |" } else { "" },
            if has_rays { " VK Grays/s | GL Grays/s |" } else { "" }
        );
            let _ = writeln!(
                s,
                "|---|---|---|---|---|---|---|---|---|---|---|{}{}",
                if has_spirv { "---|---|" } else { "" },
                if has_rays { "---|---|" } else { "" }
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
                let rate = |r: Option<&RunReport>| sig3(r.and_then(|r| r.grays_per_s));
                let rays = if has_rays {
                    format!(" {} | {} |", rate(vk), rate(gl))
                } else {
                    String::new()
                };
                let summary = |r: Option<&RunReport>, gpu: bool| {
                    r.and_then(|r| if gpu { r.gpu_ms } else { r.wall_ms })
                };
                let _ = writeln!(
                    s,
                    "| {v} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {}/{} |{extra}{rays}",
                    st.map(|x| format!("{:.5} / {:.5}", x.vulkan_mean_s, x.vulkan_median_s))
                        .unwrap_or_else(|| "–".into()),
                    st.map(|x| format!("{:.5} / {:.5}", x.opengl_mean_s, x.opengl_median_s))
                        .unwrap_or_else(|| "–".into()),
                    f(st.map(|x| x.vulkan_median_s / x.opengl_median_s), 2),
                    median_cell(summary(vk, false), 3),
                    median_cell(summary(gl, false), 3),
                    ratio_cell(summary(vk, false), summary(gl, false)),
                    median_cell(summary(vk, true), 3),
                    median_cell(summary(gl, true), 3),
                    ratio_cell(summary(vk, true), summary(gl, true)),
                    frames(vk),
                    frames(gl)
                );
            }
            let _ = writeln!(s);
        }
    }
    s
}

/// How far the APIs' images are from each other and from the f64 reference.
pub fn agreement(agreement: &[Agreement]) -> String {
    let mut s = String::new();
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
    s
}

/// Every point that failed, with why.
pub fn failures(outcomes: &[Outcome]) -> String {
    let mut s = String::new();
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
    s
}

/// "Points not run": every point × API × path of the plan that a signal left
/// out, so that a missing row is never read as a row that was not planned.
pub fn not_run(results: &Results) -> String {
    let mut s = String::new();
    let Some(i) = results.interrupted else {
        return s;
    };
    let done = |p: &Point, api: Api, path: RenderPath| {
        results.outcomes.iter().any(|o| {
            o.point.experiment == p.experiment
                && o.point.param_value == p.param_value
                && o.api == api
                && o.path == path
        })
    };
    let missing: Vec<String> = results
        .plan
        .points
        .iter()
        .flat_map(|p| results.runs.iter().map(move |&(api, path)| (p, api, path)))
        .filter(|&(p, api, path)| !done(p, api, path))
        .map(|(p, api, path)| {
            format!(
                "- {} {} {} {path}: not run ({})",
                p.experiment,
                p.param_value,
                api_name(api),
                i.signal
            )
        })
        .collect();
    if !missing.is_empty() {
        let _ = writeln!(s, "## Points not run\n\n{}\n", missing.join("\n"));
    }
    s
}
