//! docs/vulkan-walkthrough.md's steps against the code they teach: every line
//! of a step's snippet is in a file its **Where.** names (whitespace aside, so
//! rustfmt may rewrap it), each step has one snippet, `--explain` prints the
//! objects of a headless run with the page's step numbers in the order the
//! page states, and the main path, before the appendix, reads in one sitting.

use twinray_tests::repo::{assert_scan, root, text, WALKTHROUGH};
use twinray_tests::{assert_none, box_window};

/// One `## N. Title` section of the page.
struct Step {
    number: u32,
    text: String,
}

fn steps(doc: &str) -> Vec<Step> {
    let mut steps: Vec<Step> = Vec::new();
    let mut current: Option<Step> = None;
    for line in doc.lines() {
        if line.starts_with("# ") || line.starts_with("## ") {
            steps.extend(current.take());
            let number = line
                .strip_prefix("## ")
                .and_then(|rest| rest.split_once(". "))
                .and_then(|(n, _)| n.parse().ok());
            current = number.map(|number| Step {
                number,
                text: String::new(),
            });
        }
        if let Some(step) = &mut current {
            step.text += line;
            step.text.push('\n');
        }
    }
    steps.extend(current);
    steps
}

/// The files a step's `**Where.**` paragraph names (`vk/src/x.rs::f` → `vk/src/x.rs`).
fn where_files(step: &str) -> Vec<String> {
    let Some(start) = step.find("**Where.**") else {
        return Vec::new();
    };
    let paragraph = &step[start..];
    let paragraph = &paragraph[..paragraph.find("\n\n").unwrap_or(paragraph.len())];
    paragraph
        .split('`')
        .skip(1)
        .step_by(2)
        .map(|span| span.split("::").next().unwrap().to_string())
        .filter(|path| path.contains('/') && path.ends_with(".rs"))
        .collect()
}

/// The ```rust blocks of a text, each as its lines.
fn rust_snippets(text: &str) -> Vec<Vec<String>> {
    let mut snippets = Vec::new();
    let mut open: Option<Vec<String>> = None;
    for line in text.lines() {
        match (&mut open, line.trim_start()) {
            (None, l) if l.starts_with("```rust") => open = Some(Vec::new()),
            (Some(_), l) if l.starts_with("```") => snippets.extend(open.take()),
            (Some(lines), _) => lines.push(line.to_string()),
            _ => {}
        }
    }
    snippets
}

fn squeezed(text: &str) -> String {
    text.chars().filter(|c| !c.is_whitespace()).collect()
}

#[test]
fn every_snippet_line_is_in_a_file_its_step_names() {
    let doc = text(WALKTHROUGH);
    let steps = steps(&doc);
    assert!(
        steps.len() >= 22,
        "only {} numbered steps found",
        steps.len()
    );
    let mut wrong = Vec::new();
    let mut checked = 0;
    for step in &steps {
        let snippets = rust_snippets(&step.text);
        if snippets.len() != 1 {
            wrong.push(format!(
                "step {} has {} snippets, not one",
                step.number,
                snippets.len()
            ));
        }
        let files: Vec<(String, String)> = where_files(&step.text)
            .into_iter()
            .filter_map(|f| {
                let text = std::fs::read_to_string(root().join(&f)).ok()?;
                Some((f, squeezed(&text)))
            })
            .collect();
        if files.is_empty() {
            wrong.push(format!(
                "step {} names no source file under **Where.**",
                step.number
            ));
            continue;
        }
        for line in snippets.iter().flatten() {
            // `// ...` marks lines left out; anything else is quoted verbatim.
            let line = line.trim();
            if line.is_empty() || line == "// ..." {
                continue;
            }
            checked += 1;
            if !files.iter().any(|(_, text)| text.contains(&squeezed(line))) {
                let names: Vec<&str> = files.iter().map(|(f, _)| f.as_str()).collect();
                wrong.push(format!(
                    "step {}: `{line}` is in none of {}",
                    step.number,
                    names.join(", ")
                ));
            }
        }
    }
    assert_scan(
        "the walkthrough's snippets are out of step with the code",
        &wrong,
        checked,
        50,
        "snippet lines",
    );
}

/// The page's table of `--explain` orders: each row a command and the step
/// numbers it prints, in order.
fn stated_orders(doc: &str) -> Vec<(Vec<String>, Vec<u32>)> {
    doc.lines()
        .filter_map(|line| {
            let rest = line.strip_prefix("| `twinray-vk ")?;
            let (command, numbers) = rest.split_once("` |")?;
            let numbers = numbers
                .trim()
                .trim_end_matches('|')
                .split(',')
                .map(|n| n.trim().parse().ok())
                .collect::<Option<Vec<u32>>>()?;
            Some((
                command.split_whitespace().map(str::to_string).collect(),
                numbers,
            ))
        })
        .collect()
}

/// `[ n]` of each `--explain` line, with the line's title.
fn explained(stderr: &str) -> Vec<(u32, String)> {
    stderr
        .lines()
        .filter_map(|line| {
            let (n, title) = line.strip_prefix('[')?.split_once(']')?;
            let title = title.split_once(" ms  ").map_or("", |(_, t)| t);
            Some((n.trim().parse().ok()?, title.to_string()))
        })
        .collect()
}

#[test]
fn explain_prints_the_pages_steps_in_the_pages_order() {
    let doc = text(WALKTHROUGH);
    let steps = steps(&doc);
    let orders = stated_orders(&doc);
    assert_eq!(
        orders.len(),
        2,
        "the page states the order of two headless runs"
    );
    let program = twinray_tests::bin("twinray-vk");
    let mut wrong = Vec::new();
    for (command, stated) in &orders {
        let mut args: Vec<&str> = command.iter().map(String::as_str).collect();
        args.extend(["--size", "32x32"]);
        let out = twinray_tests::run(&program, &args, &[]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            out.status.success(),
            "twinray-vk {args:?} failed:\n{stderr}"
        );
        let lines = explained(&stderr);
        let mut printed: Vec<u32> = lines.iter().map(|(n, _)| *n).collect();
        printed.dedup();
        if &printed != stated {
            wrong.push(format!(
                "twinray-vk {}: the page says the steps come as {stated:?}, --explain printed {printed:?}",
                command.join(" ")
            ));
        }
        // Each Vulkan object a line names is one its step's section speaks of.
        for (n, title) in lines.iter().filter(|(n, _)| *n > 0) {
            let Some(step) = steps.iter().find(|s| s.number == *n) else {
                wrong.push(format!("[{n}] {title}: the page has no step {n}"));
                continue;
            };
            for object in title
                .split(|c: char| !c.is_alphanumeric())
                .filter(|w| w.starts_with("Vk"))
            {
                if !step.text.contains(object) {
                    wrong.push(format!("[{n}] {title}: step {n} never names {object}"));
                }
            }
        }
    }
    assert_none("--explain and the walkthrough disagree", &wrong);
}

#[test]
fn the_main_path_reads_in_one_sitting() {
    let doc = text(WALKTHROUGH);
    let end = doc
        .find("\n# Appendix")
        .expect("the walkthrough has an appendix");
    let words = doc[..end].split_whitespace().count();
    assert!(
        words <= 4500,
        "the walkthrough's main path has {words} words, more than 4,500: move a detour to the appendix"
    );
    assert!(words > 2000, "only {words} words before the appendix");
}

/// Step 20's drop order is the window's: the `Type::drop`s its **Where.**
/// names after the wait, in its order, are `--explain`'s teardown lines.
#[test]
fn the_pages_drop_order_is_the_windows() {
    let doc = text(WALKTHROUGH);
    let step = steps(&doc)
        .into_iter()
        .find(|s| s.number == 20)
        .expect("the page has step 20");
    let start = step.text.find("**Where.**").expect("step 20 says where");
    let paragraph = &step.text[start..];
    let paragraph = &paragraph[..paragraph.find("\n\n").unwrap_or(paragraph.len())];
    let stated: Vec<String> = paragraph
        .split('`')
        .skip(1)
        .step_by(2)
        .filter_map(|span| {
            let parts: Vec<&str> = span.split("::").collect();
            (parts.len() == 3 && parts[2] == "drop" && parts[1] != "VkWindow")
                .then(|| format!("{}::drop", parts[1]))
        })
        .collect();
    let xvfb = twinray_tests::Xvfb::start();
    let dir = twinray_tests::scratch("drop-order");
    let app = twinray_tests::bin("twinray-vk");
    let args = box_window("64x48", "3", &["--explain"]);
    let out = xvfb.run(&app, &args, &[], &dir);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "the window failed:\n{stderr}");
    // The teardown: the [20] lines after the last line of any other step
    // (a resize drops a swapchain earlier, too).
    let lines = explained(&stderr);
    let last_other = lines.iter().rposition(|(n, _)| *n != 20).unwrap_or(0);
    let printed: Vec<String> = lines[last_other + 1..]
        .iter()
        .filter_map(|(_, title)| Some(title.split_once(": ")?.0.to_string()))
        .collect();
    assert!(stated.len() >= 4, "step 20 names only {stated:?}");
    assert_eq!(
        printed, stated,
        "--explain's teardown lines, and step 20's drop order"
    );
}
