//! What every topic's checks share: both apps run on one input, the error
//! line's words, a scene file from a common head, and a folder's listing.

use std::path::Path;
use twinray_tests::{fail, App};

/// A scene that loads, which each bad scene file completes.
pub const SCENE_HEAD: &str = include_str!("../../data/scene_head.toml");

/// Runs both apps with `args` and checks the exit code and that the one error
/// line contains every word in `expect`.
pub fn expect_both(args: &[&str], env: &[(&str, &str)], code: i32, expect: &[&str]) {
    for app in App::BOTH {
        expect_one(&app.exe(), args, env, code, expect);
    }
}

pub fn expect_one(exe: &Path, args: &[&str], env: &[(&str, &str)], code: i32, expect: &[&str]) {
    let (got, stderr) = fail(exe, args, env);
    let name = exe.file_name().unwrap().to_string_lossy().to_string();
    assert_eq!(
        got, code,
        "{name} {args:?}: exit code {got}, stderr: {stderr}"
    );
    let errors: Vec<&str> = stderr.lines().filter(|l| l.contains("error")).collect();
    assert!(
        !errors.is_empty(),
        "{name} {args:?}: no error line in: {stderr}"
    );
    let line = errors[0];
    for word in expect {
        assert!(
            line.contains(word),
            "{name} {args:?}: error line lacks '{word}': {line}"
        );
    }
}

pub fn scene_file(dir: &Path, name: &str, body: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, format!("{SCENE_HEAD}{body}")).unwrap();
    p.to_str().unwrap().to_string()
}

pub fn headless(scene: &str) -> Vec<String> {
    ["--headless", "--size", "16x16", "--scene", scene]
        .iter()
        .map(|s| s.to_string())
        .collect()
}

pub fn strs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

/// The sorted names in `dir`: what a failed run must leave as it found.
pub fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|r| {
            r.map(|e| e.unwrap().file_name().to_string_lossy().to_string())
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}
