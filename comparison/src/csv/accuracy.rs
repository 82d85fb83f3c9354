//! accuracy.csv (every configuration's run), hard_cases.csv (every hard case
//! per strategy and API) and random.csv (every random scene's pairs). The
//! field order of each row is its column order, which the committed results
//! and the tests read.

use super::Num;
use crate::accuracy::hard::HardRow;
use crate::accuracy::pareto::point;
use crate::accuracy::random::RandomRow;
use crate::accuracy::sweeps::Row;
use crate::apps::api_name;
use serde::Serialize;
use twinray_common::scene::random as random_scene;
use twinray_common::value_name::ValueName;

#[derive(Serialize, Default)]
struct ConfigLine<'a> {
    scene: &'a str,
    width: u32,
    height: u32,
    api: &'a str,
    max_depth: u32,
    offset: String,
    triangle: String,
    sphere: String,
    /// The sweeps the row belongs to, joined by `+`.
    sweeps: String,
    default: bool,
    pareto: bool,
    point_ms: Option<Num>,
    /// The default's extra timings, joined by `;`.
    repeat_ms: String,
    status: String,
    gpu_min_ms: Option<Num>,
    wall_min_ms: Option<Num>,
    rmse: Option<Num>,
    max_abs: Option<u8>,
    above_1: Option<Num>,
    above_8: Option<Num>,
    flip_mean: Option<Num>,
    nonfinite_pixels: Option<u64>,
    /// The truth's unsettled pixels, and the error over the rest.
    mask_pixels: Option<usize>,
    max_abs_outside: Option<u8>,
    above_8_outside: Option<Num>,
}

/// accuracy.csv's text.
pub fn accuracy(rows: &[Row]) -> anyhow::Result<String> {
    super::to_string(rows.iter().enumerate().map(|(i, r)| {
        let n = &r.config.numerics;
        let ok = r.result.as_ref().ok();
        let error = r.error();
        ConfigLine {
            scene: &r.scene,
            width: r.size.width,
            height: r.size.height,
            api: api_name(r.api),
            max_depth: r.config.max_depth,
            offset: n.offset.name(),
            triangle: n.triangle.name(),
            sphere: n.sphere.name(),
            sweeps: r.sweeps.join("+"),
            default: r.is_default,
            pareto: r.pareto,
            point_ms: point(rows, i).map(|p| Num(p.0)),
            repeat_ms: r
                .repeats
                .iter()
                .map(|t| t.to_string())
                .collect::<Vec<_>>()
                .join(";"),
            status: super::status(&r.result),
            gpu_min_ms: ok.and_then(|(g, ..)| g.map(Num)),
            wall_min_ms: ok.map(|(_, w, ..)| Num(*w)),
            rmse: error.map(|e| Num(e.rmse)),
            max_abs: error.map(|e| e.max_abs),
            above_1: error.map(|e| Num(e.above_1)),
            above_8: error.map(|e| Num(e.wrong)),
            flip_mean: error.and_then(|e| e.flip.map(Num)),
            nonfinite_pixels: ok.map(|(.., nan)| *nan),
            mask_pixels: error.map(|e| e.outside.mask_pixels),
            max_abs_outside: error.map(|e| e.outside.max_abs),
            above_8_outside: error.map(|e| Num(e.outside.above_8)),
        }
    }))
}

#[derive(Serialize, Default)]
struct HardLine<'a> {
    case: &'a str,
    tolerance_pct: Num,
    strategy: &'a str,
    api: &'a str,
    status: String,
    /// Pixels off by more than WRONG_ABOVE/255 against the truth, in percent.
    wrong_pct: Option<Num>,
    /// Wrong pixels strictly inside the truth's silhouette: only for the
    /// cases that count cracks.
    crack_pixels: Option<usize>,
    /// GPU time where the driver has timers, else wall time.
    time_ms: Option<Num>,
    nonfinite_pixels: Option<u64>,
    /// The truth's unsettled pixels, and the wrong share over the rest.
    mask_pixels: Option<usize>,
    wrong_outside_pct: Option<Num>,
}

/// hard_cases.csv's text.
pub fn hard_cases(rows: &[HardRow]) -> anyhow::Result<String> {
    super::to_string(rows.iter().map(|r| {
        let ok = r.result.as_ref().ok();
        HardLine {
            case: &r.case,
            tolerance_pct: Num(r.tolerance_pct),
            strategy: &r.strategy,
            api: api_name(r.api),
            status: super::status(&r.result),
            wrong_pct: ok.map(|(w, ..)| Num(100.0 * w)),
            crack_pixels: ok.and_then(|(_, c, ..)| *c),
            time_ms: ok.map(|(_, _, t, _)| Num(*t)),
            nonfinite_pixels: ok.map(|(.., nan)| *nan),
            mask_pixels: r.outside.map(|o| o.mask_pixels),
            wrong_outside_pct: r.outside.map(|o| Num(100.0 * o.above_8)),
        }
    }))
}

#[derive(Serialize, Default)]
struct RandomLine<'a> {
    seed: u64,
    pair: &'a str,
    /// "ok", "disagree" (beyond the thresholds) or "failed: " and why.
    status: String,
    off_8_pct: Option<Num>,
    within_1_pct: Option<Num>,
    max_abs: Option<u8>,
    rmse: Option<Num>,
    nonfinite_pixels: Option<u64>,
    /// The reference's unsettled pixels, and the pair over the rest.
    mask_pixels: Option<usize>,
    off_8_outside_pct: Option<Num>,
    max_abs_outside: Option<u8>,
}

/// random.csv's text.
pub fn random(rows: &[RandomRow]) -> anyhow::Result<String> {
    super::to_string(rows.iter().map(random_line))
}

fn random_line(r: &RandomRow) -> RandomLine<'_> {
    let m = r.result.as_ref().ok();
    RandomLine {
        seed: r.seed,
        pair: r.pair,
        status: match m {
            Some(m) if random_scene::disagreement(m).is_some() => "disagree".into(),
            _ => super::status(&r.result),
        },
        off_8_pct: m.map(|m| Num(100.0 * m.above_8)),
        within_1_pct: m.map(|m| Num(100.0 * m.within_1())),
        max_abs: m.map(|m| m.max_abs),
        rmse: m.map(|m| Num(m.rmse)),
        nonfinite_pixels: m.map(|m| m.nan_pixels),
        mask_pixels: r.outside.map(|o| o.mask_pixels),
        off_8_outside_pct: r.outside.map(|o| Num(100.0 * o.above_8)),
        max_abs_outside: r.outside.map(|o| o.max_abs),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The committed results (comparison/results/*/accuracy/) and the tests
    /// read these columns by name: they must not move or change.
    #[test]
    fn the_columns_stay_as_committed_even_without_rows() {
        assert_eq!(
            accuracy(&[]).unwrap(),
            "scene,width,height,api,max_depth,offset,triangle,sphere,sweeps,default,pareto,point_ms,repeat_ms,status,gpu_min_ms,wall_min_ms,rmse,max_abs,above_1,above_8,flip_mean,nonfinite_pixels,mask_pixels,max_abs_outside,above_8_outside\n"
        );
        assert_eq!(
            hard_cases(&[]).unwrap(),
            "case,tolerance_pct,strategy,api,status,wrong_pct,crack_pixels,time_ms,nonfinite_pixels,mask_pixels,wrong_outside_pct\n"
        );
        assert_eq!(
            random(&[]).unwrap(),
            "seed,pair,status,off_8_pct,within_1_pct,max_abs,rmse,nonfinite_pixels,mask_pixels,off_8_outside_pct,max_abs_outside\n"
        );
    }
}
