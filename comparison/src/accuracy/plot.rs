//! One SVG per scene: time against RMSE on log scales, both APIs, the Pareto
//! front as a step line and the default ringed.

use super::sweeps::Row;
use crate::apps::api_name;
use crate::apps::Api;
use crate::report::plots::{finish_chart, log_log_chart};
use plotters::prelude::*;
use std::path::Path;

pub fn plot(path: &Path, scene: &str, rows: &[&Row]) -> anyhow::Result<()> {
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .filter_map(|r| {
            let (g, w, e, _) = r.result.as_ref().ok()?;
            Some([g.map(|g| (g, e.rmse)), Some((*w, e.rmse))])
        })
        .flatten()
        .flatten()
        .map(|(t, e)| (t.max(1e-3), e.max(1e-5)))
        .collect();
    let root = SVGBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    if pts.is_empty() {
        root.present()?;
        return Ok(());
    }
    let caption = format!("{scene}: time against error (log scales; ★ Pareto front, ◆ default)");
    let mut chart = log_log_chart(
        &root,
        &caption,
        &pts,
        "milliseconds per frame (fastest frame)",
        "RMSE against the f64 truth",
    )?;
    for (api, colour) in [
        (Api::Vulkan, RGBColor(200, 30, 30)),
        (Api::Opengl, RGBColor(30, 80, 200)),
    ] {
        for gpu in [true, false] {
            let mine: Vec<(&Row, f64, f64)> = rows
                .iter()
                .filter(|r| r.api == api)
                .filter_map(|r| {
                    let (g, w, e, _) = r.result.as_ref().ok()?;
                    let t = if gpu { (*g)? } else { *w };
                    Some((*r, t.max(1e-3), e.rmse.max(1e-5)))
                })
                .collect();
            if mine.is_empty() {
                continue;
            }
            let label = format!(
                "{} {}",
                api_name(api),
                if gpu { "GPU time" } else { "wall time" }
            );
            if gpu {
                chart
                    .draw_series(
                        mine.iter()
                            .map(|(_, t, e)| Circle::new((*t, *e), 4, colour.filled())),
                    )?
                    .label(label)
                    .legend(move |(x, y)| Circle::new((x + 10, y), 4, colour.filled()));
            } else {
                chart
                    .draw_series(
                        mine.iter()
                            .map(|(_, t, e)| Circle::new((*t, *e), 4, colour.stroke_width(1))),
                    )?
                    .label(label)
                    .legend(move |(x, y)| Circle::new((x + 10, y), 4, colour.stroke_width(1)));
            }
            // The Pareto front (per API, on the time the front was computed from) as a step line.
            let primary = mine
                .iter()
                .all(|(r, _, _)| r.result.as_ref().map(|x| x.0.is_some()).unwrap_or(false))
                == gpu;
            if primary {
                let mut front: Vec<(f64, f64)> = mine
                    .iter()
                    .filter(|(r, _, _)| r.pareto)
                    .map(|(_, t, e)| (*t, *e))
                    .collect();
                front.sort_by(|a, b| a.0.total_cmp(&b.0));
                chart.draw_series(LineSeries::new(front, colour.stroke_width(2)))?;
            }
            for (r, t, e) in &mine {
                if r.is_default {
                    chart.draw_series(std::iter::once(Circle::new(
                        (*t, *e),
                        9,
                        BLACK.stroke_width(2),
                    )))?;
                }
            }
        }
    }
    finish_chart(&mut chart, &root, SeriesLabelPosition::UpperRight)
}
