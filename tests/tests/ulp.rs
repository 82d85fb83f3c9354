//! `twinray ulp` end to end on the installed driver (lavapipe and llvmpipe in
//! CI): the probe's transport is lossless and its inputs are the ones the
//! orchestrator recomputes (`bits` comes back bit for bit on every API and
//! path), the operations that IEEE makes exact are exact, the correctly
//! rounded ones within half an ULP, dot within a stated bound; a run where
//! every app fails is a failure, and the probe's options are refused where
//! they cannot apply. Budget: about 30 s on a 2-core machine.

use std::collections::HashMap;
use std::path::Path;
use twinray_tests::{bin, fail, refused, run, scratch, stand_in, App};

/// One CSV line's fields (the csv crate's quoting: "..." with "" inside).
fn fields(line: &str) -> Vec<String> {
    let (mut out, mut cur, mut quoted, mut chars) =
        (Vec::new(), String::new(), false, line.chars().peekable());
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => out.push(std::mem::take(&mut cur)),
            _ => cur.push(c),
        }
    }
    out.push(cur);
    out
}

/// ulp.csv as rows of column name to value.
fn rows(dir: &Path) -> Vec<HashMap<String, String>> {
    let text = std::fs::read_to_string(dir.join("ulp.csv")).unwrap();
    let mut lines = text.lines();
    let header = fields(lines.next().unwrap());
    lines
        .map(|l| header.iter().cloned().zip(fields(l)).collect())
        .collect()
}

fn num(row: &HashMap<String, String>, column: &str) -> f64 {
    row[column]
        .parse()
        .unwrap_or_else(|_| panic!("{column} in {row:?}"))
}

#[test]
fn the_probe_is_lossless_and_exact_operations_are_exact() {
    let dir = scratch("ulp");
    let out = dir.join("out");
    let ops = "bits,add,div,min,max,clamp,dot";
    let o = run(
        &bin("twinray"),
        &[
            "ulp",
            "--inputs",
            "20000",
            "--ops",
            ops,
            "--out",
            out.to_str().unwrap(),
        ],
        &[],
    );
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "twinray ulp failed: {stderr}");
    let rows = rows(&out);
    let gpu: Vec<_> = rows.iter().filter(|r| r["api"] != "cpu").collect();
    // 7 operations x 2 APIs x 2 paths, each all + five classes.
    assert_eq!(gpu.len(), 7 * 4 * 6, "{stderr}");
    for r in &gpu {
        assert_eq!(r["status"], "ok", "{r:?}");
        let (op, class) = (r["op"].as_str(), r["class"].as_str());
        let results = num(r, "results");
        if class == "all" {
            assert_eq!(results, 20_000.0, "{r:?}");
        }
        match op {
            // Every bit pattern of every class came back: the transport and the
            // CPU's recomputation of the inputs agree with the shader.
            "bits" => {
                assert_eq!(num(r, "max_ulp"), 0.0, "{r:?}");
                assert_eq!(num(r, "measured"), results, "{r:?}");
            }
            // Exact in IEEE arithmetic; a flushed denormal is counted apart.
            "min" | "max" | "clamp" => {
                if num(r, "measured") > 0.0 {
                    assert_eq!(num(r, "max_ulp"), 0.0, "{r:?}");
                }
                assert_eq!(num(r, "nonfinite"), 0.0, "{r:?}");
            }
            // LLVM's add and divide are correctly rounded.
            "add" | "div" if class == "random" => {
                assert!(num(r, "max_ulp") <= 0.5, "{r:?}")
            }
            // Three products and two sums: on random inputs within a few ULPs
            // on average; the largest errors are cancellations.
            "dot" if class == "random" => {
                assert!(num(r, "mean_ulp") <= 1.0, "{r:?}")
            }
            _ => {}
        }
    }
    let md = std::fs::read_to_string(out.join("ulp.md")).unwrap();
    assert!(
        md.contains("| `bits` | 0 / 0 | 0 / 0 | 0 / 0 | 0 / 0 | 0 / 0 |"),
        "{md}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A stand-in for `app` in `apps` that fails every run, in `words`.
fn failing(apps: &Path, app: &str, words: &str) {
    let script = format!("#!/bin/sh\necho \"error: {words}\" >&2\nexit 3\n");
    stand_in(apps, app, &script);
}

/// `twinray ulp` on 64 inputs with the apps in `dir`/apps, writing to
/// `dir`/out, expected to fail saying each of `words`: its exit code and
/// stderr.
fn ulp_failing(dir: &Path, extra: &[&str], words: &[&str]) -> (i32, String) {
    let (apps, out) = (dir.join("apps"), dir.join("out"));
    let mut args = vec!["--bin-dir", apps.to_str().unwrap(), "ulp", "--inputs", "64"];
    args.extend_from_slice(extra);
    args.extend(["--out", out.to_str().unwrap()]);
    let (code, stderr) = fail(&bin("twinray"), &args, &[]);
    assert!(words.iter().all(|w| stderr.contains(w)), "{stderr}");
    (code, stderr)
}

#[test]
fn a_run_in_which_every_app_fails_is_a_failure_and_says_why() {
    let dir = scratch("ulp-fail");
    let apps = dir.join("apps");
    std::fs::create_dir_all(&apps).unwrap();
    for app in ["twinray-vk", "twinray-gl"] {
        failing(&apps, app, "no device here");
    }
    let words = ["4 runs failed", "no device here"];
    let (code, stderr) = ulp_failing(&dir, &["--ops", "div"], &words);
    assert_ne!(code, 0, "{stderr}");
    let md = std::fs::read_to_string(dir.join("out/ulp.md")).unwrap();
    assert!(
        md.contains("## Failed runs") && md.contains("| `div` | failed | failed |"),
        "{md}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_probes_options_are_refused_where_they_cannot_apply() {
    for app in App::BOTH {
        let base = ["--headless", "--size", "8x8"];
        refused(
            app,
            &[&base[..], &["--ulp-op", "div"]].concat(),
            "--ulp-op applies to --experiment ulp only",
        );
        refused(
            app,
            &[&base[..], &["--experiment", "ulp"]].concat(),
            "--experiment ulp needs --ulp-op",
        );
        refused(
            app,
            &[
                "--headless",
                "--size",
                "7x8",
                "--experiment",
                "ulp",
                "--ulp-op",
                "div",
            ],
            "needs an even width",
        );
        refused(
            app,
            &[
                &base[..],
                &["--experiment", "ulp", "--ulp-op", "div", "--count-rays"],
            ]
            .concat(),
            "drop --count-rays",
        );
    }
    let (code, stderr) = fail(&bin("twinray"), &["ulp", "--apis", "reference"], &[]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("--apis reference"), "{stderr}");
}

#[test]
fn a_run_in_which_some_apps_fail_exits_1_and_keeps_the_rest() {
    // 4 of 8 runs failed and `twinray ulp` exited 0: a failure only when all did.
    let dir = scratch("ulp-some-fail");
    let apps = dir.join("apps");
    std::fs::create_dir_all(&apps).unwrap();
    std::os::unix::fs::symlink(bin("twinray-vk"), apps.join("twinray-vk")).unwrap();
    failing(&apps, "twinray-gl", "no context here");
    let add = ["--ops", "add", "--paths", "fragment"];
    let (code, stderr) = ulp_failing(&dir, &add, &["1 run failed", "no context here"]);
    assert_eq!(code, 1, "{stderr}");
    let csv = std::fs::read_to_string(dir.join("out/ulp.csv")).unwrap();
    assert!(
        csv.lines().any(|l| l.starts_with("add,vulkan,fragment")),
        "{csv}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
