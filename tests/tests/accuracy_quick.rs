//! `twinray accuracy --quick` end to end on the installed driver: every scene ×
//! API × configuration renders, the default is among them once per scene and
//! API, every hard case passes with the default configuration on both APIs,
//! the local origin's before/after rows are measured, and random scenes are
//! compared three ways.

use twinray_tests::{bin, run_ok, scratch};

fn rows(csv: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let mut lines = csv.lines();
    let header = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    // The key columns come before any quoted field, so a plain split is enough for them.
    (
        header,
        lines
            .map(|l| l.split(',').map(str::to_string).collect())
            .collect(),
    )
}

#[test]
fn quick_accuracy_report_covers_every_configuration_and_the_default_passes_the_hard_cases() {
    let out = scratch("accuracy-quick");
    run_ok(
        &bin("twinray"),
        &[
            "accuracy",
            "--quick",
            "--random",
            "3",
            "--out",
            out.to_str().unwrap(),
        ],
        &[],
    );

    let (h, body) = rows(&std::fs::read_to_string(out.join("accuracy.csv")).unwrap());
    let col = |n: &str| {
        h.iter()
            .position(|c| c == n)
            .unwrap_or_else(|| panic!("no column {n}"))
    };
    for scene in ["box", "teapot", "spherelist"] {
        for api in ["vulkan", "opengl"] {
            let these: Vec<&Vec<String>> = body
                .iter()
                .filter(|r| r[col("scene")] == scene && r[col("api")] == api)
                .collect();
            assert!(
                these.len() >= 10,
                "{scene} {api}: only {} configurations",
                these.len()
            );
            assert!(
                these.iter().all(|r| r[col("status")] == "ok"),
                "{scene} {api}: a configuration failed"
            );
            assert_eq!(
                these.iter().filter(|r| r[col("default")] == "true").count(),
                1,
                "{scene} {api}: one default row"
            );
        }
    }

    let (h, body) = rows(&std::fs::read_to_string(out.join("hard_cases.csv")).unwrap());
    let col = |n: &str| h.iter().position(|c| c == n).unwrap();
    let defaults: Vec<&Vec<String>> = body
        .iter()
        .filter(|r| r[col("strategy")] == "default")
        .collect();
    assert!(
        defaults.len() >= 24,
        "at least 12 hard cases x 2 APIs, got {}",
        defaults.len()
    );
    for r in defaults {
        let wrong: f64 = r[col("wrong_pct")].parse().unwrap();
        let tol: f64 = r[col("tolerance_pct")].parse().unwrap();
        assert!(
            r[col("status")] == "ok" && wrong <= tol,
            "{} {}: {wrong}% wrong > {tol}%",
            r[col("case")],
            r[col("api")]
        );
        assert_eq!(
            r[col("nonfinite_pixels")],
            "0",
            "{} {}: NaN/Inf",
            r[col("case")],
            r[col("api")]
        );
    }
    // Before / after the local origin, both measured: world coordinates in f32
    // lose far-1e6 (10% of its pixels), the local origin keeps it within tolerance.
    let far = |strategy: &str| -> Vec<f64> {
        body.iter()
            .filter(|r| r[col("case")] == "far-1e6" && r[col("strategy")] == strategy)
            .map(|r| r[col("wrong_pct")].parse().unwrap())
            .collect()
    };
    let (before, after) = (far("origin=world"), far("default"));
    assert_eq!((before.len(), after.len()), (2, 2));
    assert!(
        before.iter().all(|w| *w > 1.0) && after.iter().all(|w| *w <= 0.1),
        "far-1e6: before {before:?}%, after {after:?}%"
    );

    let random = std::fs::read_to_string(out.join("random.csv")).unwrap();
    let (h, body) = rows(&random);
    let col = |n: &str| h.iter().position(|c| c == n).unwrap();
    assert_eq!(body.len(), 9, "3 seeds x 3 pairs:\n{random}");
    assert!(
        body.iter().all(|r| r[col("status")] == "ok"),
        "random scenes disagree:\n{random}"
    );

    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        report.contains("Default configuration"),
        "report names the default"
    );
    for section in [
        "Local origin: before and after",
        "## Random scenes (3 seeds",
    ] {
        assert!(report.contains(section), "report has no '{section}'");
    }
    std::fs::remove_dir_all(out).ok();
}
