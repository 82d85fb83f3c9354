//! What every section of report.md computes its cells from: one run's report
//! by point, API and path, the paths measured, Vulkan/OpenGL ratios, the
//! median range, and the dash for a number that is missing.

use crate::apps::Api;
use crate::compare::runs::Outcome;
use twinray_common::cli::RenderPath;
use twinray_common::report::RunReport;
use twinray_common::stats::Summary;

/// The first report of `api` that succeeded: where the device and driver come from.
pub fn first_report(outcomes: &[Outcome], api: Api) -> Option<&RunReport> {
    outcomes
        .iter()
        .find(|o| o.api == api)
        .and_then(|o| o.result.as_ref().ok())
}

pub fn report_of<'a>(
    outcomes: &'a [&Outcome],
    value: &str,
    api: Api,
    path: RenderPath,
) -> Option<&'a RunReport> {
    outcomes
        .iter()
        .find(|o| o.point.param_value == value && o.api == api && o.path == path)
        .and_then(|o| o.result.as_ref().ok())
}

/// The paths that have at least one row, fragment first.
pub fn paths_in(outcomes: &[Outcome]) -> Vec<RenderPath> {
    [RenderPath::Fragment, RenderPath::Compute]
        .into_iter()
        .filter(|p| outcomes.iter().any(|o| o.path == *p))
        .collect()
}

pub fn ratio(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(a), Some(b)) if b > 0.0 => Some(a / b),
        _ => None,
    }
}

pub fn f(v: Option<f64>, digits: usize) -> String {
    v.map(|v| format!("{v:.digits$}"))
        .unwrap_or_else(|| "–".into())
}

pub fn range(v: &[f64]) -> Option<(f64, f64, f64)> {
    if v.is_empty() {
        return None;
    }
    let mut s = v.to_vec();
    s.sort_by(|a, b| a.total_cmp(b));
    Some((s[0], s[s.len() / 2], s[s.len() - 1]))
}

/// Vulkan/OpenGL of two medians and the interval their 95 % intervals give
/// (Vulkan's low end over OpenGL's high end, and the reverse); no interval
/// where either run had too few frames for one.
pub fn ratio_interval(vk: Option<Summary>, gl: Option<Summary>) -> Option<(f64, f64)> {
    let (vk, gl) = (vk?, gl?);
    match (vk.median_lo, vk.median_hi, gl.median_lo, gl.median_hi) {
        (Some(vl), Some(vh), Some(gl_lo), Some(gh)) if gl_lo > 0.0 && gh > 0.0 => {
            Some((vl / gh, vh / gl_lo))
        }
        _ => None,
    }
}

/// Who is faster at a ratio (Vulkan time / OpenGL time): a tie where its
/// interval holds 1.00, or, without an interval, within 2 % of it.
pub fn who(value: f64, interval: Option<(f64, f64)>) -> &'static str {
    let tie = match interval {
        Some((lo, hi)) => lo <= 1.0 && 1.0 <= hi,
        None => (0.98..=1.02).contains(&value),
    };
    if tie {
        "a tie"
    } else if value > 1.0 {
        "OpenGL faster"
    } else {
        "Vulkan faster"
    }
}

/// A ratio cell: "1.07 (1.05–1.09)", "tie" added where the interval holds 1.00.
pub fn ratio_cell(vk: Option<Summary>, gl: Option<Summary>) -> String {
    let Some(r) = ratio(vk.map(|s| s.median), gl.map(|s| s.median)) else {
        return "–".into();
    };
    match ratio_interval(vk, gl) {
        Some((lo, hi)) => format!(
            "{r:.2} ({lo:.2}–{hi:.2}){}",
            if lo <= 1.0 && 1.0 <= hi { " tie" } else { "" }
        ),
        None => format!("{r:.2}"),
    }
}

/// A median cell: "79.857 ±0.4%", the interval's larger half-width in per
/// cent of the median, or the bare median where there is no interval.
pub fn median_cell(s: Option<Summary>, digits: usize) -> String {
    match s {
        Some(s) => match (s.median_lo, s.median_hi) {
            (Some(lo), Some(hi)) if s.median > 0.0 => {
                let half = (s.median - lo).max(hi - s.median) / s.median * 100.0;
                format!("{:.digits$} ±{half:.1}%", s.median)
            }
            _ => format!("{:.digits$}", s.median),
        },
        None => "–".into(),
    }
}

/// Three significant digits, however small: 13.7, 0.512, 0.000123.
pub fn sig3(v: Option<f64>) -> String {
    match v {
        Some(v) if v.is_finite() && v > 0.0 => {
            let decimals = (2 - v.log10().floor() as i32).max(0) as usize;
            format!("{v:.decimals$}")
        }
        Some(0.0) => "0".into(),
        _ => "–".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn summary(median: f64, lo: f64, hi: f64) -> Summary {
        Summary {
            mean: median,
            median,
            min: lo,
            max: hi,
            n: 6,
            median_lo: Some(lo),
            median_hi: Some(hi),
        }
    }

    #[test]
    fn ratios_carry_their_interval_and_ties_are_called() {
        let vk = summary(1.0, 0.99, 1.01);
        let gl = summary(1.0, 0.995, 1.005);
        assert_eq!(ratio_cell(Some(vk), Some(gl)), "1.00 (0.99–1.02) tie");
        let slow = summary(1.2, 1.19, 1.21);
        assert_eq!(ratio_cell(Some(slow), Some(gl)), "1.20 (1.18–1.22)");
        assert_eq!(
            who(1.2, ratio_interval(Some(slow), Some(gl))),
            "OpenGL faster"
        );
        // A 1.5 % gap is a tie beside a loose median, a gap beside a tight one.
        let near = summary(1.015, 1.012, 1.017);
        let loose = summary(1.0, 0.98, 1.02);
        assert_eq!(who(1.015, ratio_interval(Some(near), Some(loose))), "a tie");
        let tight = summary(1.0, 0.999, 1.001);
        assert_eq!(
            who(1.015, ratio_interval(Some(near), Some(tight))),
            "OpenGL faster"
        );
        assert_eq!(
            median_cell(Some(summary(80.0, 79.8, 80.4)), 3),
            "80.000 ±0.5%"
        );
    }

    #[test]
    fn rates_keep_three_significant_digits() {
        assert_eq!(sig3(Some(13.71)), "13.7");
        assert_eq!(sig3(Some(0.000123456)), "0.000123");
        assert_eq!(sig3(Some(0.5124)), "0.512");
        assert_eq!(sig3(Some(137.2)), "137");
        assert_eq!(sig3(None), "–");
    }
}
