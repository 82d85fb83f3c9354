//! `twinray summary DIR...`: the study's verdict in one table, read from the
//! results.csv of any number of `twinray compare` folders (ours under
//! `comparison/results/`, or a user's own). One row per machine and study
//! experiment: Vulkan/OpenGL on the fragment path (the study's) and on the
//! compute path, beside the study's own ratio. The README's opening table is
//! this command's output, and a test keeps the two equal.

use crate::compare::runs::EXPERIMENTS;
use crate::compare::study;
use crate::report::cells::{range, who};
use anyhow::Context;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use twinray_common::error::bad_input;

/// The columns of results.csv the table reads; older files lack the
/// intervals, and their ratios are then judged without them.
#[derive(serde::Deserialize)]
struct Row {
    experiment: String,
    param_value: String,
    api: String,
    #[serde(default)]
    path: String,
    status: String,
    device: String,
    wall_median_ms: Option<f64>,
    gpu_median_ms: Option<f64>,
    #[serde(default)]
    wall_median_lo_ms: Option<f64>,
    #[serde(default)]
    wall_median_hi_ms: Option<f64>,
    #[serde(default)]
    gpu_median_lo_ms: Option<f64>,
    #[serde(default)]
    gpu_median_hi_ms: Option<f64>,
}

/// One run's median and its interval in the clock a row is judged by.
#[derive(Clone, Copy)]
struct Timed {
    median: f64,
    interval: Option<(f64, f64)>,
}

impl Row {
    fn timed(&self, gpu: bool) -> Option<Timed> {
        let (m, lo, hi) = if gpu {
            (
                self.gpu_median_ms,
                self.gpu_median_lo_ms,
                self.gpu_median_hi_ms,
            )
        } else {
            (
                self.wall_median_ms,
                self.wall_median_lo_ms,
                self.wall_median_hi_ms,
            )
        };
        Some(Timed {
            median: m.filter(|&m| m > 0.0)?,
            interval: lo.zip(hi).filter(|(lo, _)| *lo > 0.0),
        })
    }
}

/// Where a machine's runs of one experiment on one path came from, and the
/// Vulkan and OpenGL rows by point.
#[derive(Default)]
struct Sweep {
    folder: PathBuf,
    /// param_value -> (Vulkan, OpenGL).
    points: BTreeMap<String, (Option<Row>, Option<Row>)>,
    /// The order the CSV lists the points in (the sweep's own order).
    order: Vec<String>,
}

/// (machine, experiment, path) -> its sweep.
type Sweeps = BTreeMap<(String, String, String), Sweep>;

/// The results.csv of `dir` (or `dir` itself when it is the file).
fn csv_of(dir: &Path) -> PathBuf {
    if dir.is_file() {
        dir.to_path_buf()
    } else {
        dir.join("results.csv")
    }
}

/// The machine a folder measured: its Vulkan device, else its OpenGL one.
fn read(dir: &Path, sweeps: &mut Sweeps, machines: &mut Vec<String>) -> anyhow::Result<()> {
    let file = csv_of(dir);
    if !file.is_file() {
        return Err(bad_input(format!(
            "'{}' holds no results.csv; give folders that `twinray compare` wrote",
            dir.display()
        )));
    }
    let mut reader =
        ::csv::Reader::from_path(&file).with_context(|| format!("reading '{}'", file.display()))?;
    let mut rows = Vec::new();
    for (i, row) in reader.deserialize::<Row>().enumerate() {
        rows.push(row.map_err(|e| {
            bad_input(format!(
                "'{}' row {}: not a `twinray compare` results.csv row ({e})",
                file.display(),
                i + 2
            ))
        })?);
    }
    let ok = |r: &&Row| r.status == "ok";
    let machine = rows
        .iter()
        .filter(ok)
        .find(|r| r.api == "vulkan")
        .or_else(|| rows.iter().filter(ok).find(|r| r.api == "opengl"))
        .map(|r| r.device.clone());
    let Some(machine) = machine else {
        // A folder whose every run failed, or an accel-only one: nothing to add.
        return Ok(());
    };
    if !machines.contains(&machine) {
        machines.push(machine.clone());
    }
    let mut seen: Vec<(String, String)> = Vec::new();
    for row in rows.into_iter().filter(|r| r.status == "ok") {
        if !EXPERIMENTS.contains(&row.experiment.as_str()) {
            continue;
        }
        let path = if row.path.is_empty() {
            "fragment".to_string()
        } else {
            row.path.clone()
        };
        let key = (machine.clone(), row.experiment.clone(), path.clone());
        let sweep = sweeps.entry(key.clone()).or_insert_with(|| Sweep {
            folder: dir.to_path_buf(),
            ..Sweep::default()
        });
        if sweep.folder != dir {
            return Err(bad_input(format!(
                "'{}' and '{}' both measure {} on the {path} path of {machine}; give one of them",
                sweep.folder.display(),
                dir.display(),
                row.experiment
            )));
        }
        if !seen.contains(&(row.experiment.clone(), path.clone())) {
            seen.push((row.experiment.clone(), path));
        }
        let value = row.param_value.clone();
        if !sweep.order.contains(&value) {
            sweep.order.push(value.clone());
        }
        let slot = sweep.points.entry(value).or_default();
        match row.api.as_str() {
            "vulkan" => slot.0 = Some(row),
            "opengl" => slot.1 = Some(row),
            _ => {}
        }
    }
    Ok(())
}

/// One cell: the median Vulkan/OpenGL ratio over the sweep's points, who is
/// faster there, and the range over the points.
fn cell(sweep: Option<&Sweep>, software: bool) -> String {
    let Some(sweep) = sweep else {
        return "–".into();
    };
    // GPU time where every point has it on a GPU; wall time otherwise
    // (a software driver's GPU timers are not reliable).
    let gpu = !software
        && sweep.points.values().all(|(vk, gl)| {
            [vk, gl]
                .iter()
                .all(|r| r.as_ref().is_some_and(|r| r.gpu_median_ms.is_some()))
        });
    let mut ratios: Vec<(f64, Option<(f64, f64)>)> = Vec::new();
    for value in &sweep.order {
        let (Some(vk), Some(gl)) = &sweep.points[value] else {
            continue;
        };
        let (Some(vk), Some(gl)) = (vk.timed(gpu), gl.timed(gpu)) else {
            continue;
        };
        let interval = vk
            .interval
            .zip(gl.interval)
            .map(|((vl, vh), (gl_lo, gh))| (vl / gh, vh / gl_lo));
        ratios.push((vk.median / gl.median, interval));
    }
    let values: Vec<f64> = ratios.iter().map(|r| r.0).collect();
    let Some((lo, med, hi)) = range(&values) else {
        return "–".into();
    };
    let median_point = ratios
        .iter()
        .find(|r| r.0 == med)
        .copied()
        .unwrap_or((med, None));
    let verdict = who(median_point.0, median_point.1);
    let clock = if gpu { "GPU" } else { "wall" };
    if ratios.len() == 1 {
        format!("**{med:.2}×** {verdict} ({clock})")
    } else {
        format!("**{med:.2}×** {verdict} ({lo:.2}–{hi:.2}, {clock})")
    }
}

/// "100x100–1000x1000", "1–10000 extra spheres": the sweep's span.
fn span(experiment: &str, sweeps: &[&Sweep]) -> String {
    let Some(order) = sweeps.iter().map(|s| &s.order).max_by_key(|o| o.len()) else {
        return experiment.to_string();
    };
    let (Some(first), Some(last)) = (order.first(), order.last()) else {
        return experiment.to_string();
    };
    let range = if first == last {
        first.clone()
    } else {
        format!("{first}–{last}")
    };
    if experiment == "spherelist" {
        format!("spherelist, {range} extra spheres")
    } else {
        format!("{experiment}, {range}")
    }
}

/// The study's Vulkan/OpenGL, the median over the points our sweep ran.
fn study_cell(experiment: &str, sweeps: &[&Sweep]) -> String {
    let rows = study::rows();
    let mut points: Vec<&String> = Vec::new();
    for p in sweeps.iter().flat_map(|s| &s.order) {
        if !points.contains(&p) {
            points.push(p);
        }
    }
    let values: Vec<f64> = points
        .iter()
        .filter_map(|p| study::find(&rows, experiment, p))
        .map(|r| r.vulkan_median_s / r.opengl_median_s)
        .collect();
    match range(&values) {
        Some((_, med, _)) => format!("{med:.2}×"),
        None => "–".into(),
    }
}

/// The table's Markdown, machines in the order the folders name them.
pub fn table(dirs: &[PathBuf]) -> anyhow::Result<String> {
    if dirs.is_empty() {
        return Err(bad_input(
            "summary needs at least one folder that `twinray compare` wrote",
        ));
    }
    let mut sweeps = Sweeps::new();
    let mut machines = Vec::new();
    for d in dirs {
        read(d, &mut sweeps, &mut machines)?;
    }
    if machines.is_empty() {
        return Err(bad_input(format!(
            "none of the {} folders holds a successful run of the study's experiments",
            dirs.len()
        )));
    }
    let mut s = String::from(
        "| machine | experiment | fragment path (the study's) | compute path | the study |\n|---|---|---|---|---|\n",
    );
    for m in &machines {
        let software = crate::apps::is_software(m);
        for exp in EXPERIMENTS {
            let get = |path: &str| sweeps.get(&(m.clone(), exp.to_string(), path.to_string()));
            let (frag, comp) = (get("fragment"), get("compute"));
            if frag.is_none() && comp.is_none() {
                continue;
            }
            let present: Vec<&Sweep> = frag.into_iter().chain(comp).collect();
            let _ = writeln!(
                s,
                "| {m} | {} | {} | {} | {} |",
                span(exp, &present),
                cell(frag, software),
                cell(comp, software),
                study_cell(exp, &present)
            );
        }
    }
    s.push_str(
        "\nVulkan time / OpenGL time, the median over each sweep's points (in brackets the range over the points); \
         above 1 OpenGL is faster. A tie: the median point's interval, from the two medians' 95 % intervals, holds 1.00 \
         (within 2 % for results measured before the intervals). GPU time on GPUs, wall time on a software driver; \
         the study measured the fragment path's wall time.\n",
    );
    Ok(s)
}

pub fn run(dirs: &[PathBuf]) -> anyhow::Result<()> {
    print!("{}", table(dirs)?);
    Ok(())
}
