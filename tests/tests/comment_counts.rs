//! Comments and pages that count what `common/src/gpu/layout.rs` declares
//! count it right: the storage buffers, and each binding's own comment.

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

fn rust_sources(dir: &Path, text: &mut String) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_sources(&path, text);
        } else if path.extension().is_some_and(|e| e == "rs") {
            *text += &std::fs::read_to_string(&path).unwrap();
        }
    }
}

/// Counts that comments and pages give of the scene's storage buffers (`four
/// storage buffers`) are the count in `common/src/gpu/layout.rs`'s
/// `binding::STORAGE`, and every binding constant's doc comment names its own
/// binding, not a neighbour's (`5 is ...` over binding 6).
#[test]
fn comments_count_what_layout_rs_declares() {
    let layout = std::fs::read_to_string(root().join("common/src/gpu/layout.rs")).unwrap();
    let declared = layout
        .split("pub const STORAGE: [u32; ")
        .nth(1)
        .and_then(|rest| rest.split(']').next()?.parse::<usize>().ok())
        .expect("layout.rs declares binding::STORAGE");
    let numbers = [
        "one", "two", "three", "four", "five", "six", "seven", "eight", "nine", "ten",
    ];
    let mut texts = vec![(
        "docs/vulkan-walkthrough.md".to_string(),
        std::fs::read_to_string(doc_path()).unwrap(),
    )];
    for dir in ["vk/src", "gl/src", "common/src"] {
        let mut text = String::new();
        rust_sources(&root().join(dir), &mut text);
        texts.push((dir.to_string(), text));
    }
    let mut wrong = Vec::new();
    let mut seen = 0;
    for (name, text) in &texts {
        let words: Vec<&str> = text.split_whitespace().collect();
        for pair in words.windows(3) {
            if pair[1] != "storage" || !pair[2].starts_with("buffers") {
                continue;
            }
            let word = pair[0].trim_start_matches(['(', '`']).to_lowercase();
            let Some(n) = numbers.iter().position(|w| *w == word).map(|i| i + 1) else {
                continue;
            };
            seen += 1;
            if n != declared {
                wrong.push(format!(
                    "{name}: \"{} storage buffers\", layout.rs declares {declared}",
                    pair[0]
                ));
            }
        }
    }
    // A binding's doc comment that opens with a number speaks of that binding.
    let module = layout
        .split("pub mod binding {")
        .nth(1)
        .expect("layout.rs's binding module");
    let mut doc = String::new();
    for line in module.lines().map(str::trim) {
        if let Some(comment) = line.strip_prefix("///") {
            doc += comment;
            continue;
        }
        if let Some(rest) = line.strip_prefix("pub const ") {
            let value = rest
                .split('=')
                .nth(1)
                .map(|v| v.trim().trim_end_matches(';'));
            let opening: String = doc
                .trim()
                .chars()
                .take_while(char::is_ascii_digit)
                .collect();
            if let (false, Some(value)) = (opening.is_empty(), value) {
                if opening != value {
                    wrong.push(format!(
                        "layout.rs: the comment over `{rest}` speaks of binding {opening}"
                    ));
                }
            }
        }
        doc.clear();
    }
    assert!(
        seen >= 2,
        "only {seen} storage-buffer counts found: is the search still reading?"
    );
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}
