//! Frame-time statistics as the study computed them: of N frames, summarise
//! the last 30 (or the last half when fewer than 60 were rendered).

use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq)]
pub struct Summary {
    pub mean: f64,
    pub median: f64,
    pub min: f64,
    pub max: f64,
    /// How many frames the figures cover.
    pub n: usize,
}

/// The frames the statistics cover: the last 30 of 60 (the study's method);
/// for short runs the last half, and a single frame when only one was drawn.
pub fn measured_tail(values: &[f64]) -> &[f64] {
    let keep = if values.len() >= 60 {
        30
    } else {
        values.len().div_ceil(2)
    };
    &values[values.len() - keep..]
}

pub fn summarize(values: &[f64]) -> Option<Summary> {
    let tail = measured_tail(values);
    if tail.is_empty() {
        return None;
    }
    let mut sorted = tail.to_vec();
    sorted.sort_by(|a, b| a.total_cmp(b));
    let n = sorted.len();
    Some(Summary {
        mean: sorted.iter().sum::<f64>() / n as f64,
        median: middle(&sorted),
        min: sorted[0],
        max: sorted[n - 1],
        n,
    })
}

/// The median of `values`: the middle one, or the mean of the middle two.
pub fn median(values: &[f64]) -> Option<f64> {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    (!sorted.is_empty()).then(|| middle(&sorted))
}

/// The median of sorted, non-empty `sorted`.
fn middle(sorted: &[f64]) -> f64 {
    let n = sorted.len();
    if n % 2 == 1 {
        sorted[n / 2]
    } else {
        0.5 * (sorted[n / 2 - 1] + sorted[n / 2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uses_last_thirty_of_sixty() {
        let v: Vec<f64> = (0..60).map(|i| i as f64).collect();
        let s = summarize(&v).unwrap();
        assert_eq!(s.n, 30);
        assert_eq!(s.min, 30.0);
        assert_eq!(s.max, 59.0);
        assert_eq!(s.median, 44.5);
        assert_eq!(s.mean, 44.5);
    }

    #[test]
    fn single_frame_and_empty() {
        assert_eq!(summarize(&[2.0]).unwrap().median, 2.0);
        assert!(summarize(&[]).is_none());
    }

    #[test]
    fn median_of_odd_and_even_counts_in_any_order() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), Some(2.5));
        assert_eq!(median(&[]), None);
    }
}
