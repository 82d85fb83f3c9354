//! The why step's figures: from the reports of the runs at one gap, each
//! case's ratio (or share of agreeing pixels) by default and with its
//! experiment, including the cases that subtract one run's time from
//! another's (`Hold::Floor`, `Hold::SecondFrame`).

use crate::apps::Api;
use crate::compare::runs::{
    baselines, run_label, runs_of, Case, Gap, GapMeasure, Hold, Measured, Run, WhyFigures,
    NOT_MEASURED,
};
use std::path::Path;
use twinray_common::reference::image_io::load_png;
use twinray_common::reference::metrics;
use twinray_common::report::RunReport;

/// The median over rounds of each round's median: GPU ms with `gpu`, else wall ms.
fn median_ms(reports: &[Result<RunReport, String>], gpu: bool) -> Result<f64, String> {
    let mut v = Vec::new();
    for r in reports {
        let r = r.as_ref().map_err(Clone::clone)?;
        let s = if gpu { r.gpu_ms } else { r.wall_ms };
        v.push(s.map(|s| s.median).ok_or("failed: no frame times")?);
    }
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2)
        .copied()
        .ok_or_else(|| "failed: not run (stopped)".to_string())
}

/// The case's figures from the runs at its gap.
pub(crate) fn figures(
    gap: &Gap,
    case: &Case,
    measured: &Measured,
    dir: &Path,
) -> Result<WhyFigures, String> {
    let [vk, gl] = runs_of(case);
    let default: [Run; 2] = [(Api::Vulkan, &[], None), (Api::Opengl, &[], None)];
    let reports = |run: Run| -> Result<&Vec<Result<RunReport, String>>, String> {
        measured
            .get(&run_label(run))
            .ok_or_else(|| "failed: not run (stopped)".to_string())
    };
    match gap.measure {
        GapMeasure::Agreement => {
            let within = |a: Run, b: Run| -> Result<f64, String> {
                for run in [a, b] {
                    reports(run)?
                        .iter()
                        .try_for_each(|r| r.as_ref().map(|_| ()).map_err(Clone::clone))?;
                }
                let png = |run| dir.join(format!("{}-{}.png", gap.scene, run_label(run)));
                let (a, b) = (load_png(&png(a)), load_png(&png(b)));
                let m = metrics::compare(
                    &a.map_err(|e| format!("failed: {e:#}"))?,
                    &b.map_err(|e| format!("failed: {e:#}"))?,
                )
                .map_err(|e| format!("failed: {e:#}"))?;
                Ok(100.0 * m.within_1())
            };
            Ok(WhyFigures {
                before: within(default[0], default[1])?,
                after: within(vk, gl)?,
                clock: "image",
                ms: None,
            })
        }
        GapMeasure::Ratio => {
            let [base_vk, base_gl] = baselines(case);
            let six = [default[0], default[1], vk, gl, base_vk, base_gl];
            let all: Vec<_> = six.iter().map(|&r| reports(r)).collect::<Result<_, _>>()?;
            let gpu = all.iter().all(|rs| {
                rs.iter()
                    .all(|r| r.as_ref().is_ok_and(|r| r.gpu_ms.is_some()))
            });
            let ms: Vec<f64> = all
                .iter()
                .map(|rs| median_ms(rs, gpu))
                .collect::<Result<_, _>>()?;
            let shown = match case.hold {
                // A wall-clock frame holds the host's share of the loop too,
                // which neither an empty frame nor a second dispatch measures
                // apart from the GPU's.
                Some(Hold::Floor | Hold::SecondFrame(_)) if !gpu => {
                    return Err(format!("{NOT_MEASURED}this row subtracts one run's GPU time from another's, and this driver's runs have wall time"));
                }
                Some(Hold::Floor) => {
                    let (vk, gl) = (ms[0] - ms[2], ms[1] - ms[3]);
                    if vk <= 0.0 || gl <= 0.0 {
                        return Err(format!(
                            "failed: the empty frame ({:.4} / {:.4} ms) took as long as the gap's ({:.4} / {:.4} ms)",
                            ms[2], ms[3], ms[0], ms[1]
                        ));
                    }
                    // The empty frames are shown; the ratio is of what is left.
                    return Ok(WhyFigures {
                        before: ms[0] / ms[1],
                        after: vk / gl,
                        clock: "GPU",
                        ms: Some([ms[0], ms[1], ms[2], ms[3]]),
                    });
                }
                Some(Hold::SecondFrame(_)) => {
                    // Two frames back to back less one frame at the same workgroup.
                    let (vk, gl) = (ms[2] - ms[4], ms[3] - ms[5]);
                    if vk <= 0.0 || gl <= 0.0 {
                        return Err(format!(
                            "failed: two frames back to back ({:.4} / {:.4} ms) took no longer than one ({:.4} / {:.4} ms)",
                            ms[2], ms[3], ms[4], ms[5]
                        ));
                    }
                    (vk, gl)
                }
                _ => (ms[2], ms[3]),
            };
            Ok(WhyFigures {
                before: ms[0] / ms[1],
                after: shown.0 / shown.1,
                clock: if gpu { "GPU" } else { "wall" },
                ms: Some([ms[0], ms[1], shown.0, shown.1]),
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compare::gaps::{SPHERELIST_BVH_SMALL, TEAPOT_BVH_COMPUTE};
    use twinray_common::cli::RenderPath;

    /// Both APIs as shipped, held to `hold` at `gap` (what why.rs's `floor`
    /// and `second_frame` make).
    fn held(gap: &'static Gap, hold: Hold) -> Case {
        Case {
            gap,
            vulkan: &[],
            opengl: &[],
            opengl_api: Api::Opengl,
            hold: Some(hold),
        }
    }

    /// Reports of one frame each, `labels[i]` taking `times[i]` ms (GPU time
    /// with `gpu`, else wall time only).
    fn measured(labels: &[&str], times: &[f64], gpu: bool) -> Measured {
        labels
            .iter()
            .zip(times)
            .map(|(label, &ms)| {
                let mut r =
                    crate::compare::runs::test_outcome(Api::Vulkan, RenderPath::Compute, ms)
                        .result
                        .expect("a test outcome succeeds");
                if !gpu {
                    r.gpu_ms = None;
                }
                (label.to_string(), vec![Ok(r)])
            })
            .collect()
    }

    /// The empty frame's row: each API's time less its empty frame's, on GPU
    /// time only; an empty frame as long as the gap's frame is a failure.
    #[test]
    fn a_floor_row_takes_each_empty_frame_off_gpu_time_only() {
        let case = held(&SPHERELIST_BVH_SMALL, Hold::Floor);
        let labels = ["vulkan", "opengl", "vulkan-floor", "opengl-floor"];
        let dir = Path::new("/nonexistent");
        let at = |times: &[f64], gpu| figures(case.gap, &case, &measured(&labels, times, gpu), dir);
        let f = at(&[18.0, 20.0, 6.0, 8.0], true).unwrap();
        assert_eq!((f.before, f.after, f.clock), (0.9, 1.0, "GPU"));
        assert_eq!(f.ms, Some([18.0, 20.0, 6.0, 8.0]));
        let wall = at(&[18.0, 20.0, 6.0, 8.0], false);
        assert!(wall.unwrap_err().starts_with(NOT_MEASURED));
        let longer = at(&[18.0, 7.0, 6.0, 8.0], true);
        assert!(longer.unwrap_err().starts_with("failed: the empty frame"));
    }

    /// The second frame's row: two frames back to back less one frame, at the
    /// workgroup the row holds (its own one-frame runs), and the default
    /// ratio still from each API's own workgroup; GPU time only.
    #[test]
    fn a_second_frame_row_takes_one_frame_off_two_at_its_own_workgroup() {
        let dir = Path::new("/nonexistent");
        let own = held(&TEAPOT_BVH_COMPUTE, Hold::SecondFrame(None));
        let labels = [
            "vulkan",
            "opengl",
            "vulkan-back-to-back",
            "opengl-back-to-back",
        ];
        let m = measured(&labels, &[0.16, 0.19, 0.28, 0.32], true);
        let f = figures(own.gap, &own, &m, dir).unwrap();
        assert_eq!(f.before, 0.16 / 0.19);
        assert!((f.after - 0.12 / 0.13).abs() < 1e-12, "{}", f.after);
        let m = measured(&labels, &[0.16, 0.19, 0.28, 0.32], false);
        assert!(figures(own.gap, &own, &m, dir)
            .unwrap_err()
            .starts_with(NOT_MEASURED));
        let m = measured(&labels, &[0.16, 0.19, 0.28, 0.19], true);
        assert!(figures(own.gap, &own, &m, dir)
            .unwrap_err()
            .starts_with("failed: two frames back to back"));

        let at = held(&TEAPOT_BVH_COMPUTE, Hold::SecondFrame(Some((4, 8))));
        let labels = [
            "vulkan",
            "opengl",
            "vulkan-back-to-back-4x8",
            "opengl-back-to-back-4x8",
            "vulkan-4x8",
            "opengl-4x8",
        ];
        let m = measured(&labels, &[0.16, 0.19, 0.30, 0.32, 0.17, 0.19], true);
        let f = figures(at.gap, &at, &m, dir).unwrap();
        assert_eq!(f.before, 0.16 / 0.19);
        let (vk, gl) = (0.30 - 0.17, 0.32 - 0.19);
        assert!((f.after - vk / gl).abs() < 1e-12, "{}", f.after);
        assert_eq!(f.ms, Some([0.16, 0.19, vk, gl]));
    }
}
