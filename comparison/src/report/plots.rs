//! report.md's pictures: one SVG per experiment (ours on both paths beside
//! the study's times) and scaling.svg (frame time against primitives), on the
//! log-log chart that the accuracy plots share.

use crate::apps::api_name;
use crate::apps::Api;
use crate::compare::runs::{AccelRun, Outcome};
use crate::compare::study::StudyRow;
use plotters::prelude::*;
use std::path::Path;
use twinray_common::cli::RenderPath;
use twinray_common::report::RunReport;

/// One line of a plot: its legend, colour and (x, y) points.
struct Series {
    name: String,
    colour: RGBColor,
    points: Vec<(f64, f64)>,
}

/// The chart every plot here draws on.
pub type LogLogChart<'a, 'b> =
    ChartContext<'a, SVGBackend<'b>, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>;

/// Every positive point of `series`: what the axes must span (log scales).
fn positive_points(series: &[Series]) -> Vec<(f64, f64)> {
    series
        .iter()
        .flat_map(|s| s.points.iter().copied())
        .filter(|p| p.0 > 0.0 && p.1 > 0.0)
        .collect()
}

fn x_of(exp: &str, value: &str) -> f64 {
    if exp == "spherelist" {
        value.parse().unwrap_or(1.0)
    } else {
        value
            .split('x')
            .next()
            .and_then(|w| w.parse().ok())
            .unwrap_or(1.0)
    }
}

/// Each API's line on each path: fragment in the full colour, compute in a
/// lighter shade of it.
const API_PATH_COLOURS: [(Api, RenderPath, RGBColor); 6] = [
    (Api::Vulkan, RenderPath::Fragment, RGBColor(200, 30, 30)),
    (Api::Opengl, RenderPath::Fragment, RGBColor(30, 80, 200)),
    (
        Api::OpenglSpirv,
        RenderPath::Fragment,
        RGBColor(120, 60, 160),
    ),
    (Api::Vulkan, RenderPath::Compute, RGBColor(250, 120, 110)),
    (Api::Opengl, RenderPath::Compute, RGBColor(100, 170, 250)),
    (
        Api::OpenglSpirv,
        RenderPath::Compute,
        RGBColor(190, 140, 220),
    ),
];

/// The sweep's parameter, as the x axis names it.
fn x_label(exp: &str) -> &'static str {
    if exp == "spherelist" {
        "extra spheres"
    } else {
        "image width = height (pixels)"
    }
}

pub fn plot(path: &Path, exp: &str, rows: &[&Outcome], study: &[StudyRow]) -> anyhow::Result<()> {
    let mut series: Vec<Series> = Vec::new();
    for (api, path, colour) in API_PATH_COLOURS {
        for gpu in [false, true] {
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .filter(|o| o.api == api && o.path == path)
                .filter_map(|o| {
                    let r = o.result.as_ref().ok()?;
                    let v = if gpu { r.gpu_ms } else { r.wall_ms }?.median;
                    Some((x_of(exp, &o.point.param_value), v))
                })
                .collect();
            if !pts.is_empty() {
                series.push(Series {
                    name: format!(
                        "ours {} {path} {}",
                        api_name(api),
                        if gpu { "GPU" } else { "wall" }
                    ),
                    colour,
                    points: pts,
                });
            }
        }
    }
    let st: Vec<&StudyRow> = study.iter().filter(|r| r.experiment == exp).collect();
    series.push(Series {
        name: "study vulkan".into(),
        colour: RGBColor(240, 140, 40),
        points: st
            .iter()
            .map(|r| (x_of(exp, &r.param_value), r.vulkan_median_s * 1e3))
            .collect(),
    });
    series.push(Series {
        name: "study opengl".into(),
        colour: RGBColor(40, 170, 170),
        points: st
            .iter()
            .map(|r| (x_of(exp, &r.param_value), r.opengl_median_s * 1e3))
            .collect(),
    });

    let all = positive_points(&series);
    let root = SVGBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let caption = format!("{exp}: time per frame (log scale)");
    let mut chart = log_log_chart(&root, &caption, &all, x_label(exp), "milliseconds")?;
    for Series {
        name,
        colour,
        points: pts,
    } in series
    {
        let dashed = name.contains("GPU");
        let style = if name.starts_with("study") {
            colour.stroke_width(1)
        } else {
            colour.stroke_width(2)
        };
        let mut pts = pts;
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        chart
            .draw_series(LineSeries::new(pts.clone(), style))?
            .label(name.clone())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        if dashed {
            chart.draw_series(
                pts.iter()
                    .map(|p| Cross::new(*p, 4, colour.stroke_width(1))),
            )?;
        } else {
            chart.draw_series(pts.iter().map(|p| Circle::new(*p, 3, colour.filled())))?;
        }
    }
    finish_chart(&mut chart, &root, SeriesLabelPosition::UpperLeft)
}

/// Billions of rays per second against the sweep's parameter, one line per
/// API and path: each run's counted rays over its median frame time (GPU, or
/// wall where the run has no GPU timer). Writes nothing and returns false
/// when no run counted its rays.
pub fn plot_grays(path: &Path, exp: &str, rows: &[&Outcome]) -> anyhow::Result<bool> {
    let series: Vec<Series> = API_PATH_COLOURS
        .into_iter()
        .map(|(api, p, colour)| Series {
            name: format!("{} {p}", api_name(api)),
            colour,
            points: rows
                .iter()
                .filter(|o| o.api == api && o.path == p)
                .filter_map(|o| {
                    let rate = o.result.as_ref().ok()?.grays_per_s?;
                    Some((x_of(exp, &o.point.param_value), rate))
                })
                .collect(),
        })
        .filter(|s| !s.points.is_empty())
        .collect();
    let all = positive_points(&series);
    if all.is_empty() {
        return Ok(false);
    }
    let root = SVGBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let caption = format!("{exp}: billions of rays per second (log scale)");
    let mut chart = log_log_chart(&root, &caption, &all, x_label(exp), "Grays/s")?;
    draw_dotted_lines(&mut chart, series)?;
    finish_chart(&mut chart, &root, SeriesLabelPosition::LowerRight)?;
    Ok(true)
}

/// Each series as a line with a dot at each point, in the legend by its name.
fn draw_dotted_lines(chart: &mut LogLogChart, series: Vec<Series>) -> anyhow::Result<()> {
    for Series {
        name,
        colour,
        points: mut pts,
    } in series
    {
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        chart
            .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))?
            .label(name)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        chart.draw_series(pts.iter().map(|p| Circle::new(*p, 3, colour.filled())))?;
    }
    Ok(())
}

/// The chart every plot here draws on: log scales on both axes, padded around
/// `points` (which must not be empty), a caption and labelled axes.
pub fn log_log_chart<'a, 'b>(
    root: &'a DrawingArea<SVGBackend<'b>, plotters::coord::Shift>,
    caption: &str,
    points: &[(f64, f64)],
    x_desc: &str,
    y_desc: &str,
) -> anyhow::Result<LogLogChart<'a, 'b>> {
    let (xmin, xmax) = points
        .iter()
        .fold((f64::MAX, f64::MIN), |a, p| (a.0.min(p.0), a.1.max(p.0)));
    let (ymin, ymax) = points
        .iter()
        .fold((f64::MAX, f64::MIN), |a, p| (a.0.min(p.1), a.1.max(p.1)));
    let mut chart = ChartBuilder::on(root)
        .caption(caption, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d(
            (xmin * 0.8..xmax * 1.25).log_scale(),
            (ymin * 0.5..ymax * 2.0).log_scale(),
        )?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .draw()?;
    Ok(chart)
}

/// Draws the legend at `position` and writes the SVG.
pub fn finish_chart<'a, 'b: 'a>(
    chart: &mut LogLogChart<'a, 'b>,
    root: &DrawingArea<SVGBackend<'b>, plotters::coord::Shift>,
    position: SeriesLabelPosition,
) -> anyhow::Result<()> {
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(position)
        .draw()?;
    root.present()?;
    Ok(())
}

/// Primitives in a run (spheres + triangles), from its own report.
fn primitives(r: &RunReport) -> f64 {
    (r.scene.spheres + r.scene.triangles) as f64
}

/// Frame time against primitive count on log-log axes, brute force and BVH.
pub fn plot_scaling(path: &Path, outcomes: &[Outcome], accel: &[AccelRun]) -> anyhow::Result<()> {
    let ms = |r: &RunReport| r.gpu_ms.or(r.wall_ms).map(|x| x.median);
    let mut series: Vec<Series> = Vec::new();
    let palette = [
        (
            Api::Vulkan,
            [
                RGBColor(200, 30, 30),
                RGBColor(240, 130, 40),
                RGBColor(150, 0, 90),
            ],
        ),
        (
            Api::Opengl,
            [
                RGBColor(30, 80, 200),
                RGBColor(40, 170, 170),
                RGBColor(90, 40, 160),
            ],
        ),
    ];
    for (api, [colour, sphere_bvh, teapot_bvh]) in palette {
        // Brute force: the study's sphere-list sweep plus the crossover runs.
        let mut brute: Vec<(f64, f64)> = outcomes
            .iter()
            // The BVH runs are fragment-path runs: compare like with like.
            .filter(|o| {
                o.api == api && o.point.experiment == "spherelist" && o.path == RenderPath::Fragment
            })
            .filter_map(|o| o.result.as_ref().ok())
            .filter_map(|r| Some((primitives(r), ms(r)?)))
            .collect();
        brute.extend(
            accel
                .iter()
                .filter(|a| {
                    a.api == api && a.scene == "spherelist" && a.config == "variant, brute force"
                })
                .filter_map(|a| a.result.as_ref().ok())
                .filter_map(|r| Some((primitives(r), ms(r)?))),
        );
        let bvh = |scene: &str| -> Vec<(f64, f64)> {
            accel
                .iter()
                .filter(|a| a.api == api && a.scene == scene && a.config == "variant, BVH")
                .filter_map(|a| a.result.as_ref().ok())
                .filter_map(|r| Some((primitives(r), ms(r)?)))
                .collect()
        };
        series.push(Series {
            name: format!("spherelist brute force, {}", api_name(api)),
            colour,
            points: brute,
        });
        series.push(Series {
            name: format!("spherelist BVH, {}", api_name(api)),
            colour: sphere_bvh,
            points: bvh("spherelist"),
        });
        series.push(Series {
            name: format!("teapot BVH, {}", api_name(api)),
            colour: teapot_bvh,
            points: bvh("teapot"),
        });
    }
    series.retain(|s| !s.points.is_empty());
    let all = positive_points(&series);
    if all.is_empty() {
        return Ok(());
    }
    let root = SVGBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = log_log_chart(
        &root,
        "frame time against primitives (log-log)",
        &all,
        "spheres + triangles",
        "milliseconds",
    )?;
    draw_dotted_lines(&mut chart, series)?;
    finish_chart(&mut chart, &root, SeriesLabelPosition::UpperLeft)
}
