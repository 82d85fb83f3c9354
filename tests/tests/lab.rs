//! The laboratory beside the product: the apps' `--help` shows the product's
//! options and names no experiment; `--experiments` prints the laboratory's
//! page, which is docs/experiments.md; every experiment has a runner (a why
//! step case, a test or a plan); and no file of the apps (vk/src,
//! gl/src) names an experiment: they consume the run plan the registry shaped.

use clap::ValueEnum;
use std::path::Path;
use std::process::Command;
use twinray_common::lab::experiment::Experiment;
use twinray_common::value_name::ValueName;
use twinray_tests::App;

fn names() -> Vec<String> {
    Experiment::value_variants()
        .iter()
        .map(ValueName::name)
        .collect()
}

fn stdout(app: App, args: &[&str]) -> String {
    let o = Command::new(app.exe()).args(args).output().unwrap();
    assert!(
        o.status.success(),
        "{app:?} {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout).unwrap()
}

#[test]
fn help_shows_the_product_and_no_experiment() {
    for app in App::BOTH {
        let help = stdout(app, &["--help"]);
        for hidden in [
            "--experiment ",
            "--gl-spirv",
            "--generic",
            "--specialize",
            "--shared-pad",
            "--vk-memory",
            "--vk-wait",
        ] {
            assert!(
                !help.contains(hidden),
                "{app:?} --help shows {hidden}:\n{help}"
            );
        }
        for name in names() {
            assert!(
                !help.contains(&name),
                "{app:?} --help names the experiment {name}:\n{help}"
            );
        }
        for product in [
            "--scene",
            "--size",
            "--headless",
            "--path",
            "--accel",
            "--experiments",
        ] {
            assert!(help.contains(product), "{app:?} --help lacks {product}");
        }
    }
}

#[test]
fn the_experiments_option_prints_the_page() {
    let page = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/experiments.md"),
    )
    .unwrap();
    for app in App::BOTH {
        assert_eq!(stdout(app, &["--experiments"]), page, "{app:?}");
    }
    for name in names() {
        assert!(page.contains(&format!("`{name}`")), "the page lists {name}");
    }
}

/// Every Rust file under `dir`.
fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

#[test]
fn the_apps_name_no_experiment() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    for dir in ["vk/src", "gl/src"] {
        rust_files(&root.join(dir), &mut files);
    }
    assert!(files.len() > 20, "the apps' files were found");
    let mut found = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        for (n, line) in text.lines().enumerate() {
            let hit = line.contains("Experiment")
                || line.contains("--experiment")
                || names().iter().any(|name| {
                    line.contains(&format!("`{name}`"))
                        || line.contains(&format!("\"{name}\""))
                        || line.contains(&format!("{name}`"))
                });
            if hit {
                found.push(format!("{}:{}: {}", f.display(), n + 1, line.trim()));
            }
        }
    }
    assert!(
        found.is_empty(),
        "the apps name experiments; the registry (common/src/lab) should:\n{}",
        found.join("\n")
    );
}

/// The experiment names after each `--experiment` in `text`, however it is
/// written: `--experiment NAME`, `--experiment=NAME`, or as the next item of
/// a list (`"--experiment", "NAME"`).
fn experiments_passed(text: &str) -> Vec<String> {
    let separator = |c: char| c.is_whitespace() || "=\"',".contains(c);
    text.match_indices("--experiment")
        .map(|(at, flag)| &text[at + flag.len()..])
        // `--experiments` (the page) is another option.
        .filter(|rest| rest.starts_with(separator))
        .map(|rest| {
            rest.trim_start_matches(separator)
                .chars()
                .take_while(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || *c == '-')
                .collect()
        })
        .filter(|name: &String| !name.is_empty())
        .collect()
}

/// The quoted names on a plan's `experiment` lines (`experiment = [false,
/// "glslang"]`, `options = { experiment = "no-contraction" }`).
fn plan_experiments(text: &str) -> Vec<String> {
    text.lines()
        .filter(|line| {
            line.trim_start().contains("experiment") && !line.trim_start().starts_with('#')
        })
        .flat_map(|line| line.split('"').skip(1).step_by(2).map(str::to_string))
        .collect()
}

#[test]
fn experiments_are_found_however_they_are_passed() {
    assert_eq!(
        plan_experiments(
            "# experiment \"x\"\nexperiment = [false, \"glslang\", \"ulp\"]\nscene = \"box\"\n"
        ),
        ["glslang", "ulp"]
    );
    let text = "args: [\"--experiment\", \"split-ray-stack\"]\n\
                run --experiment ulp --ulp-op div; --experiment=glslang\n\
                options = ['--experiment', 'naga-aliasing'] --experiments";
    assert_eq!(
        experiments_passed(text),
        ["split-ray-stack", "ulp", "glslang", "naga-aliasing"]
    );
}

/// An experiment stays only while something runs it (issue #44): a row of the
/// comparison's why step (`CASES` in comparison/src/compare/why.rs), a test
/// (tests/tests, common/tests) or a plan (comparison/plans/*.toml). A
/// concluded one leaves the registry, and with it the code and the page; its
/// findings page cites the commit that still has it.
#[test]
fn every_experiment_in_the_registry_has_a_runner() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let why = std::fs::read_to_string(root.join("comparison/src/compare/why.rs")).unwrap();
    let cases = why
        .split("pub const CASES")
        .nth(1)
        .and_then(|rest| rest.split("\n];").next())
        .expect("why.rs declares CASES");
    let mut files = Vec::new();
    for dir in ["tests/tests", "common/tests"] {
        rust_files(&root.join(dir), &mut files);
    }
    // This file names experiments to test the laboratory, not to run them.
    files.retain(|f| !f.ends_with("tests/tests/lab.rs"));
    if let Ok(plans) = std::fs::read_dir(root.join("comparison/plans")) {
        files.extend(
            plans
                .map(|e| e.unwrap().path())
                .filter(|p| p.extension().is_some_and(|x| x == "toml")),
        );
    }
    assert!(files.len() > 20, "the test files were found");
    let mut passed = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        passed.extend(experiments_passed(&text));
        if f.extension().is_some_and(|x| x == "toml") {
            passed.extend(plan_experiments(&text));
        }
    }
    let unrun: Vec<String> = Experiment::value_variants()
        .iter()
        .filter(|e| {
            // The whole variant: `Experiment::Glslang` is not `Experiment::GlslangX`.
            let named = format!("Experiment::{e:?}");
            !cases
                .match_indices(&named)
                .any(|(at, _)| !cases[at + named.len()..].starts_with(char::is_alphanumeric))
        })
        .map(ValueName::name)
        .filter(|name| !passed.contains(name))
        .collect();
    assert!(
        unrun.is_empty(),
        "nothing runs these experiments (no why-step case, test or plan): {}; \
         retire them from common/src/lab, the apps and the shader, and cite the \
         commit that has them on their findings page",
        unrun.join(", ")
    );
}

/// Refused before any window opens: no display is needed to see it.
#[test]
fn a_headless_experiment_is_refused_in_a_window() {
    for app in App::BOTH {
        twinray_tests::refused(
            app,
            &["--experiment", "ulp", "--ulp-op", "add"],
            "--experiment ulp is a headless measurement; run it with --headless",
        );
    }
}
