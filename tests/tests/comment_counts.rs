//! Comments and pages that count what `common/src/gpu/layout.rs` declares
//! count it right: the storage buffers, and each binding's own comment.

use twinray_tests::repo::{assert_scan, rust_sources, text, WALKTHROUGH};

/// Counts that comments and pages give of the scene's storage buffers (`four
/// storage buffers`) are the count in `common/src/gpu/layout.rs`'s
/// `binding::STORAGE`, and every binding constant's doc comment names its own
/// binding, not a neighbour's (`5 is ...` over binding 6).
#[test]
fn comments_count_what_layout_rs_declares() {
    let layout = text("common/src/gpu/layout.rs");
    let declared = layout
        .split("pub const STORAGE: [u32; ")
        .nth(1)
        .and_then(|rest| rest.split(']').next()?.parse::<usize>().ok())
        .expect("layout.rs declares binding::STORAGE");
    let numbers = [
        "one", "two", "three", "four", "five", "six", "seven", "eight", "nine", "ten",
    ];
    let mut texts = vec![(WALKTHROUGH.to_string(), text(WALKTHROUGH))];
    for dir in ["vk/src", "gl/src", "common/src"] {
        texts.push((dir.to_string(), rust_sources(&[dir])));
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
    assert_scan(
        "counts that are not layout.rs's",
        &wrong,
        seen,
        2,
        "storage-buffer counts",
    );
}
