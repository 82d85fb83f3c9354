//! The front pages stay short and lead somewhere: README.md is a five-minute
//! read (at most 150 lines); every relative link of README.md,
//! comparison/results/README.md and tests/README.md reaches a file or folder,
//! and where it names a heading (`page.md#anchor`) that page has the heading;
//! and every `page.md#anchor` a code comment cites (a findings page instead
//! of a timing that would go stale, the module map in docs/architecture.md)
//! names a heading that is there; and the Rust version the pages ask a
//! newcomer to install is the one cargo enforces.

use std::path::PathBuf;
use twinray_tests::markdown::{anchors, assert_links_resolve, broken, links, slug};
use twinray_tests::repo::{assert_scan, files_under, read, root};

const MAX_README_LINES: usize = 150;

/// The pages a newcomer reads first, relative to the root.
const FRONT_PAGES: [&str; 3] = [
    "README.md",
    "comparison/results/README.md",
    "tests/README.md",
];

/// Where code comments may cite a page, and the files read there.
const CODE_DIRS: [&str; 5] = [
    "common/src",
    "vk/src",
    "gl/src",
    "comparison/src",
    "shaders",
];
const CODE_EXTENSIONS: [&str; 5] = ["rs", "glsl", "frag", "comp", "vert"];

/// Every `path.md#anchor` written in a line, as the text cites it.
fn cited_anchors(line: &str) -> Vec<String> {
    line.split(|c: char| c.is_whitespace() || "()\"'`,;<>[]".contains(c))
        .filter(|word| word.contains(".md#"))
        .map(|word| word.trim_end_matches(['.', ':']).to_string())
        .collect()
}

#[test]
fn the_readme_is_a_five_minute_read() {
    let lines = read(&root().join("README.md")).lines().count();
    assert!(
        lines <= MAX_README_LINES,
        "README.md has {lines} lines, more than {MAX_README_LINES}: move the detail to the page \
         that owns it (docs/architecture.md, comparison/results/README.md, tests/README.md) and link to it"
    );
}

#[test]
fn every_link_of_the_front_pages_resolves() {
    assert_links_resolve(&FRONT_PAGES, 20, "links on the front pages");
}

#[test]
fn every_page_a_code_comment_cites_has_the_heading() {
    let files = CODE_DIRS
        .iter()
        .flat_map(|dir| files_under(&root().join(dir), &CODE_EXTENSIONS));
    let mut missing = Vec::new();
    let mut checked = 0;
    for file in files {
        let shown = file.strip_prefix(root()).unwrap().display().to_string();
        for (n, line) in read(&file).lines().enumerate() {
            for cited in cited_anchors(line) {
                checked += 1;
                // Code cites pages from the repository's root.
                if let Some(why) = broken(&root().join("README.md"), &cited) {
                    missing.push(format!("{shown}:{}: {why}", n + 1));
                }
            }
        }
    }
    assert_scan(
        "code comments cite sections that are not there",
        &missing,
        checked,
        5,
        "cited sections in the code",
    );
}

#[test]
fn anchors_are_githubs() {
    assert_eq!(
        slug(" Local memory and OpenGL's multiprocessors (`investigation/gl-multiprocessors/`)"),
        "local-memory-and-opengls-multiprocessors-investigationgl-multiprocessors"
    );
    assert_eq!(slug(" `--set` keys"), "--set-keys");
    assert_eq!(
        slug(" naga does not short-circuit `&&` and `||` (`x/`)"),
        "naga-does-not-short-circuit--and--x"
    );
    assert_eq!(
        anchors("# A\n```\n# not a heading\n```\n## A\n#hashtag\n### B: c\n"),
        ["a", "a-1", "b-c"]
    );
    assert_eq!(
        links("[a](x.md#y) ![b](i.png)\n```\n[c](not-a-link.md)\n```\n"),
        ["x.md#y", "i.png"]
    );
    assert_eq!(
        cited_anchors("// (see docs/architecture.md#the-tracers-parts)."),
        ["docs/architecture.md#the-tracers-parts"]
    );
}

/// The Rust a newcomer must install is the `rust-version` that cargo enforces:
/// README.md and CONTRIBUTING.md name it, and said 1.85 after the workspace
/// had moved to 1.86.
#[test]
fn the_pages_name_the_rust_version_cargo_enforces() {
    let manifest = read(&root().join("Cargo.toml"));
    let version = manifest
        .lines()
        .find_map(|l| l.trim().strip_prefix("rust-version = "))
        .map(|v| v.trim_matches('"'))
        .expect("Cargo.toml sets rust-version");
    for page in ["README.md", "CONTRIBUTING.md"] {
        let text = read(&root().join(page));
        let named: Vec<&str> = text
            .split("Rust ")
            .skip(1)
            .filter_map(|rest| rest.split_once(" or newer").map(|(v, _)| v))
            .filter(|v| !v.is_empty() && v.chars().all(|c| c.is_ascii_digit() || c == '.'))
            .collect();
        assert!(
            !named.is_empty(),
            "{page} does not say which Rust to install (\"Rust {version} or newer\")"
        );
        assert!(
            named.iter().all(|v| *v == version),
            "{page} names Rust {named:?}, but Cargo.toml's rust-version is {version}"
        );
    }
}

/// The README opens with the study's verdict: the table between its summary
/// markers, within the first 40 lines, is exactly what `twinray summary`
/// prints over the committed compare folders, so a new result cannot land
/// without the table that states it.
#[test]
fn the_readme_verdict_is_what_twinray_summary_prints() {
    let readme = read(&root().join("README.md"));
    let begin = "<!-- twinray summary: begin -->\n";
    let end = "<!-- twinray summary: end -->";
    let (Some(b), Some(e)) = (readme.find(begin), readme.find(end)) else {
        panic!("README.md lacks the '{begin}' and '{end}' markers around its verdict table");
    };
    let end_line = readme[..e].lines().count() + 1;
    assert!(
        end_line <= 40,
        "the verdict table must end within README.md's first 40 lines; its end marker is on line {end_line}"
    );
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(root().join("comparison/results"))
        .unwrap()
        .flatten()
        .filter(|m| m.path().is_dir())
        .flat_map(|m| std::fs::read_dir(m.path()).unwrap().flatten())
        .map(|e| e.path())
        .filter(|p| {
            p.is_dir()
                && p.file_name()
                    .is_some_and(|n| n.to_string_lossy().starts_with("compare"))
        })
        .collect();
    // The shell's glob order: the README's command is `comparison/results/*/compare*`.
    dirs.sort();
    assert!(
        !dirs.is_empty(),
        "no compare folder under comparison/results"
    );
    let mut args = vec!["summary".to_string()];
    args.extend(dirs.iter().map(|d| d.display().to_string()));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = twinray_tests::run_ok(&twinray_tests::bin("twinray"), &args, &[]);
    let printed = String::from_utf8(out.stdout).unwrap();
    assert_eq!(
        &readme[b + begin.len()..e],
        printed,
        "README.md's verdict table is not what `twinray summary comparison/results/*/compare*` prints; paste its output between the markers"
    );
}
