//! The accuracy report.md, section by section: the method, where the default
//! stands, why it is the default, each scene's sweeps, the hard cases with the
//! local origin's before and after, and the random scenes.

use super::hard::{hard_strategies, HardRow, HardStrategy};
use super::pareto::{dominators, point, time_tie};
use super::random::{random_markdown, RandomRow};
use super::sweeps::Row;
use crate::apps::api_name;
use crate::apps::Api;
use std::fmt::Write as _;
use std::path::Path;
use twinray_common::cli::Size;
use twinray_common::scene::hard::{HardCase, WRONG_ABOVE};
use twinray_common::scene::numerics::Numerics;
use twinray_common::scene::OriginMode;
use twinray_common::scene::Scene;
use twinray_common::value_name::ValueName;

fn f3(v: f64) -> String {
    format!("{v:.3}")
}

/// Everything the accuracy report is written from.
pub struct Report<'a> {
    pub quick: bool,
    pub out: &'a Path,
    pub rows: &'a [Row],
    pub hard_rows: &'a [HardRow],
    pub cases: &'a [HardCase],
    /// The random scenes and their size (none with `--random 0`).
    pub random: Option<(&'a [RandomRow], Size)>,
    pub plots: &'a [String],
    pub cpu: &'a str,
    /// How long the whole run took.
    pub secs: f64,
    /// "interrupted by SIGTERM during the hard cases", where a signal stopped the run.
    pub interrupted: Option<&'a str>,
}

impl Report<'_> {
    /// report.md, section by section.
    pub fn markdown(&self) -> String {
        let mut s = self.intro();
        s += &summary(self.rows);
        s += &outside_mask(self.rows, self.hard_rows);
        s += &why_default(self.rows, self.hard_rows);
        s += &scene_tables(self.rows, self.plots);
        if !self.hard_rows.is_empty() {
            s += &hard_cases(self.hard_rows, self.cases);
        }
        if let Some((rows, size)) = self.random {
            s += &random_markdown(rows, size);
        }
        let _ = writeln!(
            s,
            "Every row is in `accuracy.csv` and `hard_cases.csv` (the random scenes' in `random.csv`); the images are in `images/`."
        );
        s
    }

    /// The title, the run, the default and how error and time are measured.
    fn intro(&self) -> String {
        let mut s = String::new();
        match self.interrupted {
            Some(i) => {
                let _ = writeln!(s, "# twinray accuracy — speed against error ({i})\n");
                let _ = writeln!(
                    s,
                    "**The run was {i}.** The tables hold the runs that finished; what the signal left out is missing from them.\n"
                );
            }
            None => {
                let _ = writeln!(s, "# twinray accuracy — speed against error\n");
            }
        }
        let _ = writeln!(
            s,
            "Preset: {}. CPU: {}. Run time: {:.0} s. Command: `twinray accuracy{} --out {}`.\n",
            if self.quick { "quick" } else { "full" },
            self.cpu,
            self.secs,
            if self.quick { " --quick" } else { "" },
            self.out.display()
        );
        let d = Numerics::default();
        let _ = writeln!(
            s,
            "**Default configuration**: offset `{}`, triangle test `{}`, sphere test `{}` (each scene's own max depth).\n",
            d.offset.name(),
            d.triangle.name(),
            d.sphere.name()
        );
        let _ = writeln!(
            s,
            "Error is measured against the *truth*: the f64 reference (`reference::render_truth`) with a 1e-8 offset \
             along the normal, watertight triangles, the stable sphere test, and max depth 16 — so the depth sweep shows \
             what stopping early costs and the numerical sweeps what f32 costs. RMSE and max abs are over 8-bit channels \
             (0..1 and 1/255 steps); `>1/255` and `wrong` are shares of pixels off by more than 1 and {WRONG_ABOVE} steps; FLIP is \
             the mean of NVIDIA's perceptual FLIP error (nv-flip 0.1.2, 67 pixels per degree). Time is the fastest frame's GPU \
             time where the driver has timers, else its wall time (submit + wait); the minimum, because other load on a \
             shared machine only adds time. Every sweep changes one knob from the default; ★ marks the Pareto front of \
             (time, RMSE) per scene and API, ◆ the default. Configurations that compile to the same shader on a scene \
             (a max depth that no mirror or glass can use) are one point, marked = when it is the default's, and a point's \
             time is the median of its timings; the default runs three times (first, in the middle and last), and the \
             spread of its timings (at least 1%) is the time tie: times closer than what the same work scatters from run \
             to run count as equal, as do RMSE within 1%. Numerical choices that render any hard case (below) outside its \
             tolerance are not candidates for the front: correctness on the hard cases is a constraint, not a cost to \
             trade.\n"
        );
        s
    }
}

/// Every scene's default, and every hard case's worst strategy, over all
/// pixels and outside the truth's unsettled mask: the pixels whose f64 colour
/// moves by more than 8/255 when the primary ray turns by 4 f32 ULPs. No f32
/// tracer can be held to those; outside them, every figure is a bound a
/// regression would break.
fn outside_mask(rows: &[Row], hard_rows: &[HardRow]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "## Outside the unsettled mask

The truth's unsettled mask holds the pixels whose f64 colour moves by more than \
         8/255 when the primary ray turns by 4 f32 ULPs (an edge on a pixel centre, a grazing hit): no f32 tracer can \
         settle them, so each error is given over all pixels and over the rest.\n\n\
         | scene | API | mask pixels | max abs: all / outside | >8/255: all / outside |\n|---|---|---|---|---|"
    );
    for r in rows.iter().filter(|r| r.is_default) {
        if let Some(e) = r.error() {
            let _ = writeln!(
                s,
                "| {} ({}) | {} | {} | {} / {} | {:.4}% / {:.4}% |",
                r.scene,
                r.size,
                api_name(r.api),
                e.outside.mask_pixels,
                e.max_abs,
                e.outside.max_abs,
                100.0 * e.wrong,
                100.0 * e.outside.above_8
            );
        }
    }
    if !hard_rows.is_empty() {
        let _ = writeln!(
            s,
            "\nHard cases, the largest share of wrong pixels (off by more than {WRONG_ABOVE}/255) over every strategy and API:\n\n\
             | case | mask pixels | wrong: all / outside |\n|---|---|---|"
        );
        let mut names: Vec<&str> = hard_rows.iter().map(|r| r.case.as_str()).collect();
        names.dedup();
        for name in names {
            let these: Vec<&HardRow> = hard_rows.iter().filter(|r| r.case == name).collect();
            let all = these
                .iter()
                .filter_map(|r| r.result.as_ref().ok().map(|x| x.0))
                .fold(None, |m: Option<f64>, w| Some(m.map_or(w, |m| m.max(w))));
            let outs: Vec<_> = these.iter().filter_map(|r| r.outside).collect();
            let out = outs
                .iter()
                .map(|o| o.above_8)
                .fold(None, |m: Option<f64>, w| Some(m.map_or(w, |m| m.max(w))));
            let mask = outs
                .first()
                .map_or("–".into(), |o| o.mask_pixels.to_string());
            let pct = |v: Option<f64>| v.map_or("–".into(), |v| format!("{:.3}%", 100.0 * v));
            let _ = writeln!(s, "| {name} | {mask} | {} / {} |", pct(all), pct(out));
        }
    }
    let _ = writeln!(s);
    s
}

/// Where the default stands per scene and API: its time and error against the
/// cheapest configuration's.
fn summary(rows: &[Row]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "## Summary\n");
    for api in [Api::Vulkan, Api::Opengl] {
        for scene in rows
            .iter()
            .map(|r| r.scene.clone())
            .collect::<std::collections::BTreeSet<_>>()
        {
            let these: Vec<usize> = (0..rows.len())
                .filter(|&i| rows[i].scene == scene && rows[i].api == api && rows[i].result.is_ok())
                .collect();
            let Some(def) = these.iter().copied().find(|&i| rows[i].is_default) else {
                continue;
            };
            let Some(cheap) = these.iter().copied().min_by(|&a, &b| {
                let t = |i| point(rows, i).map_or(f64::MAX, |p| p.0);
                t(a).total_cmp(&t(b))
            }) else {
                continue;
            };
            let (dt, de) = point(rows, def).unwrap_or((f64::NAN, f64::NAN));
            let (ct, ce) = point(rows, cheap).unwrap_or((f64::NAN, f64::NAN));
            let (tie, times) = time_tie(rows, &scene, api);
            let _ = writeln!(
                s,
                "- {scene}, {}: default {} ms (median of {}: {}; time tie ±{:.1}%), RMSE {:.5}{}; cheapest ({}) {} ms, RMSE {:.5}: the default costs {:.2}×.",
                api_name(api),
                f3(dt),
                times.len(),
                times.iter().map(|t| f3(*t)).collect::<Vec<_>>().join(", "),
                100.0 * tie,
                de,
                if rows[def].pareto { " (on the Pareto front)" } else { " (**not** on the Pareto front)" },
                if rows[cheap].program == rows[def].program { "the default's own shader".to_string() } else { rows[cheap].config.label() },
                f3(ct),
                ce,
                dt / ct
            );
        }
    }
    let _ = writeln!(s);

    s
}

/// Why the numerical default is the default: which strategies pass the hard
/// cases, and whether anything dominates the default.
fn why_default(rows: &[Row], hard_rows: &[HardRow]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "## Why this default\n");
    let _ = writeln!(
        s,
        "The numerical knobs decide correctness, the depth decides cost: every numerical choice costs about the same \
         per ray (the sweeps below differ by noise except where noted), so the default takes the choice that keeps the \
         hard cases right, and each scene keeps its own max depth.\n"
    );
    if !hard_rows.is_empty() {
        for HardStrategy { label, .. } in hard_strategies() {
            let these: Vec<&HardRow> = hard_rows.iter().filter(|r| r.strategy == label).collect();
            let ok = these.iter().filter(|r| r.passes()).count();
            let failed: Vec<String> = these
                .iter()
                .filter(|r| !r.passes())
                .map(|r| r.case.clone())
                .fold(Vec::new(), |mut v, c| {
                    if !v.contains(&c) {
                        v.push(c);
                    }
                    v
                });
            let _ = writeln!(
                s,
                "- `{label}`: {ok} of {} hard-case renders within tolerance{}",
                these.len(),
                if failed.is_empty() {
                    String::new()
                } else {
                    format!("; fails {}", failed.join(", "))
                }
            );
        }
        let _ = writeln!(s);
    }
    for (i, r) in rows
        .iter()
        .enumerate()
        .filter(|(_, r)| r.is_default && r.result.is_ok())
    {
        let by: Vec<String> = dominators(rows, i)
            .into_iter()
            .map(|j| rows[j].config.label())
            .collect();
        let _ = writeln!(
            s,
            "- {} {}: {}",
            r.scene,
            api_name(r.api),
            if by.is_empty() {
                "the default is on the Pareto front".to_string()
            } else {
                format!("the default is dominated by {}", by.join("; "))
            }
        );
    }
    let _ = writeln!(
        s,
        "\nWhere a configuration with a *smaller max depth* dominates, the scene simply needs fewer bounces than it allows \
         (no mirror or glass in view beyond that depth): max depth is a per-scene setting, not part of the numerical \
         default. On a shared software driver the time tie is wide and the timings scatter more than it says; the GPU \
         report is the one to read for speed.\n"
    );

    s
}

/// One section per scene: its plot and every configuration's row.
fn scene_tables(rows: &[Row], plots: &[String]) -> String {
    let mut s = String::new();
    for scene in rows
        .iter()
        .map(|r| r.scene.clone())
        .collect::<Vec<_>>()
        .iter()
        .fold(Vec::<String>::new(), |mut v, x| {
            if !v.contains(x) {
                v.push(x.clone());
            }
            v
        })
    {
        let these: Vec<&Row> = rows.iter().filter(|r| r.scene == scene).collect();
        let size = these
            .first()
            .map(|r| r.size.to_string())
            .unwrap_or_default();
        let _ = writeln!(s, "## {scene} ({size})\n");
        if let Some(p) = plots.iter().find(|p| p.contains(&format!("-{scene}."))) {
            let _ = writeln!(s, "![{scene}]({p})\n");
        }
        let _ = writeln!(s, "| sweep | max depth | offset | triangle | sphere | API | GPU ms (min) | wall ms (min) | RMSE | max abs | >1/255 | wrong | FLIP | NaN | |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
        for r in these {
            let n = &r.config.numerics;
            let same = !r.is_default
                && rows.iter().any(|d| {
                    d.is_default && d.scene == r.scene && d.api == r.api && d.program == r.program
                });
            let mark = format!(
                "{}{}",
                if r.pareto { "★" } else { "" },
                if r.is_default {
                    "◆"
                } else if same {
                    "="
                } else {
                    ""
                }
            );
            let head = format!(
                "| {} | {} | {} | {} | {} | {} |",
                r.sweeps.join(", "),
                r.config.max_depth,
                n.offset.name(),
                n.triangle.name(),
                n.sphere.name(),
                api_name(r.api)
            );
            match &r.result {
                Ok((g, w, e, nan)) => {
                    let _ = writeln!(
                        s,
                        "{head} {} | {} | {:.5} | {} | {:.2}% | {:.2}% | {} | {} | {mark} |",
                        g.map(f3).unwrap_or_else(|| "–".into()),
                        f3(*w),
                        e.rmse,
                        e.max_abs,
                        100.0 * e.above_1,
                        100.0 * e.wrong,
                        e.flip
                            .map(|f| format!("{f:.4}"))
                            .unwrap_or_else(|| "–".into()),
                        nan
                    );
                }
                Err(e) => {
                    let _ = writeln!(
                        s,
                        "{head} failed: {} | | | | | | | | |",
                        e.replace('|', "/")
                    );
                }
            }
        }
        let _ = writeln!(s);
    }

    s
}

/// The hard-case table, the local origin's before and after, and what each
/// strategy costs.
fn hard_cases(hard_rows: &[HardRow], cases: &[HardCase]) -> String {
    let mut s = String::new();
    let strategies: Vec<String> = hard_strategies().into_iter().map(|st| st.label).collect();
    let _ = writeln!(
        s,
        "## Hard cases (scenes/hard/, 64x64)\n\nShare of wrong pixels (off by more than {WRONG_ABOVE}/255 against the truth) per case, \
         strategy and API (Vulkan / OpenGL); crack pixels in brackets where the case counts them. **Bold**: above the case's \
         tolerance. The default must pass every case (tests/tests/hard_cases.rs checks it).\n"
    );
    let _ = write!(s, "| case | tolerance |");
    for st in &strategies {
        let _ = write!(s, " {st} |");
    }
    let _ = writeln!(s, "\n|---|---|{}", "---|".repeat(strategies.len()));
    for case in cases {
        let _ = write!(s, "| {} | {}% |", case.name, case.tolerance_pct);
        for st in &strategies {
            let cell: Vec<String> = [Api::Vulkan, Api::Opengl]
                .iter()
                .map(|api| {
                    match hard_rows
                        .iter()
                        .find(|r| r.case == case.name && &r.strategy == st && r.api == *api)
                        .map(|r| &r.result)
                    {
                        Some(Ok((w, c, _, nan))) => {
                            let v = format!("{:.2}", 100.0 * w);
                            let v = if 100.0 * w > case.tolerance_pct {
                                format!("**{v}**")
                            } else {
                                v
                            };
                            let c = c.map(|c| format!(" [{c}]")).unwrap_or_default();
                            let nan = if *nan > 0 {
                                format!(" NaN {nan}")
                            } else {
                                String::new()
                            };
                            format!("{v}{c}{nan}")
                        }
                        Some(Err(_)) => "failed".into(),
                        None => "–".into(),
                    }
                })
                .collect();
            let _ = write!(s, " {} |", cell.join(" / "));
        }
        let _ = writeln!(s);
    }
    let _ = write!(s, "{}", origin_table(hard_rows, cases));
    // What each strategy costs: total time over all cases, and how many cases it fails.
    let _ = writeln!(s, "\n| strategy | cases within tolerance (VK / GL) | total time over the cases, ms (VK / GL) | worst case |\n|---|---|---|---|");
    for st in &strategies {
        let mut cells = Vec::new();
        let mut times = Vec::new();
        for api in [Api::Vulkan, Api::Opengl] {
            let these: Vec<&HardRow> = hard_rows
                .iter()
                .filter(|r| &r.strategy == st && r.api == api)
                .collect();
            let ok = these.iter().filter(|r| r.passes()).count();
            cells.push(format!("{ok}/{}", these.len()));
            times.push(f3(these
                .iter()
                .filter_map(|r| r.result.as_ref().ok().map(|x| x.2))
                .sum::<f64>()));
        }
        let worst = hard_rows
            .iter()
            .filter(|r| &r.strategy == st)
            .filter_map(|r| r.result.as_ref().ok().map(|x| (r, x.0)))
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(r, w)| format!("{} ({}): {:.2}% wrong", r.case, api_name(r.api), 100.0 * w))
            .unwrap_or_default();
        let _ = writeln!(
            s,
            "| {st} | {} | {} | {worst} |",
            cells.join(" / "),
            times.join(" / ")
        );
    }
    let _ = writeln!(s);
    s
}

/// Before / after camera-relative rendering: the cases whose local origin is
/// not zero, rendered with world coordinates in f32 (`origin=world`, before)
/// and relative to the local origin (the default, after), measured as rows.
fn origin_table(hard_rows: &[HardRow], cases: &[HardCase]) -> String {
    let mut s = String::new();
    let moved: Vec<(&HardCase, [f64; 3])> = cases
        .iter()
        .filter_map(|c| {
            let scene = Scene::load(&c.path.to_string_lossy(), &[]).ok()?;
            let o = twinray_common::scene::camera::local_origin(&scene).to_array();
            (o != [0.0; 3]).then_some((c, o))
        })
        .collect();
    if moved.is_empty() {
        return s;
    }
    let _ = writeln!(
        s,
        "\n### Local origin: before and after\n\nThe cases whose local origin (the camera's look-at point on a power-of-two \
         grid, `camera::local_origin`) is not zero; every other case has origin zero and identical images in both columns. \
         Wrong pixels (off by more than {WRONG_ABOVE}/255), Vulkan / OpenGL, against the one truth: the f64 reference in the local frame.\n\n\
         | case | local origin | tolerance | before: world coordinates in f32 (`origin=world`) | after: relative to the local origin (default) |\n|---|---|---|---|---|"
    );
    let cell = |case: &str, st: &str| -> String {
        [Api::Vulkan, Api::Opengl]
            .iter()
            .map(|api| {
                match hard_rows
                    .iter()
                    .find(|r| r.case == case && r.strategy == st && r.api == *api)
                    .map(|r| &r.result)
                {
                    Some(Ok((w, _, _, _))) => format!("{:.3}%", 100.0 * w),
                    Some(Err(_)) => "failed".into(),
                    None => "–".into(),
                }
            })
            .collect::<Vec<_>>()
            .join(" / ")
    };
    for (c, o) in moved {
        let _ = writeln!(
            s,
            "| {} | ({:e}, {:e}, {:e}) | {}% | {} | {} |",
            c.name,
            o[0],
            o[1],
            o[2],
            c.tolerance_pct,
            cell(&c.name, &format!("origin={}", OriginMode::World.name())),
            cell(&c.name, "default")
        );
    }
    let _ = writeln!(s);
    s
}
