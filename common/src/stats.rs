//! Frame-time statistics: which frames count (the study's rule, the last 30
//! of 60, or every frame after a warm-up), their summary, the median's 95 %
//! confidence interval, and the rule that stops a run once that interval is
//! narrow enough (`--settle`).

use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq)]
pub struct Summary {
    pub mean: f64,
    pub median: f64,
    pub min: f64,
    pub max: f64,
    /// How many frames the figures cover.
    pub n: usize,
    /// The median's 95 % confidence interval, from the order statistics (no
    /// assumption on the distribution); absent below 6 frames, where no two
    /// order statistics cover the median with 95 % confidence.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub median_lo: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub median_hi: Option<f64>,
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

/// How many of `count` frames are warm-up under the study's rule: all but
/// those [`measured_tail`] keeps.
pub fn study_warmup(count: usize) -> usize {
    count - measured_tail(&vec![0.0; count]).len()
}

/// The summary of the study's tail of `values` ([`measured_tail`]).
pub fn summarize(values: &[f64]) -> Option<Summary> {
    summarize_all(measured_tail(values))
}

/// The summary of every one of `values`.
pub fn summarize_all(values: &[f64]) -> Option<Summary> {
    if values.is_empty() {
        return None;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(|a, b| a.total_cmp(b));
    let n = sorted.len();
    let interval = median_interval(&sorted);
    Some(Summary {
        mean: sorted.iter().sum::<f64>() / n as f64,
        median: middle(&sorted),
        min: sorted[0],
        max: sorted[n - 1],
        n,
        median_lo: interval.map(|i| i.0),
        median_hi: interval.map(|i| i.1),
    })
}

/// The 1-based rank k of the order statistics x(k) and x(n+1-k) that bound
/// the median of n samples with at least 95 % confidence: the largest k with
/// P(Binomial(n, 1/2) < k) <= 2.5 %. None below 6 samples.
pub fn interval_rank(n: usize) -> Option<usize> {
    if n < 6 {
        return None;
    }
    if n > 300 {
        // The normal approximation; exact enough at this size, and 0.5^n
        // would underflow the exact sum long before n reaches the cap.
        let k = (n as f64 / 2.0 - 1.96 * (n as f64).sqrt() / 2.0).floor() as usize;
        return Some(k.max(1));
    }
    // P(B < k) = sum over i < k of C(n, i) / 2^n, built up term by term.
    let mut pmf = 0.5f64.powi(n as i32);
    let mut below = 0.0;
    let mut k = 0;
    while k < n / 2 {
        if below + pmf > 0.025 {
            break;
        }
        below += pmf;
        k += 1;
        pmf *= (n - k + 1) as f64 / k as f64;
    }
    (k >= 1).then_some(k)
}

/// The median's 95 % interval of sorted `sorted` (see [`interval_rank`]).
pub fn median_interval(sorted: &[f64]) -> Option<(f64, f64)> {
    let n = sorted.len();
    interval_rank(n).map(|k| (sorted[k - 1], sorted[n - k]))
}

/// When a timed loop may stop: `--frames` is the cap; with `--settle PCT`,
/// the loop also stops once the median's 95 % interval lies within ±PCT %
/// of the median, after a warm-up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FramePlan {
    pub cap: u32,
    /// The half-width the interval must reach, as a fraction (0.01 for ±1 %).
    pub settle: Option<f64>,
}

/// How long a settling run warms up: its first frames until this much wall
/// time has passed (at least one frame, at most half the cap, and at most
/// what leaves 6 timed frames). A GPU's clocks
/// and caches settle within it; a slow frame is its own warm-up.
pub const WARMUP_MS: f64 = 200.0;

impl FramePlan {
    /// A fixed number of frames: the study's rule decides the warm-up.
    pub fn fixed(cap: u32) -> FramePlan {
        FramePlan { cap, settle: None }
    }

    /// Whether the frame just finished (`done` frames so far, `elapsed_ms`
    /// of wall time since the first began) ends the warm-up.
    pub fn warmup_over(&self, done: usize, elapsed_ms: f64) -> bool {
        // At most half the cap, and no more than leaves 6 timed frames where
        // the cap has room for them.
        let cap = self.cap as usize;
        let longest = (cap / 2).min(cap.saturating_sub(6)).max(1);
        done >= 1 && (elapsed_ms >= WARMUP_MS || done >= longest)
    }

    /// Whether the timed frames so far (`timed`, in the clock that counts)
    /// are settled: the median's interval within ±settle of the median.
    pub fn settled(&self, timed: &[f64]) -> bool {
        let Some(p) = self.settle else {
            return false;
        };
        // Sorting every frame is cheap at the sizes that settle; past a few
        // thousand frames, look every 64th.
        if timed.len() > 4096 && timed.len() % 64 != 0 {
            return false;
        }
        let mut sorted = timed.to_vec();
        sorted.sort_by(f64::total_cmp);
        let median = middle_or_nan(&sorted);
        match median_interval(&sorted) {
            Some((lo, hi)) => median > 0.0 && lo >= median * (1.0 - p) && hi <= median * (1.0 + p),
            None => false,
        }
    }
}

fn middle_or_nan(sorted: &[f64]) -> f64 {
    if sorted.is_empty() {
        f64::NAN
    } else {
        middle(sorted)
    }
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
    fn the_median_interval_covers_ninety_five_percent() {
        assert_eq!(interval_rank(5), None, "x(1)..x(5) covers only 93.75 %");
        assert_eq!(interval_rank(6), Some(1), "x(1)..x(6) covers 96.9 %");
        // Published table values (e.g. Conover): n=10 -> k=2, n=20 -> k=6, n=30 -> k=10.
        assert_eq!(interval_rank(10), Some(2));
        assert_eq!(interval_rank(20), Some(6));
        assert_eq!(interval_rank(30), Some(10));
        // The normal approximation joins the exact sum without a jump.
        let exact = interval_rank(300).unwrap() as f64;
        let approx = interval_rank(301).unwrap() as f64;
        assert!((exact - approx).abs() <= 1.0, "{exact} vs {approx}");
        let s = summarize_all(&[5.0, 1.0, 4.0, 2.0, 3.0, 6.0]).unwrap();
        assert_eq!((s.median_lo, s.median_hi), (Some(1.0), Some(6.0)));
        assert!(summarize_all(&[1.0; 5]).unwrap().median_lo.is_none());
    }

    #[test]
    fn a_run_settles_only_inside_the_band() {
        let plan = FramePlan {
            cap: 60,
            settle: Some(0.01),
        };
        // Six frames within ±1 % settle; five never do.
        assert!(plan.settled(&[100.0, 100.5, 99.5, 100.2, 99.8, 100.0]));
        assert!(!plan.settled(&[100.0, 100.5, 99.5, 100.2, 99.8]));
        // One frame 2 % off widens the interval past the band.
        assert!(!plan.settled(&[100.0, 102.0, 99.5, 100.2, 99.8, 100.0]));
        assert!(!FramePlan::fixed(60).settled(&[1.0; 10]));
        // The warm-up: a slow first frame is enough, fast ones wait for the
        // time or half the cap.
        assert!(plan.warmup_over(1, 2500.0));
        assert!(!plan.warmup_over(3, 1.0));
        assert!(plan.warmup_over(30, 1.0));
        let short = FramePlan {
            cap: 8,
            settle: Some(0.02),
        };
        assert!(!short.warmup_over(1, 1.0));
        assert!(short.warmup_over(2, 1.0), "8 frames leave 6 timed after 2");
        assert_eq!(study_warmup(60), 30);
        assert_eq!(study_warmup(7), 3);
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
