//! The laboratory beside the product: the apps' `--help` shows the product's
//! options and names no experiment; `--experiments` prints the laboratory's
//! page, which is docs/experiments.md; and no file of the apps (vk/src,
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
