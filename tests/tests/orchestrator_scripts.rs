//! The tracked shell scripts against the apps they drive: every
//! `--experiment NAME` a script passes is a name both apps accept today, so an
//! investigation cannot record an app's refusal as its data and look as if it
//! ran (as `gpu-lmem.sh` did with the retired `global-bvh-stack`); every
//! script passes shellcheck at its warning level and defines no function twice;
//! and every committed plan (comparison/plans/*.toml) passes `twinray sweep
//! --dry-run`, which checks each option set with the apps' own parsers, so a
//! plan that names a retired experiment or option fails here, not on a GPU.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use twinray_tests::{bin, bin_dir, fail, run, scratch, App};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// The experiment names an app accepts, as it says itself: clap lists the
/// possible values when it refuses one, so no copy of the list can go stale.
fn accepted(app: App) -> BTreeSet<String> {
    let (code, stderr) = fail(&app.exe(), &["--experiment", "__none__"], &[]);
    assert_eq!(code, 2, "{app:?} accepted --experiment __none__: {stderr}");
    let list = stderr
        .split("[possible values: ")
        .nth(1)
        .and_then(|rest| rest.split(']').next())
        .unwrap_or_else(|| panic!("{app:?} listed no possible values: {stderr}"));
    let names: BTreeSet<String> = list.split(", ").map(|s| s.trim().to_string()).collect();
    assert!(names.len() > 1, "{app:?} listed {names:?}");
    names
}

/// Every tracked `*.sh`, as git lists it (untracked scratch scripts are no
/// one else's business).
fn tracked_scripts() -> Vec<PathBuf> {
    let root = root();
    let o = std::process::Command::new("git")
        .args(["ls-files", "-z", "--", "*.sh"])
        .current_dir(&root)
        .output()
        .expect("running git ls-files (the test reads the tracked scripts)");
    assert!(
        o.status.success(),
        "git ls-files failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let files: Vec<PathBuf> = o
        .stdout
        .split(|&b| b == 0)
        .filter(|p| !p.is_empty())
        .map(|p| root.join(String::from_utf8_lossy(p).as_ref()))
        .collect();
    assert!(!files.is_empty(), "git lists no *.sh in {}", root.display());
    files
}

/// The literal names after `--experiment` (or `--experiment=`) in a script's
/// commands; a name from a variable (`$e`) is the caller's to check, and a
/// comment line may name a retired experiment to say what was run then.
fn experiments_in(text: &str) -> Vec<(usize, String)> {
    let mut found = Vec::new();
    for (n, line) in text.lines().enumerate() {
        if line.trim_start().starts_with('#') {
            continue;
        }
        let mut rest = line;
        while let Some(at) = rest.find("--experiment") {
            rest = &rest[at + "--experiment".len()..];
            let Some(arg) = rest.strip_prefix([' ', '=']) else {
                continue;
            };
            let name: String = arg
                .trim_start_matches(['"', '\''])
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '-' || *c == '_')
                .collect();
            if !name.is_empty() {
                found.push((n + 1, name));
            }
        }
    }
    found
}

#[test]
fn the_parser_finds_literal_names_and_skips_variables() {
    let text = "run x vk --experiment naga-aliasing --path compute\n\
                f=\"--workgroup 4x8 --experiment=global-bvh-stack\"\n\
                # once --experiment one-query\n\
                run y gl --experiment \"$e\" --experiment 'quad'\n";
    assert_eq!(
        experiments_in(text),
        vec![
            (1, "naga-aliasing".to_string()),
            (2, "global-bvh-stack".to_string()),
            (4, "quad".to_string()),
        ]
    );
}

#[test]
fn every_experiment_a_tracked_script_passes_is_one_the_apps_accept() {
    let names: Vec<BTreeSet<String>> = App::BOTH.into_iter().map(accepted).collect();
    let mut checked = 0;
    let mut unknown = Vec::new();
    for script in tracked_scripts() {
        let text = std::fs::read_to_string(&script)
            .unwrap_or_else(|e| panic!("reading {}: {e}", script.display()));
        for (line, name) in experiments_in(&text) {
            checked += 1;
            for (app, accepted) in App::BOTH.iter().zip(&names) {
                if !accepted.contains(&name) {
                    unknown.push(format!(
                        "{}:{line}: --experiment {name} (not accepted by {app:?})",
                        script.strip_prefix(root()).unwrap_or(&script).display()
                    ));
                }
            }
        }
    }
    // The remaining scripts pass several; none found means the search is broken.
    assert!(checked > 3, "only {checked} --experiment names found");
    assert!(
        unknown.is_empty(),
        "scripts pass experiments the apps refuse (rename or retire them):\n{}",
        unknown.join("\n")
    );
}

/// Every tracked script passes shellcheck at its warning level: a quoting slip
/// or a variable set and never used in an investigation script shows here,
/// not on a borrowed GPU.
#[test]
fn every_tracked_script_passes_shellcheck() {
    let scripts = tracked_scripts();
    let out = std::process::Command::new("shellcheck")
        .args(["-x", "-S", "warning", "-f", "gcc"])
        .args(&scripts)
        .current_dir(root())
        .output()
        .unwrap_or_else(|e| {
            panic!("shellcheck could not run ({e}): install Debian's shellcheck (scripts/setup.sh does)")
        });
    assert!(
        out.status.success(),
        "shellcheck finds problems in the tracked scripts:\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// No shell function is defined twice in one script: bash keeps the last
/// definition silently, so a second `teapot_points` in `lib.sh` once gave
/// every script that sourced it another set of points (no `--frames`, no
/// `--count-rays`) with no warning from shellcheck.
#[test]
fn no_script_defines_a_function_twice() {
    let mut checked = 0;
    let mut twice = Vec::new();
    for script in tracked_scripts() {
        let text = std::fs::read_to_string(&script)
            .unwrap_or_else(|e| panic!("reading {}: {e}", script.display()));
        let mut seen = BTreeSet::new();
        for (n, line) in text.lines().enumerate() {
            let Some(name) = function_defined(line) else {
                continue;
            };
            checked += 1;
            if !seen.insert(name.to_string()) {
                twice.push(format!("{}:{}: {name}", script.display(), n + 1));
            }
        }
    }
    // gpu-unsettled.sh and gpu-clocks.sh define one each; none found means
    // the search is broken.
    assert!(checked >= 2, "only {checked} function definitions found");
    assert!(
        twice.is_empty(),
        "functions defined a second time (bash keeps only the last):\n{}",
        twice.join("\n")
    );
}

/// `name` where `line` opens a function definition, `name() {` at the start
/// of the line (the form every tracked script uses).
fn function_defined(line: &str) -> Option<&str> {
    let name = line.strip_suffix("() {")?;
    let ok = !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    ok.then_some(name)
}

#[test]
fn a_function_definition_is_recognised_and_a_call_is_not() {
    assert_eq!(function_defined("teapot_points() {"), Some("teapot_points"));
    assert_eq!(function_defined("    teapot_points"), None);
    assert_eq!(function_defined("echo \"f() {\""), None);
}

/// The `name = "folder"` lines of a plan's `[builds]` table (the plans
/// write each on one line; the sweep's own parser reads the rest).
fn build_folders(plan: &str) -> Vec<String> {
    plan.lines()
        .skip_while(|l| l.trim() != "[builds]")
        .skip(1)
        .take_while(|l| !l.trim_start().starts_with('['))
        .filter_map(|l| {
            l.split_once('=')
                .map(|(_, v)| v.trim().trim_matches('"').to_string())
        })
        .filter(|v| !v.is_empty())
        .collect()
}

#[test]
fn builds_are_read_from_the_builds_table_alone() {
    let plan =
        "rounds = 1\n[builds]\nold = \"../../.bin/old\"\n\nnew = \"b\"\n[axes]\nsize = [\"1x1\"]\n";
    assert_eq!(build_folders(plan), ["../../.bin/old", "b"]);
}

/// Every committed plan, as CI sees it: its builds are folders of links to
/// the apps under test (placed where the plan names them, relative to a copy
/// of the plan), and `twinray sweep --dry-run` reads and checks it, every
/// option set parsed by each app's own parser and every environment value by
/// its knob's, and prints its cells.
#[test]
fn every_committed_plan_is_one_the_apps_accept() {
    let plans: Vec<PathBuf> = std::fs::read_dir(root().join("comparison/plans"))
        .expect("reading comparison/plans")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    assert!(plans.len() > 5, "only {} plans found", plans.len());
    let mut refused = Vec::new();
    for plan in &plans {
        let name = plan.file_name().unwrap().to_string_lossy().into_owned();
        let text = std::fs::read_to_string(plan).unwrap();
        let dir = scratch(&format!("plan-{name}"));
        let copy = dir.join("comparison/plans").join(&name);
        std::fs::create_dir_all(copy.parent().unwrap()).unwrap();
        std::fs::write(&copy, &text).unwrap();
        let folders = build_folders(&text);
        assert!(!folders.is_empty(), "{name} names no build");
        for folder in folders {
            let at = copy.parent().unwrap().join(&folder);
            std::fs::create_dir_all(&at).unwrap();
            for app in ["twinray-vk", "twinray-gl"] {
                if !at.join(app).exists() {
                    std::os::unix::fs::symlink(bin_dir().join(app), at.join(app)).unwrap();
                }
            }
        }
        let o = run(
            &bin("twinray"),
            &[
                "sweep",
                copy.to_str().unwrap(),
                "--out",
                dir.join("out").to_str().unwrap(),
                "--dry-run",
            ],
            &[],
        );
        let cells = String::from_utf8_lossy(&o.stdout).lines().count();
        if !o.status.success() || cells == 0 {
            refused.push(format!(
                "{name}: {}",
                String::from_utf8_lossy(&o.stderr).trim()
            ));
        }
        assert!(
            !dir.join("out").exists(),
            "--dry-run wrote {}",
            dir.join("out").display()
        );
    }
    assert!(
        refused.is_empty(),
        "plans the sweep refuses:\n{}",
        refused.join("\n")
    );
}
