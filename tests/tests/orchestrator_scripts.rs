//! The tracked shell scripts against the apps they drive: every
//! `--experiment NAME` a script passes is a name both apps accept today, so an
//! investigation cannot record an app's refusal as its data and look as if it
//! ran (as `gpu-lmem.sh` did with the retired `global-bvh-stack`); and every
//! script passes shellcheck at its warning level and defines no function twice.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use twinray_tests::{fail, App};

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
    // The investigations pass dozens; none found means the search is broken.
    assert!(checked > 10, "only {checked} --experiment names found");
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
    // lib.sh alone defines a dozen; none found means the search is broken.
    assert!(checked > 10, "only {checked} function definitions found");
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
