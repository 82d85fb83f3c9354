//! The repository as the page and source tests read it: its root, its files
//! by relative path, the source files under a folder, and the verdict of a
//! scan over them. One copy, so that every test walks the tree the same way.

use std::path::{Path, PathBuf};

/// The page most of the page tests hold to the code.
pub const WALKTHROUGH: &str = "docs/vulkan-walkthrough.md";

/// The repository's root (the tests crate sits one folder below it).
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// A file's text; a test that cannot read what it checks says which file.
pub fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The text of the file at `rel`, relative to the root.
pub fn text(rel: &str) -> String {
    read(&root().join(rel))
}

/// The files under `dir`, at any depth, whose extension is one of
/// `extensions`, in a stable order; none where `dir` is missing.
pub fn files_under(dir: &Path, extensions: &[&str]) -> Vec<PathBuf> {
    let mut out = Vec::new();
    walk(dir, extensions, &mut out);
    out
}

fn walk(dir: &Path, extensions: &[&str], out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<PathBuf> = entries.map(|e| e.unwrap().path()).collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            walk(&path, extensions, out);
        } else if path
            .extension()
            .is_some_and(|e| extensions.iter().any(|x| e == *x))
        {
            out.push(path);
        }
    }
}

/// The Rust source under `dirs` (relative to the root), all files together.
pub fn rust_sources(dirs: &[&str]) -> String {
    dirs.iter()
        .flat_map(|dir| files_under(&root().join(dir), &["rs"]))
        .map(|file| read(&file))
        .collect()
}

/// The verdict of a scan: nothing `wrong` (listed under `problem`), and at
/// least `min` things `checked`, so that a scan that has stopped finding what
/// it reads cannot pass by finding nothing wrong.
pub fn assert_scan(problem: &str, wrong: &[String], checked: usize, min: usize, what: &str) {
    crate::assert_none(problem, wrong);
    assert!(
        checked >= min,
        "only {checked} {what} found (at least {min} expected): is the scan still reading them?"
    );
}
