//! `twinray compare --quick` end to end on whatever driver is installed: it
//! finishes, and results.csv holds every API × experiment × point, all ok, with
//! the report, the plots and the agreement images beside it, and the why
//! step's table and why.csv hold a computed verdict for every gap × experiment.

use std::collections::BTreeSet;
use twinray_tests::{bin, run_ok, scratch};

#[test]
fn quick_comparison_writes_every_api_experiment_and_point() {
    let out = scratch("compare-quick");
    run_ok(
        &bin("twinray"),
        // Two frames a point: the test checks what the run writes, not its
        // times, and the preset's eight took it from 4 to 7.5 minutes on 2 cores.
        &[
            "compare",
            "--quick",
            "--frames",
            "2",
            "--out",
            out.to_str().unwrap(),
        ],
        &[],
    );

    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("no column {name}"))
    };
    let (exp, value, api, status, path) = (
        col("experiment"),
        col("param_value"),
        col("api"),
        col("status"),
        col("path"),
    );
    let mut seen = BTreeSet::new();
    for line in lines {
        // Quoted fields come after the key columns, so a plain split is enough for these.
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f[status], "ok", "failed point: {line}");
        seen.insert((
            f[exp].to_string(),
            f[value].to_string(),
            f[api].to_string(),
            f[path].to_string(),
        ));
    }
    let mut expected = BTreeSet::new();
    let points = [
        ("teapot", &["24x24", "40x40"][..]),
        ("box", &["100x100", "200x200"][..]),
        ("spherelist", &["1", "10", "100"][..]),
    ];
    for a in ["vulkan", "opengl"] {
        for p in ["fragment", "compute"] {
            for (e, values) in points {
                for v in values {
                    expected.insert((e.to_string(), v.to_string(), a.to_string(), p.to_string()));
                }
            }
        }
    }
    assert_eq!(
        seen, expected,
        "results.csv must hold every API x path x experiment x point of the quick preset"
    );

    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    let summary: Vec<&str> = report.lines().skip(2).take(4).collect();
    for (line, exp) in summary.iter().zip(["teapot", "box", "spherelist"]) {
        assert!(
            line.starts_with(&format!("- **{exp}** — Vulkan/OpenGL: fragment")),
            "report opens with a summary line per experiment: {line}"
        );
        assert!(line.contains("compute") && line.contains("Why:"), "{line}");
    }
    assert_eq!(summary[3], "", "the summary is three lines");
    for f in [
        "teapot.svg",
        "box.svg",
        "spherelist.svg",
        "scaling.svg",
        "images/box-reference.png",
    ] {
        assert!(out.join(f).exists(), "{f} missing");
    }
    // Every tracer's dump, and a row for it in the drivers' section.
    let section = report
        .split("## What the drivers compiled")
        .nth(1)
        .and_then(|s| s.split("\n## ").next())
        .expect("the report has the drivers' section");
    let rows = section
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| scene"))
        .count();
    assert_eq!(
        rows,
        4 * 2 * 2,
        "scene x accel (4) x path x API rows: {section}"
    );
    assert!(!section.contains("failed"), "{section}");
    for api in ["vulkan", "opengl"] {
        let dir = out.join(format!("shaders/teapot-bvh-{api}-compute"));
        for f in ["compute.spv", "compute.glsl", "statistics.json"] {
            assert!(dir.join(f).exists(), "{} missing", dir.join(f).display());
        }
    }
    why_table_has_a_verdict_per_gap_and_experiment(&report, &out);
    std::fs::remove_dir_all(out).ok();
}

/// A word of each experiment the why table must hold a row for.
const WHY_ROWS: &[&str] = &[
    "glslang",
    "no-loop-bounding",
    "opengl-spirv",
    "split-ray-stack",
    "shared-bvh-stack",
    "local-bvh-stack",
    "naga-aliasing",
    "no-contraction",
    "float-controls",
    "first-of-equals",
    "walk-then-shade",
    "workgroup 4x8",
    "--set max_depth=1",
    "timed-barrier",
    "less their empty frame's time",
    "the second of two frames back to back",
    "at workgroup 4x8: the second of two frames back to back",
    "capped-bvh-stack",
    "capped-bvh-stack+unpaired-bvh-stack",
];

fn why_table_has_a_verdict_per_gap_and_experiment(report: &str, out: &std::path::Path) {
    let section = report
        .split("## Why the gaps")
        .nth(1)
        .expect("the report has the why section");
    assert!(
        section.contains("say nothing about GPUs"),
        "a software driver's why table says what its ratios are worth: {section}"
    );
    let table: Vec<&str> = section
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| gap"))
        .collect();
    let csv = std::fs::read_to_string(out.join("why.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        header,
        [
            "gap",
            "scene",
            "accel",
            "path",
            "size",
            "measure",
            "experiment",
            "clock",
            "default_value",
            "experiment_value",
            "share_closed",
            "vulkan_ms_default",
            "opengl_ms_default",
            "vulkan_ms_experiment",
            "opengl_ms_experiment",
            "verdict",
            "status"
        ]
    );
    // Status is the last column and the only one that may hold a comma (an
    // app's sentence naming a device), so the split stops before it.
    let rows: Vec<Vec<&str>> = lines
        .map(|l| {
            l.splitn(header.len(), ',')
                .map(|f| f.trim_matches('"'))
                .collect()
        })
        .collect();
    assert_eq!(rows.len(), table.len(), "one CSV row per table row");
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let verdicts = [
        "no gap to explain",
        "closes the gap",
        "no effect",
        "explains ",
        "widens the gap by ",
        "reverses the gap",
    ];
    let mut experiments = String::new();
    for (row, line) in rows.iter().zip(&table) {
        assert_eq!(row.len(), header.len(), "{row:?}");
        let status = row[col("status")];
        let experiment = row[col("experiment")];
        experiments.push_str(experiment);
        // glslangValidator missing: the row says so.
        if status.starts_with("not run: ") {
            assert!(experiment.contains("glslang"), "{row:?}");
            continue;
        }
        // A software driver's runs have wall time, which the rows that take
        // one run's time off another's (the empty frame, the second frame)
        // do not take apart: the row says so.
        if status.starts_with("not measured: ") {
            assert!(
                (experiment.contains("empty frame") || experiment.contains("back to back"))
                    && status.contains("wall time"),
                "{row:?}"
            );
            continue;
        }
        assert_eq!(status, "ok", "{row:?}");
        let verdict = row[col("verdict")];
        assert!(verdicts.iter().any(|v| verdict.starts_with(v)), "{verdict}");
        assert!(line.ends_with(&format!("| {verdict} |")), "{line}");
        let value = |c: &str| row[col(c)].parse::<f64>().unwrap();
        let (before, after) = (value("default_value"), value("experiment_value"));
        if row[col("clock")] == "image" {
            assert!((0.0..=100.0).contains(&before) && (0.0..=100.0).contains(&after));
        } else {
            // The ratios are the times behind them; less the empty frame's
            // where the row takes it off.
            let ratio = value("vulkan_ms_default") / value("opengl_ms_default");
            assert!((ratio / before - 1.0).abs() < 1e-9, "{row:?}");
            let (vk, gl) = (value("vulkan_ms_experiment"), value("opengl_ms_experiment"));
            let ratio = if experiment.contains("empty frame") {
                (value("vulkan_ms_default") - vk) / (value("opengl_ms_default") - gl)
            } else {
                vk / gl
            };
            assert!((ratio / after - 1.0).abs() < 1e-9, "{row:?}");
        }
    }
    for e in WHY_ROWS {
        assert!(experiments.contains(e), "no why row for {e}");
    }
}
