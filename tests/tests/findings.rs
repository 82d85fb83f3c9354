//! The findings stay answers, and what they cite stays reachable
//! (docs/findings/README.md):
//! - every `COMMIT:PATH` that tracked Markdown cites opens with `git show`
//!   (`git cat-file -e`); in a shallow clone this part says why it cannot run
//!   and is skipped;
//! - every relative link of every tracked Markdown file reaches a file or
//!   folder, and a heading where it names one (`page.md#anchor`);
//! - every findings page is at most 300 lines and opens with its verdict: at
//!   most 10 lines of prose between its title and its first section;
//! - the index links every page;
//! - no figure (a number with a unit: ms, s, ns, Grays/s, MB, GB, MiB, KiB,
//!   or a ratio such as 1.13× or ×3.6) is stated on two findings pages: each
//!   lives on one page, and the others link to it.

use std::collections::BTreeMap;
use std::io::Write;
use std::process::{Command, Stdio};
use twinray_tests::assert_none;
use twinray_tests::markdown::{
    anchors, assert_links_resolve, citations, links, prose, without_code_spans,
};
use twinray_tests::repo::{assert_scan, read, root};

const FINDINGS: &str = "docs/findings";
const INDEX: &str = "README.md";
const MAX_PAGE_LINES: usize = 300;
const MAX_VERDICT_LINES: usize = 10;

/// `git ARGS` in the repository's root; its stdout, or `None` where git is
/// missing or this is no git checkout.
fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git")
        .args(args)
        .current_dir(root())
        .output()
        .ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).into_owned())
}

/// The Markdown files git tracks, or would (new and not ignored), that are in
/// the working tree, relative to the root.
fn tracked_markdown() -> Vec<String> {
    let listed = git(&[
        "ls-files",
        "--cached",
        "--others",
        "--exclude-standard",
        "--",
        "*.md",
    ])
    .expect("git ls-files: these checks read the tracked Markdown files");
    listed
        .lines()
        .filter(|f| root().join(f).is_file())
        .map(str::to_string)
        .collect()
}

/// The findings pages, the index aside, as (file name, text).
fn findings_pages() -> Vec<(String, String)> {
    let dir = root().join(FINDINGS);
    let mut pages: Vec<(String, String)> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .filter(|p| p.file_name().is_some_and(|n| n != INDEX))
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                read(&p),
            )
        })
        .collect();
    pages.sort();
    pages
}

/// The figures a line states: a number followed by a unit (`0.233 ms`,
/// `13.7 Grays/s`, `1.13×`) or a ratio written `×3.62`. Code spans are
/// commands, not figures, and are left out; so are workgroup shapes (`8×4`).
fn figures(line: &str) -> Vec<String> {
    const UNITS: [&str; 10] = [
        "Grays/s", "Mrays/s", "ms", "ns", "s", "MB", "GB", "MiB", "KiB", "KB",
    ];
    let line = without_code_spans(line).replace('\u{a0}', " ");
    let chars: Vec<char> = line.chars().collect();
    let mut found = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let starts_number = chars[i].is_ascii_digit()
            && (i == 0 || !(chars[i - 1].is_alphanumeric() || chars[i - 1] == '.'));
        if !starts_number {
            i += 1;
            continue;
        }
        // `×3.62` is a ratio; the 4 of `8×4` is a shape's second side.
        let prefixed_by_times =
            i > 0 && chars[i - 1] == '×' && (i < 2 || !chars[i - 2].is_ascii_digit());
        let mut j = i;
        while j < chars.len()
            && (chars[j].is_ascii_digit()
                || (matches!(chars[j], '.' | ',')
                    && chars.get(j + 1).is_some_and(char::is_ascii_digit)))
        {
            j += 1;
        }
        let number: String = chars[i..j].iter().collect();
        let rest: String = chars[j..].iter().collect();
        let after_space = rest.strip_prefix(' ').unwrap_or(&rest);
        if prefixed_by_times {
            found.push(format!("×{number}"));
        } else if let Some(tail) = rest.strip_prefix('×') {
            // 8×4 is a workgroup shape, 1000×1000 a size: no figure.
            if !tail.starts_with(|c: char| c.is_ascii_digit()) {
                found.push(format!("{number}×"));
            }
        } else if let Some(unit) = UNITS.iter().find(|u| {
            after_space.starts_with(*u)
                && !after_space[u.len()..].starts_with(|c: char| c.is_alphanumeric())
        }) {
            found.push(format!("{number} {unit}"));
        }
        i = j.max(i + 1);
    }
    found
}

#[test]
fn every_cited_commit_path_opens() {
    let mut cited: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for file in tracked_markdown() {
        for (n, line) in read(&root().join(&file)).lines().enumerate() {
            for citation in citations(line) {
                cited
                    .entry(citation)
                    .or_default()
                    .push(format!("{file}:{}", n + 1));
            }
        }
    }
    assert!(
        cited.len() >= 10,
        "only {} COMMIT:PATH citations found in the tracked Markdown: is the search still reading it?",
        cited.len()
    );
    if git(&["rev-parse", "--is-shallow-repository"]).is_some_and(|s| s.trim() == "true") {
        println!(
            "skipped: this clone is shallow, so the {} cited COMMIT:PATHs cannot be opened; \
             `git fetch --unshallow` gives the history they live in",
            cited.len()
        );
        return;
    }
    let mut child = Command::new("git")
        .args(["cat-file", "--batch-check"])
        .current_dir(root())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("git cat-file");
    let mut input = String::new();
    for citation in cited.keys() {
        input += citation;
        input.push('\n');
    }
    child
        .stdin
        .take()
        .unwrap()
        .write_all(input.as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "git cat-file --batch-check failed");
    let answers = String::from_utf8_lossy(&out.stdout);
    let answers: Vec<&str> = answers.lines().collect();
    assert_eq!(answers.len(), cited.len(), "one answer per citation");
    let missing: Vec<String> = cited
        .iter()
        .zip(&answers)
        .filter(|(_, answer)| answer.ends_with(" missing") || answer.ends_with(" ambiguous"))
        .map(|((citation, places), _)| format!("{citation} (cited at {})", places.join(", ")))
        .collect();
    assert_none("cited COMMIT:PATHs that `git show` cannot open", &missing);
}

#[test]
fn every_relative_link_of_the_markdown_resolves() {
    assert_links_resolve(&tracked_markdown(), 100, "links in the tracked Markdown");
}

#[test]
fn every_findings_page_opens_with_its_verdict() {
    let pages = findings_pages();
    assert!(pages.len() >= 5, "only {} findings pages", pages.len());
    let mut wrong = Vec::new();
    for (name, text) in &pages {
        let lines: Vec<&str> = text.lines().collect();
        if lines.len() > MAX_PAGE_LINES {
            wrong.push(format!(
                "{name}: {} lines, more than {MAX_PAGE_LINES}: split the question",
                lines.len()
            ));
        }
        if !lines.first().is_some_and(|l| l.starts_with("# ")) {
            wrong.push(format!(
                "{name}: the first line is not the page's title (`# …`)"
            ));
            continue;
        }
        let verdict: Vec<&str> = lines[1..]
            .iter()
            .take_while(|l| !l.starts_with("## "))
            .filter(|l| !l.trim().is_empty())
            .copied()
            .collect();
        if verdict.is_empty() || verdict.len() > MAX_VERDICT_LINES {
            wrong.push(format!(
                "{name}: the verdict before the first section is {} lines, not 1 to {MAX_VERDICT_LINES}",
                verdict.len()
            ));
        }
        if verdict
            .iter()
            .any(|l| l.starts_with('|') || l.starts_with('#'))
        {
            wrong.push(format!("{name}: the verdict holds a table or heading"));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn the_index_lists_every_page() {
    let index = read(&root().join(FINDINGS).join(INDEX));
    let listed = links(&index);
    let missing: Vec<String> = findings_pages()
        .into_iter()
        .map(|(name, _)| name)
        .filter(|name| !listed.iter().any(|l| l.split('#').next() == Some(name)))
        .collect();
    assert!(
        missing.is_empty(),
        "{FINDINGS}/{INDEX} does not list: {}",
        missing.join(", ")
    );
}

#[test]
fn no_figure_is_stated_on_two_findings_pages() {
    let mut pages = findings_pages();
    pages.push((INDEX.to_string(), read(&root().join(FINDINGS).join(INDEX))));
    let mut seen: BTreeMap<String, Vec<String>> = BTreeMap::new();
    let mut total = 0;
    for (name, text) in &pages {
        for line in prose(text) {
            for figure in figures(line) {
                total += 1;
                let on = seen.entry(figure).or_default();
                if !on.contains(name) {
                    on.push(name.clone());
                }
            }
        }
    }
    let twice: Vec<String> = seen
        .iter()
        .filter(|(_, on)| on.len() > 1)
        .map(|(figure, on)| format!("{figure}: {}", on.join(", ")))
        .collect();
    assert_scan(
        "figures stated on more than one findings page (keep each on one, link from the others)",
        &twice,
        total,
        50,
        "figures on the findings pages",
    );
}

#[test]
fn the_parsers_read_what_the_pages_write() {
    assert_eq!(
        citations("(`f8d14ba:comparison/results/nvidia-h100/investigation/fma-pad/`)."),
        ["f8d14ba:comparison/results/nvidia-h100/investigation/fma-pad/"]
    );
    assert!(citations("at 17:48, see docs/a.md: 3 ms").is_empty());
    assert_eq!(
        figures(
            "0.233 ms and 13.7 Grays/s, 1.13× Vulkan's, ×3.62, 8×4 and `--size 1000x1000 2 ms`"
        ),
        ["0.233 ms", "13.7 Grays/s", "1.13×", "×3.62"]
    );
    assert_eq!(
        figures("1,277 ms, 4 MiB; 2,048 invocations"),
        ["1,277 ms", "4 MiB"]
    );
    assert_eq!(
        links("[a](x.md#y \"t\") `[c](code.md)` ![b](i.png)\n"),
        ["x.md#y", "i.png"]
    );
    assert_eq!(
        anchors("# A\n```\n# not a heading\n```\n## A\n### B: c\n"),
        ["a", "a-1", "b-c"]
    );
}
