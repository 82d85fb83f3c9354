//! Seeded random scenes (`--scene random:SEED`) rendered by both apps and the
//! f64 reference, compared pairwise, and the distribution of their errors.

use super::sweeps::render_app;
use crate::apps::api_name;
use crate::apps::Api;
use std::fmt::Write as _;
use std::path::Path;
use twinray_common::cli::Size;
use twinray_common::reference;
use twinray_common::reference::metrics;
use twinray_common::scene::random as random_scene;
use twinray_common::scene::Scene;

/// One random scene's three renders compared pairwise.
#[derive(Debug, Clone)]
pub struct RandomRow {
    pub seed: u64,
    /// "Vulkan vs reference", "OpenGL vs reference", "Vulkan vs OpenGL".
    pub pair: &'static str,
    pub result: Result<metrics::Metrics, String>,
    /// The same pair over the pixels outside the reference's unsettled mask.
    pub outside: Option<super::sweeps::Outside>,
}

pub const RANDOM_PAIRS: [&str; 3] = [
    "Vulkan vs reference",
    "OpenGL vs reference",
    "Vulkan vs OpenGL",
];

pub fn random_size(quick: bool) -> Size {
    if quick {
        Size {
            width: 48,
            height: 36,
        }
    } else {
        Size {
            width: 160,
            height: 120,
        }
    }
}

/// Renders seeds 0..n with both apps and the reference (the scene's own
/// numerics, so the three should differ by f32 rounding only).
pub fn run_random(
    n: u64,
    size: Size,
    out: &Path,
    stop: &std::sync::atomic::AtomicBool,
) -> anyhow::Result<Vec<RandomRow>> {
    let mut rows = Vec::new();
    for seed in 0..n {
        if stop.load(std::sync::atomic::Ordering::SeqCst) {
            break;
        }
        let name = format!("{}{seed}", random_scene::PREFIX);
        let scene = Scene::load(&name, &[])?;
        let reference = reference::render(&scene, size.width, size.height);
        let ref_nan = reference.nonfinite_pixels() as u64;
        let reference = reference.to_rgb8();
        let mask = twinray_common::reference::unsettled::unsettled(&scene, size.width, size.height);
        let mut imgs = Vec::new();
        for api in [Api::Vulkan, Api::Opengl] {
            let png = out.join(format!("images/random-{seed}-{}.png", api_name(api)));
            imgs.push(
                render_app(api, &name, size, Vec::new(), 1, &png)
                    .map_err(|e| format!("{e:#}"))
                    .map(|(_, _, nan, img)| {
                        let _ = std::fs::remove_file(&png);
                        (nan, img)
                    }),
            );
        }
        if stop.load(std::sync::atomic::Ordering::SeqCst) && imgs.iter().any(Result::is_err) {
            // Stopped by the signal, not failed: not a row of random.csv.
            break;
        }
        let cmp = |a: &Result<(u64, image::RgbImage), String>,
                   b: Option<&Result<(u64, image::RgbImage), String>>|
         -> Result<metrics::Metrics, String> {
            let (na, a) = a.as_ref().map_err(Clone::clone)?;
            let (nb, b) = match b {
                Some(b) => {
                    let (n, i) = b.as_ref().map_err(Clone::clone)?;
                    (*n, i)
                }
                None => (ref_nan, &reference),
            };
            let mut m = metrics::compare(a, b).map_err(|e| format!("{e:#}"))?;
            m.nan_pixels = na + nb;
            Ok(m)
        };
        let results = [
            cmp(&imgs[0], None),
            cmp(&imgs[1], None),
            cmp(&imgs[0], Some(&imgs[1])),
        ];
        let img = |i: usize| imgs[i].as_ref().ok().map(|(_, img)| img);
        let pairs = [
            (img(0), Some(&reference)),
            (img(1), Some(&reference)),
            (img(0), img(1)),
        ];
        let outsides = pairs.map(|(a, b)| {
            a.zip(b)
                .and_then(|(a, b)| super::sweeps::outside(a, b, &mask).ok())
        });
        for ((pair, result), outside) in RANDOM_PAIRS.into_iter().zip(results).zip(outsides) {
            let bad = match &result {
                Ok(m) => random_scene::disagreement(m),
                Err(e) => Some(e.clone()),
            };
            if let Some(why) = bad {
                eprintln!(
                    "  random:{seed} {pair}: {why}\n  reproduce: {}",
                    random_scene::reproduce(seed, size.width, size.height, "")
                );
            }
            rows.push(RandomRow {
                seed,
                pair,
                result,
                outside,
            });
        }
    }
    Ok(rows)
}

/// The value at quantile `p` (0..1) of sorted `v` (nearest rank).
fn quantile(v: &[f64], p: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v[((p * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1]
}

pub fn random_markdown(rows: &[RandomRow], size: Size) -> String {
    let mut s = String::new();
    let seeds = rows.iter().map(|r| r.seed).max().map_or(0, |m| m + 1);
    let _ = writeln!(
        s,
        "## Random scenes ({seeds} seeds, {size})\n\n`--scene random:SEED` for seeds 0..{seeds} (common/src/scene/random.rs: spheres, triangles, \
         a mesh, diffuse, mirror and glass with glass inside glass, 1–4 lights, random cameras), each rendered by both apps and \
         the f64 reference with the scene's own numerics. A pair disagrees when more than {:.2}% of its pixels are off by more \
         than 8/255 or fewer than {:.0}% are within 1/255 (the thresholds tests/tests/random_scenes.rs applies to 20 seeds). \
         Distribution over the seeds:\n",
        100.0 * random_scene::MAX_OFF_SHARE,
        100.0 * random_scene::MIN_WITHIN_1
    );
    let _ = writeln!(
        s,
        "| pair | seeds | disagree | off by >8/255: median / 90% / 99% / max | within 1/255: min / 1% / median | max abs: median / max | outside the unsettled mask: pixels over 8/255 (all seeds) / max abs | mask pixels: median / max |\n|---|---|---|---|---|---|---|---|"
    );
    let mut failing = Vec::new();
    for pair in RANDOM_PAIRS {
        let these: Vec<&RandomRow> = rows.iter().filter(|r| r.pair == pair).collect();
        let ok: Vec<&metrics::Metrics> = these
            .iter()
            .filter_map(|r| r.result.as_ref().ok())
            .collect();
        let mut off: Vec<f64> = ok.iter().map(|m| 100.0 * m.above_8).collect();
        let mut within: Vec<f64> = ok.iter().map(|m| 100.0 * m.within_1()).collect();
        let mut max_abs: Vec<f64> = ok.iter().map(|m| f64::from(m.max_abs)).collect();
        for v in [&mut off, &mut within, &mut max_abs] {
            v.sort_by(f64::total_cmp);
        }
        let bad: Vec<&&RandomRow> = these
            .iter()
            .filter(|r| {
                r.result
                    .as_ref()
                    .map_or(true, |m| random_scene::disagreement(m).is_some())
            })
            .collect();
        for r in &bad {
            failing.push(format!(
                "- random:{} {pair}: {}. Reproduce: `{}`",
                r.seed,
                match &r.result {
                    Ok(m) => random_scene::disagreement(m).unwrap_or_default(),
                    Err(e) => e.replace('\n', " "),
                },
                random_scene::reproduce(r.seed, size.width, size.height, "")
            ));
        }
        let outs: Vec<&super::sweeps::Outside> =
            these.iter().filter_map(|r| r.outside.as_ref()).collect();
        let outside_over_8: f64 = outs
            .iter()
            .map(|o| {
                let compared = (size.width * size.height) as usize - o.mask_pixels;
                (o.above_8 * compared as f64).round()
            })
            .sum();
        let outside_max = outs.iter().map(|o| o.max_abs).max();
        let mut mask_px: Vec<f64> = outs.iter().map(|o| o.mask_pixels as f64).collect();
        mask_px.sort_by(f64::total_cmp);
        let _ = writeln!(
            s,
            "| {pair} | {} | {} | {:.3}% / {:.3}% / {:.3}% / {:.3}% | {:.2}% / {:.2}% / {:.2}% | {:.0} / {:.0} | {} / {} | {} / {} |",
            these.len(),
            bad.len(),
            quantile(&off, 0.5),
            quantile(&off, 0.9),
            quantile(&off, 0.99),
            quantile(&off, 1.0),
            quantile(&within, 0.0),
            quantile(&within, 0.01),
            quantile(&within, 0.5),
            quantile(&max_abs, 0.5),
            quantile(&max_abs, 1.0),
            outside_over_8,
            outside_max.map_or("–".into(), |m| m.to_string()),
            quantile(&mask_px, 0.5),
            quantile(&mask_px, 1.0),
        );
    }
    if failing.is_empty() {
        let _ = writeln!(s, "\nEvery seed agrees within the thresholds.\n");
    } else {
        let _ = writeln!(s, "\nDisagreeing seeds:\n\n{}\n", failing.join("\n"));
    }
    s
}
