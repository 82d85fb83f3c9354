//! Reading Markdown as the page tests do: prose outside code blocks, the
//! anchors GitHub gives headings, the targets of links, and whether a
//! relative link leads anywhere. One reader for the page tests,
//! so that the two cannot disagree on what a link or a heading is.

use crate::repo::{assert_scan, read, root};
use std::path::Path;

/// A line without its inline code spans (`like this`).
pub fn without_code_spans(line: &str) -> String {
    line.split('`').step_by(2).collect::<Vec<_>>().join(" ")
}

/// The lines of a Markdown text outside fenced code blocks.
pub fn prose(text: &str) -> Vec<&str> {
    let mut in_block = false;
    let mut lines = Vec::new();
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            in_block = !in_block;
        } else if !in_block {
            lines.push(line);
        }
    }
    lines
}

/// The inline code spans of a text's prose, e.g. `vk/src/device.rs::Device::new`.
pub fn code_spans(text: &str) -> Vec<String> {
    prose(text)
        .iter()
        .flat_map(|line| line.split('`').skip(1).step_by(2).map(str::to_string))
        .collect()
}

/// Every `COMMIT:PATH` a line cites: an abbreviated or full commit (7 to 40
/// hexadecimal digits), a colon, and a path.
pub fn citations(line: &str) -> Vec<String> {
    line.split(|c: char| c.is_whitespace() || "()\"'`,;<>[]*".contains(c))
        .filter_map(|word| {
            let word = word.trim_end_matches(['.', ':']);
            let (commit, path) = word.split_once(':')?;
            let hex = (7..=40).contains(&commit.len())
                && commit
                    .chars()
                    .all(|c| c.is_ascii_hexdigit() && !c.is_ascii_uppercase());
            (hex && !path.is_empty() && !path.contains(':') && !path.starts_with('/'))
                .then(|| word.to_string())
        })
        .collect()
}

/// The anchor GitHub gives a heading: lower case, everything but letters,
/// digits, spaces, `-` and `_` dropped, each space a hyphen.
pub fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, ' ' | '-' | '_'))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The anchors of a page's headings; a repeated heading gets `-1`, `-2`, …
pub fn anchors(text: &str) -> Vec<String> {
    let mut found: Vec<String> = Vec::new();
    for line in prose(text) {
        let Some(heading) = line.strip_prefix('#') else {
            continue;
        };
        let heading = heading.trim_start_matches('#');
        if !heading.starts_with(' ') {
            continue;
        }
        let base = slug(heading);
        let numbered = |a: &str| {
            a.strip_prefix(&format!("{base}-"))
                .is_some_and(|n| n.parse::<u32>().is_ok())
        };
        let repeats = found.iter().filter(|a| **a == base || numbered(a)).count();
        found.push(if repeats == 0 {
            base
        } else {
            format!("{base}-{repeats}")
        });
    }
    found
}

/// The targets of a text's Markdown links and images, `[text](target)`,
/// outside code blocks and code spans; a link's title is dropped.
pub fn links(text: &str) -> Vec<String> {
    let mut targets = Vec::new();
    for line in prose(text) {
        let line = without_code_spans(line);
        for part in line.split("](").skip(1) {
            if let Some(end) = part.find(')') {
                let target = part[..end].split_whitespace().next().unwrap_or("");
                targets.push(target.to_string());
            }
        }
    }
    targets
}

/// Why `target`, linked from the page `from`, leads nowhere; `None` where it
/// resolves. Web addresses are not followed.
pub fn broken(from: &Path, target: &str) -> Option<String> {
    if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
        return None;
    }
    let (path, anchor) = match target.split_once('#') {
        Some((p, a)) => (p, Some(a)),
        None => (target, None),
    };
    let file = if path.is_empty() {
        from.to_path_buf()
    } else {
        from.parent().unwrap().join(path)
    };
    if !file.exists() {
        return Some(format!("{target}: no file {}", file.display()));
    }
    let anchor = anchor?;
    if file.extension().is_none_or(|e| e != "md") {
        return Some(format!(
            "{target}: an anchor into a file that is not Markdown"
        ));
    }
    if !anchors(&read(&file)).iter().any(|a| a == anchor) {
        return Some(format!(
            "{target}: no heading with the anchor #{anchor} in {path}"
        ));
    }
    None
}

/// Every relative link of the `pages` (relative to the root) leads somewhere,
/// and at least `min` links were read.
pub fn assert_links_resolve<S: AsRef<str>>(pages: &[S], min: usize, what: &str) {
    let mut broken_links = Vec::new();
    let mut checked = 0;
    for page in pages {
        let page = page.as_ref();
        let path = root().join(page);
        for target in links(&read(&path)) {
            checked += 1;
            if let Some(why) = broken(&path, &target) {
                broken_links.push(format!("{page}: {why}"));
            }
        }
    }
    assert_scan("links that lead nowhere", &broken_links, checked, min, what);
}
