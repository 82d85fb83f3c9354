//! A comparison or accuracy run in which some run failed is not a success:
//! after the report is written (so nothing finished is lost), the command
//! ends with an error that says how many runs failed and why, in the apps'
//! own words.

use std::fmt::Write as _;

/// At most this many distinct reasons are quoted; the report lists every run.
const REASONS: usize = 4;

/// `Ok` when nothing failed; else one error naming the count and each
/// distinct reason (with how many runs gave it and one of them).
/// `failed` holds (run, reason) pairs.
pub fn check(failed: &[(String, String)]) -> anyhow::Result<()> {
    if failed.is_empty() {
        return Ok(());
    }
    let mut reasons: Vec<(&str, &str, usize)> = Vec::new();
    for (run, reason) in failed {
        match reasons.iter_mut().find(|(r, _, _)| r == reason) {
            Some(entry) => entry.2 += 1,
            None => reasons.push((reason, run, 1)),
        }
    }
    let mut text = format!(
        "{} run{} failed (report.md has each)",
        failed.len(),
        if failed.len() == 1 { "" } else { "s" }
    );
    for (i, (reason, run, n)) in reasons.iter().take(REASONS).enumerate() {
        let sep = if i == 0 { ": " } else { "; " };
        let _ = match n {
            1 => write!(text, "{sep}{run}: {reason}"),
            _ => write!(text, "{sep}{n} like {run}: {reason}"),
        };
    }
    if reasons.len() > REASONS {
        let _ = write!(text, "; and {} other reasons", reasons.len() - REASONS);
    }
    Err(anyhow::anyhow!(text))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pair(run: &str, reason: &str) -> (String, String) {
        (run.to_string(), reason.to_string())
    }

    #[test]
    fn nothing_failed_is_success() {
        assert!(check(&[]).is_ok());
    }

    #[test]
    fn the_error_counts_the_runs_and_quotes_each_reason_once() {
        let failed = [
            pair("box 100x100 vulkan fragment", "twinray-vk: error: no GPU"),
            pair("box 200x200 vulkan fragment", "twinray-vk: error: no GPU"),
            pair("box 100x100 opengl fragment", "twinray-gl: error: no EGL"),
        ];
        let e = check(&failed).unwrap_err().to_string();
        assert_eq!(
            e,
            "3 runs failed (report.md has each): 2 like box 100x100 vulkan \
             fragment: twinray-vk: error: no GPU; box 100x100 opengl fragment: twinray-gl: error: no EGL"
        );
    }
}
