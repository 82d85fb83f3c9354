//! The Pareto front of time against error, per scene and API: which
//! configurations no other beats on both, with times that scatter less than
//! the default's own repeats counted as equal.

use super::sweeps::Row;
use crate::apps::Api;
use twinray_common::scene::numerics::Numerics;
use twinray_common::stats::median;

/// The smallest time tie: below 1% no measurement here is steadier.
pub const TIME_TIE_FLOOR: f64 = 0.01;
/// The time tie when fewer than three timings of the default exist.
pub const TIME_TIE_FALLBACK: f64 = 0.05;
/// RMSE within this factor (or 1e-6) counts as equal.
pub const ERROR_TIE: f64 = 1.01;

/// Whether (t2, e2) dominates (t, e): at least as fast and as accurate, and
/// clearly better in one. Times within the relative `tie` and RMSE within
/// ERROR_TIE count as equal.
pub fn dominates(t2: f64, e2: f64, t: f64, e: f64, tie: f64) -> bool {
    let as_fast = t2 <= t * (1.0 + tie);
    let as_good = e2 <= e * ERROR_TIE + 1e-6;
    let faster = t2 * (1.0 + tie) < t;
    let better = e2 * ERROR_TIE + 1e-6 < e;
    as_fast && as_good && (faster || better)
}

/// Every timing of the rows that run `program` on this scene and API.
fn timings(rows: &[Row], scene: &str, api: Api, program: &str) -> Vec<f64> {
    rows.iter()
        .filter(|r| r.scene == scene && r.api == api && r.program == program)
        .flat_map(|r| r.time().into_iter().chain(r.repeats.iter().copied()))
        .collect()
}

/// One point of the front: the median of all timings of its program, and the
/// largest RMSE among its rows (they render the same image).
pub fn point(rows: &[Row], i: usize) -> Option<(f64, f64)> {
    let r = &rows[i];
    let t = median(&timings(rows, &r.scene, r.api, &r.program))?;
    let e = rows
        .iter()
        .filter(|o| o.scene == r.scene && o.api == r.api && o.program == r.program)
        .filter_map(|o| o.error().map(|e| e.rmse))
        .fold(None, |m: Option<f64>, e| Some(m.map_or(e, |m| m.max(e))))?;
    Some((t, e))
}

/// The time tie for one scene and API, and the timings it came from: the
/// relative spread (max/min - 1) of the default program's timings, which
/// measures how far the same work scatters from run to run on this machine.
pub fn time_tie(rows: &[Row], scene: &str, api: Api) -> (f64, Vec<f64>) {
    let Some(def) = rows
        .iter()
        .find(|r| r.scene == scene && r.api == api && r.is_default)
    else {
        return (TIME_TIE_FALLBACK, Vec::new());
    };
    let t = timings(rows, scene, api, &def.program);
    if t.len() < 3 {
        return (TIME_TIE_FALLBACK, t);
    }
    let (lo, hi) = t
        .iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), &x| (lo.min(x), hi.max(x)));
    ((hi / lo - 1.0).max(TIME_TIE_FLOOR), t)
}

/// The rows that dominate row `i`: same scene and API, another program, sound.
pub fn dominators(rows: &[Row], i: usize) -> Vec<usize> {
    let r = &rows[i];
    let Some((t, e)) = point(rows, i) else {
        return Vec::new();
    };
    let (tie, _) = time_tie(rows, &r.scene, r.api);
    (0..rows.len())
        .filter(|&j| {
            let o = &rows[j];
            o.scene == r.scene && o.api == r.api && o.program != r.program && o.sound
        })
        .filter(|&j| matches!(point(rows, j), Some((t2, e2)) if dominates(t2, e2, t, e, tie)))
        .collect()
}

/// Marks the rows on the Pareto front of (time, RMSE), per scene and API: no
/// other point dominates theirs. A row whose numerics render a hard case wrong
/// (`unsound`) is neither on the front nor allowed to dominate: being right on
/// the hard cases is a constraint, not a cost to trade.
pub fn mark_pareto(rows: &mut [Row], unsound: &[Numerics]) {
    for row in rows.iter_mut() {
        row.sound = !unsound.contains(&row.config.numerics);
    }
    let front: Vec<bool> = (0..rows.len())
        .map(|i| rows[i].sound && point(rows, i).is_some() && dominators(rows, i).is_empty())
        .collect();
    for (row, on) in rows.iter_mut().zip(front) {
        row.pareto = on;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accuracy::sweeps::{Config, Error};
    use twinray_common::cli::Size;

    #[test]
    fn ties_do_not_dominate() {
        let tie = 0.05;
        assert!(
            !dominates(10.2, 0.01, 10.0, 0.01, tie),
            "2% slower, same error"
        );
        assert!(!dominates(9.8, 0.01, 10.0, 0.01, tie), "2% faster is noise");
        assert!(dominates(8.0, 0.01, 10.0, 0.01, tie));
        assert!(dominates(10.2, 0.005, 10.0, 0.01, tie));
        assert!(!dominates(8.0, 0.02, 10.0, 0.01, tie));
        // A tighter tie, measured on a steadier machine, separates 2%.
        assert!(dominates(9.8, 0.01, 10.0, 0.01, 0.01));
        assert!(!dominates(10.2, 0.005, 10.0, 0.01, 0.01));
    }

    fn row(
        api: Api,
        program: &str,
        time: f64,
        rmse: f64,
        is_default: bool,
        repeats: Vec<f64>,
    ) -> Row {
        Row {
            scene: "s".into(),
            size: Size {
                width: 1,
                height: 1,
            },
            config: Config {
                max_depth: 1,
                numerics: Numerics::default(),
            },
            sweeps: vec![],
            api,
            result: Ok((
                Some(time),
                time,
                Error {
                    rmse,
                    max_abs: 0,
                    above_1: 0.0,
                    wrong: 0.0,
                    flip: None,
                    outside: crate::accuracy::sweeps::Outside {
                        mask_pixels: 0,
                        max_abs: 0,
                        above_8: 0.0,
                    },
                },
                0,
            )),
            pareto: false,
            sound: true,
            is_default,
            program: program.into(),
            repeats,
        }
    }

    #[test]
    fn the_default_program_is_one_point_and_its_spread_is_the_tie() {
        // The default timed 10.0, 10.1, 10.4 ms (median 10.1, spread 4%); a row
        // with the same shader at 9.0 ms joins its point rather than beating it.
        let rows = vec![
            row(Api::Vulkan, "a", 10.0, 0.01, true, vec![10.1, 10.4]),
            row(Api::Vulkan, "a", 9.0, 0.01, false, vec![]),
            row(Api::Vulkan, "b", 9.8, 0.01, false, vec![]),
            row(Api::Vulkan, "c", 10.2, 0.005, false, vec![]),
            row(Api::Vulkan, "d", 8.0, 0.02, false, vec![]),
        ];
        assert_eq!(point(&rows, 0), Some((10.05, 0.01)));
        let (tie, times) = time_tie(&rows, "s", Api::Vulkan);
        assert_eq!(times.len(), 4);
        assert!((tie - (10.4 / 9.0 - 1.0)).abs() < 1e-12);
        // b ties with the default; c is as fast within the tie and better; d is worse.
        assert_eq!(dominators(&rows, 0), vec![3]);
    }
}
