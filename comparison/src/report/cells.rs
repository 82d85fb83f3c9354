//! What every section of report.md computes its cells from: one run's report
//! by point, API and path, the paths measured, Vulkan/OpenGL ratios, the
//! median range, and the dash for a number that is missing.

use crate::apps::Api;
use crate::compare::runs::Outcome;
use twinray_common::cli::RenderPath;
use twinray_common::report::RunReport;

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
