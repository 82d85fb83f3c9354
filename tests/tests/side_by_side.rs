//! docs/vulkan-walkthrough.md's per-step "Vulkan (ash) | OpenGL (glow)"
//! tables quote calls the two apps really make, each with the arguments the
//! code passes: a name alone let `draw_arrays(glow::TRIANGLES, 0, 3)` stand for
//! the headless draw of `pass.vertices()` vertices.

use twinray_tests::markdown::code_spans;
use twinray_tests::repo::{assert_scan, rust_sources, text, WALKTHROUGH};

/// Identifiers directly followed by `(`: the functions a snippet calls.
fn called(snippet: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut current = String::new();
    for c in snippet.chars() {
        if c.is_alphanumeric() || c == '_' {
            current.push(c);
            continue;
        }
        let function = current.starts_with(|f: char| f.is_lowercase() || f == '_');
        if c == '(' && function {
            names.push(current.clone());
        }
        current.clear();
    }
    names
}

/// Each call of a snippet with its arguments, as written: `name(args)`, the
/// parentheses balanced. `…` in the arguments marks some left out.
fn calls_with_arguments(snippet: &str) -> Vec<String> {
    let mut calls = Vec::new();
    for name in called(snippet) {
        let Some(start) = snippet.find(&format!("{name}(")) else {
            continue;
        };
        let mut depth = 0;
        for (i, c) in snippet[start..].char_indices() {
            match c {
                '(' => depth += 1,
                ')' => depth -= 1,
                _ => continue,
            }
            if depth == 0 {
                calls.push(snippet[start..start + i + 1].to_string());
                break;
            }
        }
    }
    calls
}

/// Without whitespace, and without the trailing comma rustfmt adds to a
/// call it wraps.
fn squeezed(text: &str) -> String {
    let text: String = text.chars().filter(|c| !c.is_whitespace()).collect();
    text.replace(",)", ")")
}

/// The call, arguments and all, is in the code; where `…` leaves some out,
/// the parts around it are.
fn call_in(squeezed_source: &str, call: &str) -> bool {
    squeezed(call)
        .split('…')
        .all(|part| squeezed_source.contains(part))
}

/// The per-step "Vulkan (ash) | OpenGL (glow)" tables quote calls the two apps
/// really make, with the arguments they make them with.
#[test]
fn the_side_by_side_calls_are_in_the_code() {
    let doc = text(WALKTHROUGH);
    let (vk_sq, gl_sq) = (
        squeezed(&rust_sources(&["vk/src"])),
        squeezed(&rust_sources(&["gl/src"])),
    );
    let mut in_table = false;
    let mut missing = Vec::new();
    let (mut tables, mut checked) = (0, 0);
    for line in doc.lines() {
        if line.starts_with("| Vulkan (ash) | OpenGL (") {
            in_table = true;
            tables += 1;
            continue;
        }
        if !line.starts_with('|') {
            in_table = false;
            continue;
        }
        if !in_table || line.starts_with("|---") {
            continue;
        }
        // Split on cell borders, not on `\|` inside a closure's code span.
        let cells: Vec<String> = line
            .replace("\\|", "¦")
            .trim()
            .trim_matches('|')
            .split('|')
            .map(str::to_string)
            .collect();
        for (cell, (side, source)) in cells.iter().zip([("vk", &vk_sq), ("gl", &gl_sq)]) {
            for span in code_spans(cell) {
                // Each call with its arguments: `draw_arrays(…, 0, 3)` where the
                // code draws `pass.vertices()` vertices is a different call.
                for call in calls_with_arguments(&span.replace('¦', "|")) {
                    checked += 1;
                    if !call_in(source, &call) {
                        missing.push(format!("`{span}`: {call} is not in {side}/src"));
                    }
                }
            }
        }
    }
    assert_scan(
        "the side-by-side tables quote calls the code does not make",
        &missing,
        checked,
        60,
        "calls in the tables",
    );
    assert!(tables >= 15, "only {tables} side-by-side tables found");
}

#[test]
fn a_quoted_call_is_held_to_its_arguments() {
    let code = squeezed("gl.draw_arrays(glow::TRIANGLES, 0, pass.vertices() as i32);");
    let calls = calls_with_arguments("`gl.draw_arrays(glow::TRIANGLES, 0, 3)`, every frame");
    assert_eq!(calls, ["draw_arrays(glow::TRIANGLES, 0, 3)"]);
    assert!(
        !call_in(&code, &calls[0]),
        "a different vertex count passed"
    );
    assert!(call_in(
        &code,
        "draw_arrays(glow::TRIANGLES, 0, pass.vertices() as i32)"
    ));
    assert!(call_in(&code, "draw_arrays(…, pass.vertices() as i32)"));
}
