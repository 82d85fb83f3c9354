//! The docs stay true to the code. In every README and document: every file
//! named exists (in the repository, or as a name the code writes), every
//! `path::function` is still defined there, every relative link resolves. In
//! docs/vulkan-walkthrough.md also: its object diagram names types and calls
//! the two apps really use (the side-by-side tables: side_by_side.rs), every picture exists,
//! and its lines-of-code table is the one this test counts
//! (`TWINRAY_UPDATE_DOCS=1` rewrites the table instead of failing).

use std::path::{Path, PathBuf};
use twinray_tests::markdown::{citations, code_spans};
use twinray_tests::repo::{assert_scan, files_under, root, rust_sources, text, WALKTHROUGH};

/// Every README and document of the project.
fn documents() -> Vec<PathBuf> {
    let mut docs: Vec<PathBuf> = ["README.md", "CONTRIBUTING.md"]
        .iter()
        .map(|d| root().join(d))
        .collect();
    for dir in [
        "common",
        "vk",
        "gl",
        "comparison",
        "comparison/results",
        "tests",
        "scenes",
        "shaders",
    ] {
        docs.push(root().join(dir).join("README.md"));
    }
    if let Ok(entries) = std::fs::read_dir(root().join("docs")) {
        docs.extend(
            entries
                .map(|e| e.unwrap().path())
                .filter(|p| p.extension().is_some_and(|e| e == "md")),
        );
    }
    docs.retain(|d| d.is_file());
    docs.sort();
    docs
}

/// Every file of the repository (not the build output), relative to the root.
fn repository_files() -> Vec<String> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy();
            if (name.starts_with('.') && name != ".ci") || name == "target" {
                continue;
            }
            if path.is_dir() {
                walk(&path, out);
            } else {
                out.push(path);
            }
        }
    }
    let mut files = Vec::new();
    walk(&root(), &mut files);
    files
        .iter()
        .map(|f| f.strip_prefix(root()).unwrap().display().to_string())
        .collect()
}

/// A span that names a file: a path without spaces or placeholders whose last
/// part has an extension, optionally followed by `::Type::function` or `::function`.
fn file_reference(span: &str) -> Option<(String, Vec<String>)> {
    let (path, rest) = match span.split_once("::") {
        Some((p, r)) => (p, r.split("::").map(str::to_string).collect()),
        None => (span, Vec::new()),
    };
    let known = [
        "rs", "md", "glsl", "frag", "vert", "comp", "sh", "toml", "obj", "bpt", "png", "svg",
        "csv", "json", "lock",
    ];
    let placeholder = |c: char| " *<>{}$|=".contains(c);
    // A `COMMIT:PATH` names a file of an older commit, which findings.rs
    // opens with git; it need not be in today's tree.
    if !citations(path).is_empty() {
        return None;
    }
    let (_, extension) = path.rsplit_once('.')?;
    (!path.contains(placeholder) && !path.starts_with('-') && known.contains(&extension))
        .then(|| (path.to_string(), rest))
}

/// Where a referenced path lies: relative to the root, to the document's
/// folder, or (a bare file name) anywhere in the repository.
fn locate(path: &str, doc: &Path, files: &[String]) -> Option<PathBuf> {
    let candidates = [root().join(path), doc.parent().unwrap().join(path)];
    if let Some(found) = candidates.into_iter().find(|p| p.is_file()) {
        return Some(found);
    }
    if path.contains('/') {
        return None;
    }
    files
        .iter()
        .find(|f| f.rsplit('/').next() == Some(path))
        .map(|f| root().join(f))
}

/// File names the apps write (`report.md`, `statistics.json`, ...) are no
/// repository files; the code holds them as string literals.
fn written_by_the_code(name: &str, sources: &str) -> bool {
    let bare = name.rsplit('/').next().unwrap();
    sources.contains(&format!("\"{bare}\"")) || sources.contains(&format!("\"{bare}"))
}

/// `path::name` names a function, or a type, module or constant of that file.
fn defines_item(text: &str, name: &str) -> bool {
    let function = [format!("fn {name}("), format!("fn {name}<")];
    let other = ["struct", "enum", "trait", "mod", "const", "static", "type"]
        .map(|kind| format!("{kind} {name}"));
    let item = |pat: &String| {
        text.match_indices(pat.as_str()).any(|(i, _)| {
            !text[i + pat.len()..].starts_with(|c: char| c.is_alphanumeric() || c == '_')
        })
    };
    function.iter().any(|pat| text.contains(pat.as_str())) || other.iter().any(item)
}

fn defines_type(text: &str, owner: &str) -> bool {
    [
        format!("struct {owner}"),
        format!("impl {owner}"),
        format!("for {owner}"),
        format!("enum {owner}"),
    ]
    .iter()
    .any(|p| text.contains(p.as_str()))
}

#[test]
fn every_file_and_function_the_docs_name_exists() {
    let files = repository_files();
    let code = rust_sources(&["common", "vk", "gl", "comparison", "tests"]);
    let mut missing = Vec::new();
    let mut walkthrough_references = 0;
    for doc in documents() {
        let text = std::fs::read_to_string(&doc).unwrap();
        let shown = doc.strip_prefix(root()).unwrap().display().to_string();
        for span in code_spans(&text) {
            let Some((path, items)) = file_reference(&span) else {
                continue;
            };
            let Some(file) = locate(&path, &doc, &files) else {
                if items.is_empty() && written_by_the_code(&path, &code) {
                    continue;
                }
                missing.push(format!(
                    "{shown}: `{span}`: no file {path} in the repository"
                ));
                continue;
            };
            if doc == root().join(WALKTHROUGH) {
                walkthrough_references += 1;
            }
            let Some((function, owners)) = items.split_last() else {
                continue;
            };
            let text = std::fs::read_to_string(&file).unwrap_or_default();
            if !defines_item(&text, function) {
                missing.push(format!("{shown}: `{span}`: no {function} in {path}"));
            }
            for owner in owners.iter().filter(|o| !defines_type(&text, o)) {
                missing.push(format!("{shown}: `{span}`: no type {owner} in {path}"));
            }
        }
        // Relative links: [text](path#anchor).
        for part in text.split("](").skip(1) {
            let target = part.split(')').next().unwrap();
            let target = target.split('#').next().unwrap();
            if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            if !doc.parent().unwrap().join(target).exists() {
                missing.push(format!("{shown}: links to {target}, which does not exist"));
            }
        }
    }
    assert_scan(
        "the docs name things that are gone",
        &missing,
        walkthrough_references,
        40,
        "references in the walkthrough",
    );
}

#[test]
fn a_file_name_is_recognised_with_or_without_a_folder() {
    let r = |s: &str| file_reference(s).map(|(p, items)| (p, items.len()));
    assert_eq!(r("app.rs"), Some(("app.rs".into(), 0)));
    assert_eq!(
        r("vk/src/device.rs::Device::new"),
        Some(("vk/src/device.rs".into(), 2))
    );
    assert_eq!(r("FINDINGS.md"), Some(("FINDINGS.md".into(), 0)));
    assert_eq!(r("--out FILE.png"), None);
    assert_eq!(r("twinray-vk-<scene>-<n>.png"), None);
    assert_eq!(r("*.spv"), None);
    assert_eq!(r("vk::QueueFlags"), None);
}

fn calls_in(source: &str, name: &str) -> bool {
    source.contains(&format!("{name}("))
}

/// The object diagram's Vulkan half names ash types and calls of vk/src, each
/// type linked to its reference page; its OpenGL half glow types and calls of gl/src.
#[test]
fn the_object_diagram_names_what_the_code_uses() {
    let doc = text(WALKTHROUGH);
    let start = doc.find("```mermaid\n").expect("a mermaid diagram");
    let diagram = &doc[start + 3..];
    let diagram = &diagram[..diagram.find("```").unwrap()];
    let (vk_src, gl_src) = (rust_sources(&["vk/src"]), rust_sources(&["gl/src"]));
    let mut side = "";
    let mut missing = Vec::new();
    let mut checked = 0;
    for line in diagram.lines().map(str::trim) {
        if line.starts_with("subgraph vulkan") {
            side = "vk";
            continue;
        }
        if line.starts_with("subgraph opengl") {
            side = "gl";
            continue;
        }
        if line == "end" {
            side = "";
            continue;
        }
        let source = match side {
            "vk" => &vk_src,
            "gl" => &gl_src,
            _ => continue,
        };
        // Type names: ash::X, vk::X, glow::X, as the code writes them.
        for prefix in ["ash::", "vk::", "glow::"] {
            for part in line.split(prefix).skip(1) {
                let name: String = part
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                let written = format!("{prefix}{name}");
                let used = source.match_indices(&written).any(|(i, _)| {
                    !source[i + written.len()..]
                        .starts_with(|c: char| c.is_alphanumeric() || c == '_')
                });
                checked += 1;
                if !used {
                    missing.push(format!("{written} is not used in {side}/src"));
                }
                // Every Vulkan object links to its reference page somewhere on the page.
                let page = format!("/man/html/Vk{name}.html");
                if side == "vk" && name != "Entry" && !doc.contains(&page) {
                    missing.push(format!("no link to the reference page of Vk{name}"));
                }
            }
        }
        // Calls: the snake_case word after <br/> in a node, or on an edge.
        let words = line
            .split("<br/>")
            .skip(1)
            .chain(line.split("-- ").skip(1))
            .filter_map(|w| {
                let w: String = w
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                w.contains('_').then_some(w)
            });
        for call in words {
            checked += 1;
            if !calls_in(source, &call) {
                missing.push(format!("{call}(…) is not called in {side}/src"));
            }
        }
    }
    assert_scan(
        "the object diagram is out of step with the code or its links",
        &missing,
        checked,
        50,
        "names in the diagram",
    );
}

#[test]
fn every_picture_the_docs_show_exists() {
    for (doc, dir) in [
        (root().join(WALKTHROUGH), root().join("docs")),
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
    files_under(&dir, &["rs"])
        .iter()
        .map(|f| {
            let shown = f.strip_prefix(&dir).unwrap().display();
            (format!("{crate_dir}/src/{shown}"), code_lines(f))
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
    let path = root().join(WALKTHROUGH);
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

/// `vk/src/lib.rs` lists the modules in reading order, vk/README.md's table
/// gives the same order, and the walkthrough's steps meet the files (each
/// step's first `**Where.**` file) in that order too.
#[test]
fn one_reading_order_in_lib_rs_the_vk_readme_and_the_walkthrough() {
    let read = |p: &str| std::fs::read_to_string(root().join(p)).unwrap();
    let lib: Vec<String> = read("vk/src/lib.rs")
        .lines()
        .filter_map(|l| l.strip_prefix("pub mod ")?.strip_suffix(';'))
        .map(str::to_string)
        .collect();
    let readme: Vec<String> = read("vk/README.md")
        .lines()
        .filter_map(|l| l.split("| `src/").nth(1)?.split_once(".rs`"))
        .map(|(m, _)| m.to_string())
        .collect();
    assert_eq!(readme, lib, "vk/README.md's reading order is not lib.rs's");
    let mut met: Vec<String> = Vec::new();
    for line in read("docs/vulkan-walkthrough.md").lines() {
        let Some(rest) = line.strip_prefix("**Where.** `vk/src/") else {
            continue;
        };
        let module = rest.split(".rs").next().unwrap().to_string();
        if !met.contains(&module) {
            met.push(module);
        }
    }
    let positions: Vec<Option<usize>> = met
        .iter()
        .map(|m| lib.iter().position(|l| l == m))
        .collect();
    assert!(
        met.len() >= 10
            && positions.iter().all(Option::is_some)
            && positions.windows(2).all(|w| w[0] < w[1]),
        "the walkthrough meets vk/src's files as {met:?}, not in lib.rs's order {lib:?}"
    );
}

/// docs/architecture.md's map of `common` names every module of it: a file
/// `common/src/a/b.rs` as `b` (a folder's `mod.rs` as the folder's name).
#[test]
fn the_module_map_names_every_module_of_common() {
    let doc = text("docs/architecture.md");
    let start = doc
        .find("## The modules of `common`")
        .expect("docs/architecture.md has a section on the modules of `common`");
    let section = &doc[start..];
    let section = &section[..section[3..].find("\n## ").map_or(section.len(), |e| e + 3)];
    let mut files = Vec::new();
    let mut stack = vec![root().join("common/src")];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() && !path.ends_with("bin") {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                files.push(path);
            }
        }
    }
    let mut missing = Vec::new();
    for file in &files {
        let stem = file.file_stem().unwrap().to_string_lossy();
        let name = match stem.as_ref() {
            // The crate root, and unit tests kept in a file of their own.
            "lib" | "tests" => continue,
            "mod" => file
                .parent()
                .unwrap()
                .file_name()
                .unwrap()
                .to_string_lossy(),
            _ => stem,
        };
        let named = [
            format!("`{name}`"),
            format!("`{name}/`"),
            format!("::{name}`"),
        ];
        if !named.iter().any(|n| section.contains(n.as_str())) {
            missing.push(file.strip_prefix(root()).unwrap().display().to_string());
        }
    }
    assert!(files.len() > 10, "only {} files in common/src", files.len());
    assert!(
        missing.is_empty(),
        "docs/architecture.md's map of `common` does not name {}",
        missing.join(", ")
    );
}
