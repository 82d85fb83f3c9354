//! `--explain`: the live walkthrough. Each app reports every API object right
//! after creating it, with the parameters that matter; this module prints those
//! reports on stderr (stdout belongs to `--json`), each with the number of the
//! docs/vulkan-walkthrough.md step that explains it (0: the run plan that
//! twinray-common prepares, before or beside the API objects; an OpenGL line
//! carries the number of the Vulkan step it twins), and times them.
//!
//! A step's time is the time since the previous report (or since `enable`), so
//! it covers the creation call and whatever preparation led up to it, but not
//! the reporting: a report's details can cost time of their own (the BVH
//! line's SAH cost walks the whole tree), which no step is charged; reports
//! come in the order they happen, which is the order of the code, so a reader
//! who runs `--explain` beside the page sees where the code's order and the
//! page's differ (tests/tests/walkthrough_steps.rs holds the two together).
//!
//! Global rather than passed around: the constructors that report are the same
//! ones the timed runs use, and threading a logger through all of them would
//! change every signature for a flag that is off in every measured run.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::Instant;

static ON: AtomicBool = AtomicBool::new(false);
static LAST: Mutex<Option<Instant>> = Mutex::new(None);

/// Turns reporting on and prints the header; `program` names the app.
pub fn enable(program: &str, api: &str) {
    ON.store(true, Ordering::SeqCst);
    *LAST.lock().unwrap_or_else(|e| e.into_inner()) = Some(Instant::now());
    eprintln!("{program} --explain: every {api} object in the order it is created; [n] = its step in docs/vulkan-walkthrough.md, time = since the previous line");
}

pub fn is_on() -> bool {
    ON.load(Ordering::Relaxed)
}

/// Reports an object of walkthrough step `step`. `details` is built only when
/// reporting is on, so the measured runs pay nothing for it. Each line of it is
/// printed indented.
pub fn numbered(step: u32, title: &str, details: impl FnOnce() -> String) {
    if !is_on() {
        return;
    }
    report(step, title, details);
}

fn report(n: u32, title: &str, details: impl FnOnce() -> String) {
    let now = Instant::now();
    let elapsed_ms = {
        let last = LAST.lock().unwrap_or_else(|e| e.into_inner());
        last.map(|t| (now - t).as_secs_f64() * 1e3).unwrap_or(0.0)
    };
    eprintln!("{}", format_step(n, elapsed_ms, title, &details()));
    // The next step's time starts after this report.
    *LAST.lock().unwrap_or_else(|e| e.into_inner()) = Some(Instant::now());
}

/// `[ 4]  +0.42 ms  VkDevice` then the details, one per indented line.
pub fn format_step(n: u32, elapsed_ms: f64, title: &str, details: &str) -> String {
    let mut s = format!("[{n:>2}] {:>+9.2} ms  {title}", elapsed_ms);
    for line in details.lines().filter(|l| !l.trim().is_empty()) {
        s.push_str("\n                   ");
        s.push_str(line);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn step_lines_are_numbered_and_details_indented() {
        let s = format_step(3, 0.4217, "VkDevice", "queue family 0\n\nswapchain");
        let lines: Vec<&str> = s.lines().collect();
        assert_eq!(lines[0], "[ 3]     +0.42 ms  VkDevice");
        assert_eq!(lines.len(), 3, "empty detail lines are dropped: {s}");
        assert!(lines[1].trim_start() == "queue family 0" && lines[1].starts_with("    "));
    }
}
