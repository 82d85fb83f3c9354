//! docs/vulkan-walkthrough.md stays true to the code: every file it names
//! exists, every `path::function` it names is still defined there, every
//! picture it shows exists, and its lines-of-code table is the one this test
//! counts (`TWINRAY_UPDATE_DOCS=1` rewrites the table instead of failing).

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

fn doc_path() -> PathBuf {
    root().join("docs/vulkan-walkthrough.md")
}

/// Backticked spans of the document, e.g. `vk/src/device.rs::Device::new`.
fn code_spans(doc: &str) -> Vec<String> {
    // Only inline spans outside ``` blocks.
    let mut spans = Vec::new();
    let mut in_block = false;
    for line in doc.lines() {
        if line.trim_start().starts_with("```") {
            in_block = !in_block;
            continue;
        }
        if in_block {
            continue;
        }
        let parts: Vec<&str> = line.split('`').collect();
        spans.extend(parts.iter().skip(1).step_by(2).map(|s| s.to_string()));
    }
    spans
}

/// A span that names a repository file: a relative path with a known extension,
/// optionally followed by `::Type::function` or `::function`.
fn file_reference(span: &str) -> Option<(String, Vec<String>)> {
    let (path, rest) = match span.split_once("::") {
        Some((p, r)) => (p, r.split("::").map(str::to_string).collect()),
        None => (span, Vec::new()),
    };
    let known = [".rs", ".md", ".glsl", ".frag", ".vert", ".sh", ".toml"];
    (path.contains('/') && !path.contains(' ') && known.iter().any(|e| path.ends_with(e)))
        .then(|| (path.to_string(), rest))
}

#[test]
fn every_file_and_function_the_walkthrough_names_exists() {
    let doc = std::fs::read_to_string(doc_path()).expect("docs/vulkan-walkthrough.md");
    let mut checked = 0;
    let mut missing = Vec::new();
    for span in code_spans(&doc) {
        let Some((path, items)) = file_reference(&span) else {
            continue;
        };
        let file = root().join(&path);
        let Ok(text) = std::fs::read_to_string(&file) else {
            missing.push(format!("`{span}`: file {path} does not exist"));
            continue;
        };
        checked += 1;
        if let Some((function, owners)) = items.split_last() {
            let defines = |name: &str| {
                [format!("fn {name}("), format!("fn {name}<")]
                    .iter()
                    .any(|pat| text.contains(pat.as_str()))
            };
            if !defines(function) {
                missing.push(format!("`{span}`: no fn {function} in {path}"));
            }
            for owner in owners {
                let owned = [
                    format!("struct {owner}"),
                    format!("impl {owner}"),
                    format!("for {owner}"),
                    format!("enum {owner}"),
                ];
                if !owned.iter().any(|p| text.contains(p.as_str())) {
                    missing.push(format!("`{span}`: no type {owner} in {path}"));
                }
            }
        }
    }
    assert!(
        missing.is_empty(),
        "the walkthrough names things that are gone:\n{}",
        missing.join("\n")
    );
    assert!(
        checked >= 40,
        "only {checked} references found: is the parser still reading the document?"
    );
}

#[test]
fn every_picture_the_docs_show_exists() {
    for (doc, dir) in [
        (doc_path(), root().join("docs")),
        (root().join("README.md"), root()),
    ] {
        let text = std::fs::read_to_string(&doc).unwrap();
        for part in text.split("](").skip(1) {
            let target = part.split(')').next().unwrap();
            if target.ends_with(".png") {
                assert!(
                    dir.join(target).is_file(),
                    "{} shows {target}, which does not exist",
                    doc.display()
                );
            }
        }
    }
}

/// Non-blank lines that are not comments (`//`, `//!`, `///`), per file.
fn code_lines(file: &Path) -> usize {
    let text = std::fs::read_to_string(file).unwrap();
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with("//"))
        .count()
}

fn count(crate_dir: &str) -> Vec<(String, usize)> {
    let dir = root().join(crate_dir).join("src");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "rs"))
        .collect();
    files.sort();
    files
        .iter()
        .map(|f| {
            (
                format!(
                    "{crate_dir}/src/{}",
                    f.file_name().unwrap().to_string_lossy()
                ),
                code_lines(f),
            )
        })
        .collect()
}

/// The table between the loc markers, as this test counts it today.
fn loc_table() -> String {
    let vk = count("vk");
    let gl = count("gl");
    let total = |v: &[(String, usize)]| v.iter().map(|(_, n)| n).sum::<usize>();
    let (tv, tg) = (total(&vk), total(&gl));
    let mut s = String::from(
        "| Vulkan (`vk/src/`) | lines | OpenGL (`gl/src/`) | lines |\n|---|---:|---|---:|\n",
    );
    for i in 0..vk.len().max(gl.len()) {
        let cell = |v: &[(String, usize)]| {
            v.get(i).map_or(("".into(), "".into()), |(f, n)| {
                (format!("`{f}`"), n.to_string())
            })
        };
        let ((fv, nv), (fg, ng)) = (cell(&vk), cell(&gl));
        s += &format!("| {fv} | {nv} | {fg} | {ng} |\n");
    }
    s += &format!("| **total** | **{tv}** | **total** | **{tg}** |\n");
    s += &format!("\nVulkan needs {:.1}× the code of OpenGL for the same two paths (headless and windowed).\n", tv as f64 / tg as f64);
    s
}

#[test]
fn the_lines_of_code_table_matches_the_code() {
    let path = doc_path();
    let doc = std::fs::read_to_string(&path).unwrap();
    let (begin, end) = ("<!-- loc:begin -->\n", "<!-- loc:end -->");
    let start = doc.find(begin).expect("loc:begin marker") + begin.len();
    let stop = doc.find(end).expect("loc:end marker");
    let expected = loc_table();
    if doc[start..stop] == expected {
        return;
    }
    if std::env::var("TWINRAY_UPDATE_DOCS").is_ok_and(|v| v == "1") {
        let updated = format!("{}{}{}", &doc[..start], expected, &doc[stop..]);
        std::fs::write(&path, updated).unwrap();
        return;
    }
    panic!(
        "the walkthrough's lines-of-code table is out of date; run\n  TWINRAY_UPDATE_DOCS=1 cargo test --release -p twinray-tests --test walkthrough\nexpected:\n{expected}"
    );
}
