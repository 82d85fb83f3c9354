//! `twinray accuracy`: speed against error. Renders the standard scenes with
//! both apps over the knobs that trade one for the other (maximum depth, the
//! secondary-ray offset, the triangle and sphere tests), measures every image
//! against the f64 truth (reference.rs `render_truth`, depth 16 for the depth
//! sweep), marks the Pareto front, then runs the hard cases (scenes/hard/) per
//! strategy (with the local origin's before/after columns), and last compares
//! both apps and the reference on seeded random scenes (`--random N`). Writes
//! report.md, accuracy.csv, hard_cases.csv, random.csv, one SVG per scene and
//! the images.

use crate::apps::{run_json, Api};
use crate::compare::api_name;
use anyhow::Context;
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use twinray_common::cli::{RenderArgs, Size};
use twinray_common::limits::MAX_DEPTH;
use twinray_common::reference;
use twinray_common::reference::metrics;
use twinray_common::scene::hard::{self, HardCase, WRONG_ABOVE};
use twinray_common::scene::numerics::{Numerics, Offset, SphereTest, TriangleTest};
use twinray_common::scene::random;
use twinray_common::scene::OriginMode;
use twinray_common::scene::Scene;
use twinray_common::value_name::ValueName;

#[derive(clap::Args, Debug, Clone)]
pub struct AccuracyArgs {
    /// Small images and few frames: a few minutes on software drivers.
    #[arg(long)]
    pub quick: bool,
    /// Output folder.
    #[arg(long, default_value = "accuracy-out")]
    pub out: PathBuf,
    /// The hard-case folder (default: scenes/hard of this source tree).
    #[arg(long)]
    pub hard: Option<PathBuf>,
    /// Skip the hard cases.
    #[arg(long)]
    pub no_hard: bool,
    /// Random scenes (`--scene random:SEED`, seeds 0..N) rendered by both
    /// apps and the reference; default 100, 10 with --quick, 0 skips them.
    #[arg(long, value_name = "N")]
    pub random: Option<u64>,
}

/// One random scene's three renders compared pairwise.
#[derive(Debug, Clone)]
pub struct RandomRow {
    pub seed: u64,
    /// "Vulkan vs reference", "OpenGL vs reference", "Vulkan vs OpenGL".
    pub pair: &'static str,
    pub result: Result<metrics::Metrics, String>,
}

const RANDOM_PAIRS: [&str; 3] = [
    "Vulkan vs reference",
    "OpenGL vs reference",
    "Vulkan vs OpenGL",
];

fn random_size(quick: bool) -> Size {
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
fn run_random(n: u64, size: Size, out: &Path) -> anyhow::Result<Vec<RandomRow>> {
    let mut rows = Vec::new();
    for seed in 0..n {
        let name = format!("{}{seed}", random::PREFIX);
        let scene = Scene::load(&name, &[])?;
        let reference = reference::render(&scene, size.width, size.height);
        let ref_nan = reference.nonfinite_pixels() as u64;
        let reference = reference.to_rgb8();
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
        for (pair, result) in RANDOM_PAIRS.into_iter().zip(results) {
            let bad = match &result {
                Ok(m) => random::disagreement(m),
                Err(e) => Some(e.clone()),
            };
            if let Some(why) = bad {
                eprintln!(
                    "  random:{seed} {pair}: {why}\n  reproduce: {}",
                    random::reproduce(seed, size.width, size.height, "")
                );
            }
            rows.push(RandomRow { seed, pair, result });
        }
    }
    Ok(rows)
}

fn random_csv(rows: &[RandomRow]) -> String {
    let mut s =
        String::from("seed,pair,status,off_8_pct,within_1_pct,max_abs,rmse,nonfinite_pixels\n");
    for r in rows {
        match &r.result {
            Ok(m) => {
                let _ = writeln!(
                    s,
                    "{},{},{},{},{},{},{},{}",
                    r.seed,
                    q(r.pair),
                    if random::disagreement(m).is_some() {
                        "disagree"
                    } else {
                        "ok"
                    },
                    100.0 * m.above_8,
                    100.0 * m.within_1(),
                    m.max_abs,
                    m.rmse,
                    m.nan_pixels
                );
            }
            Err(e) => {
                let _ = writeln!(
                    s,
                    "{},{},{},,,,,",
                    r.seed,
                    q(r.pair),
                    q(&format!("failed: {e}"))
                );
            }
        }
    }
    s
}

/// The value at quantile `p` (0..1) of sorted `v` (nearest rank).
fn quantile(v: &[f64], p: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v[((p * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1]
}

fn random_markdown(rows: &[RandomRow], size: Size) -> String {
    let mut s = String::new();
    let seeds = rows.iter().map(|r| r.seed).max().map_or(0, |m| m + 1);
    let _ = writeln!(
        s,
        "## Random scenes ({seeds} seeds, {size})\n\n`--scene random:SEED` for seeds 0..{seeds} (common/src/scene/random.rs: spheres, triangles, \
         a mesh, diffuse, mirror and glass with glass inside glass, 1–4 lights, random cameras), each rendered by both apps and \
         the f64 reference with the scene's own numerics. A pair disagrees when more than {:.2}% of its pixels are off by more \
         than 8/255 or fewer than {:.0}% are within 1/255 (the thresholds tests/tests/random_scenes.rs applies to 20 seeds). \
         Distribution over the seeds:\n",
        100.0 * random::MAX_OFF_SHARE,
        100.0 * random::MIN_WITHIN_1
    );
    let _ = writeln!(
        s,
        "| pair | seeds | disagree | off by >8/255: median / 90% / 99% / max | within 1/255: min / 1% / median | max abs: median / max |\n|---|---|---|---|---|---|"
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
                    .map_or(true, |m| random::disagreement(m).is_some())
            })
            .collect();
        for r in &bad {
            failing.push(format!(
                "- random:{} {pair}: {}. Reproduce: `{}`",
                r.seed,
                match &r.result {
                    Ok(m) => random::disagreement(m).unwrap_or_default(),
                    Err(e) => e.replace('\n', " "),
                },
                random::reproduce(r.seed, size.width, size.height, "")
            ));
        }
        let _ = writeln!(
            s,
            "| {pair} | {} | {} | {:.3}% / {:.3}% / {:.3}% / {:.3}% | {:.2}% / {:.2}% / {:.2}% | {:.0} / {:.0} |",
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
        );
    }
    if failing.is_empty() {
        let _ = writeln!(s, "\nEvery seed agrees within the thresholds.\n");
    } else {
        let _ = writeln!(s, "\nDisagreeing seeds:\n\n{}\n", failing.join("\n"));
    }
    s
}

/// One point of a sweep: a maximum depth and a numerical configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct Config {
    pub max_depth: u32,
    pub numerics: Numerics,
}

impl Config {
    fn set_args(&self) -> Vec<String> {
        let mut v = self.numerics.set_args();
        v.push(format!("max_depth={}", self.max_depth));
        v
    }
    fn label(&self) -> String {
        format!("depth {} {}", self.max_depth, self.numerics.label())
    }
}

/// What a sweep varies; a config may belong to several (the default to all).
fn sweeps_of(c: &Config, default: &Config) -> Vec<&'static str> {
    let n = &c.numerics;
    let d = &default.numerics;
    let mut s = Vec::new();
    if n == d {
        s.push("depth");
    }
    if c.max_depth == default.max_depth {
        if n.triangle == d.triangle && n.sphere == d.sphere {
            s.push("offset");
        }
        if n.offset == d.offset && n.sphere == d.sphere {
            s.push("triangle");
        }
        if n.offset == d.offset && n.triangle == d.triangle {
            s.push("sphere");
        }
    }
    s
}

/// The one-knob-at-a-time sweeps around the scene's default.
pub fn configs(default: &Config) -> Vec<Config> {
    let mut v: Vec<Config> = Vec::new();
    let mut push = |c: Config| {
        if !v.contains(&c) {
            v.push(c);
        }
    };
    push(default.clone());
    for d in 1..=8 {
        push(Config {
            max_depth: d,
            numerics: default.numerics,
        });
    }
    for offset in Offset::ALL {
        push(Config {
            numerics: Numerics {
                offset,
                ..default.numerics
            },
            ..default.clone()
        });
    }
    for triangle in TriangleTest::ALL {
        push(Config {
            numerics: Numerics {
                triangle,
                ..default.numerics
            },
            ..default.clone()
        });
    }
    for sphere in SphereTest::ALL {
        push(Config {
            numerics: Numerics {
                sphere,
                ..default.numerics
            },
            ..default.clone()
        });
    }
    v
}

/// The standard scenes and their sizes.
fn scenes(quick: bool) -> Vec<(&'static str, Size, Vec<String>)> {
    let s = |w, h| Size {
        width: w,
        height: h,
    };
    if quick {
        vec![
            ("box", s(96, 72), vec![]),
            ("teapot", s(48, 36), vec![]),
            ("spherelist", s(96, 72), vec!["extra_spheres=100".into()]),
        ]
    } else {
        vec![
            ("box", s(640, 480), vec![]),
            ("teapot", s(320, 240), vec![]),
            ("spherelist", s(400, 300), vec!["extra_spheres=100".into()]),
        ]
    }
}

/// Error of one image against the truth.
#[derive(Debug, Clone, Copy)]
pub struct Error {
    pub rmse: f64,
    pub max_abs: u8,
    pub above_1: f64,
    pub wrong: f64,
    pub flip: Option<f64>,
}

fn error_of(test: &image::RgbImage, truth: &image::RgbImage) -> anyhow::Result<Error> {
    let m = metrics::compare(test, truth)?;
    Ok(Error {
        rmse: m.rmse,
        max_abs: m.max_abs,
        above_1: m.above_1,
        wrong: hard::wrong_share(test, truth),
        flip: flip_mean(test, truth),
    })
}

/// Mean FLIP error (NVIDIA's perceptual metric, nv-flip) at the default
/// viewing distance (67 pixels per degree).
fn flip_mean(test: &image::RgbImage, truth: &image::RgbImage) -> Option<f64> {
    if test.dimensions() != truth.dimensions() {
        return None;
    }
    let (w, h) = truth.dimensions();
    let r = nv_flip::FlipImageRgb8::with_data(w, h, truth.as_raw());
    let t = nv_flip::FlipImageRgb8::with_data(w, h, test.as_raw());
    let map = nv_flip::flip(r, t, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    Some(nv_flip::FlipPool::from_image(&map).mean() as f64)
}

/// One app run at one config.
#[derive(Debug, Clone)]
pub struct Row {
    pub scene: String,
    pub size: Size,
    pub config: Config,
    pub sweeps: Vec<&'static str>,
    pub api: Api,
    pub result: Result<(Option<f64>, f64, Error, u64), String>,
    pub pareto: bool,
    /// Its numerics render every hard case within tolerance (or no hard cases ran).
    pub sound: bool,
    pub is_default: bool,
    /// The shader this config compiles to on this scene (its defines). Rows
    /// with the same program and scene are one point of the front: a max
    /// depth that no mirror or glass can use changes nothing but the noise.
    pub program: String,
    /// More timings of the same config (the default runs again first and last).
    pub repeats: Vec<f64>,
}

impl Row {
    /// GPU time if the driver has timers, else wall time (fastest frame).
    fn time(&self) -> Option<f64> {
        self.result
            .as_ref()
            .ok()
            .map(|(g, w, _, _)| g.unwrap_or(*w))
    }
    fn error(&self) -> Option<&Error> {
        self.result.as_ref().ok().map(|r| &r.2)
    }
}

fn render_app(
    api: Api,
    scene: &str,
    size: Size,
    set: Vec<String>,
    frames: u32,
    png: &Path,
) -> anyhow::Result<(Option<f64>, f64, u64, image::RgbImage)> {
    let args = RenderArgs {
        frames: Some(frames),
        out: Some(png.to_path_buf()),
        json: true,
        set,
        ..RenderArgs::headless(scene, size)
    };
    let r = run_json(api, &args)?;
    let img = twinray_common::reference::image_io::load_png(png)?;
    // The fastest frame, not the median: other work on a shared machine only
    // ever adds time, so the minimum is the steadiest estimate of the cost.
    let wall = r.wall_ms.map(|s| s.min).unwrap_or(f64::NAN);
    Ok((r.gpu_ms.map(|s| s.min), wall, r.nonfinite_pixels, img))
}

fn overrides(set: &[String]) -> Vec<(String, String)> {
    set.iter()
        .filter_map(|kv| kv.split_once('='))
        .map(|(k, v)| (k.into(), v.into()))
        .collect()
}

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

fn median(v: &mut [f64]) -> Option<f64> {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    (n > 0).then(|| 0.5 * (v[(n - 1) / 2] + v[n / 2]))
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
    let t = median(&mut timings(rows, &r.scene, r.api, &r.program))?;
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
fn mark_pareto(rows: &mut [Row], unsound: &[Numerics]) {
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

/// The shader a config compiles to on a scene, as its sorted defines.
fn program_of(scene: &str, set: &[String]) -> anyhow::Result<String> {
    let scene = Scene::load(scene, &overrides(set))?;
    // The variant the apps would compile for this scene with default options.
    let args = RenderArgs::headless(
        &scene.name,
        Size {
            width: 1,
            height: 1,
        },
    );
    let v = twinray_common::shader::variant::Variant::chosen(&scene, &args);
    Ok(v.defines
        .iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect::<Vec<_>>()
        .join(" "))
}

/// One hard case under one strategy and API.
#[derive(Debug, Clone)]
pub struct HardRow {
    pub case: String,
    pub tolerance_pct: f64,
    pub strategy: String,
    pub api: Api,
    /// (wrong share, crack pixels if checked, time ms, non-finite pixels)
    pub result: Result<(f64, Option<usize>, f64, u64), String>,
}

pub fn run(args: &AccuracyArgs) -> anyhow::Result<()> {
    twinray_common::reference::image_io::prepare_output_dir("--out", &args.out)?;
    twinray_common::reference::image_io::prepare_output_dir("--out", &args.out.join("images"))?;
    let frames = if args.quick { 5 } else { 30 };
    let mut rows: Vec<Row> = Vec::new();
    let started = std::time::Instant::now();
    for (scene_name, size, set) in scenes(args.quick) {
        let scene = Scene::load(scene_name, &overrides(&set))?;
        let default = Config {
            max_depth: scene.max_depth,
            numerics: scene.numerics,
        };
        let mut deep = scene.clone();
        deep.max_depth = MAX_DEPTH;
        let truth = reference::render_truth(&deep, size.width, size.height);
        truth.save_png(&args.out.join(format!("images/{scene_name}-truth.png")))?;
        let truth = truth.to_rgb8();
        // The default goes in the middle of the run order, not first: on the
        // software driver the first timed configuration after the truth render
        // came out 30-45% slower than the same shader later on.
        let mut list = configs(&default);
        let mid = list.len() / 2;
        list.rotate_left(mid);
        // The default also runs first and last: the spread of its timings is
        // the time tie of the front (see `time_tie`).
        let mut order: Vec<(usize, bool)> = (0..list.len()).map(|k| (k, false)).collect();
        let def_k = list.iter().position(|c| *c == default).unwrap_or(0);
        order.insert(0, (def_k, true));
        order.push((def_k, true));
        let mut repeats: Vec<(Api, f64)> = Vec::new();
        // One discarded run per API first: the first process to meet a shader
        // variant compiles it into Mesa's cache and warms the driver, and that
        // run would otherwise always be the default's.
        for api in [Api::Vulkan, Api::Opengl] {
            let png = args.out.join(format!("images/{scene_name}-warmup.png"));
            let mut s = set.clone();
            s.extend(default.set_args());
            let _ = render_app(api, scene_name, size, s, 2, &png);
            let _ = std::fs::remove_file(&png);
        }
        eprintln!(
            "twinray accuracy: {scene_name} at {size}: {} configurations x 2 APIs",
            list.len()
        );
        for (slot, &(k, repeat)) in order.iter().enumerate() {
            let c = &list[k];
            for api in if slot % 2 == 0 {
                [Api::Vulkan, Api::Opengl]
            } else {
                [Api::Opengl, Api::Vulkan]
            } {
                let mut s = set.clone();
                s.extend(c.set_args());
                if repeat {
                    let png = args
                        .out
                        .join(format!("images/{scene_name}-{}-repeat.png", api_name(api)));
                    match render_app(api, scene_name, size, s, frames, &png) {
                        Ok((g, w, _, _)) => repeats.push((api, g.unwrap_or(w))),
                        Err(e) => eprintln!(
                            "  {scene_name} default (repeat) {}: FAILED: {e:#}",
                            api_name(api)
                        ),
                    }
                    let _ = std::fs::remove_file(&png);
                    continue;
                }
                let png = args
                    .out
                    .join(format!("images/{scene_name}-{}-{k}.png", api_name(api)));
                let program = program_of(scene_name, &s)?;
                let result = render_app(api, scene_name, size, s, frames, &png)
                    .and_then(|(g, w, nan, img)| Ok((g, w, error_of(&img, &truth)?, nan)))
                    .map_err(|e| format!("{e:#}"));
                if let Err(e) = &result {
                    eprintln!(
                        "  {scene_name} {} {}: FAILED: {e}",
                        c.label(),
                        api_name(api)
                    );
                }
                rows.push(Row {
                    scene: scene_name.into(),
                    size,
                    config: c.clone(),
                    sweeps: sweeps_of(c, &default),
                    api,
                    result,
                    pareto: false,
                    sound: true,
                    is_default: *c == default,
                    program,
                    repeats: Vec::new(),
                });
            }
        }
        for r in rows
            .iter_mut()
            .filter(|r| r.scene == scene_name && r.is_default)
        {
            r.repeats = repeats
                .iter()
                .filter(|(a, _)| *a == r.api)
                .map(|(_, t)| *t)
                .collect();
        }
    }
    mark_pareto(&mut rows, &[]);

    let mut hard_rows = Vec::new();
    let mut cases = Vec::new();
    if !args.no_hard {
        let dir = args.hard.clone().unwrap_or_else(|| {
            let local = PathBuf::from("scenes/hard");
            if local.is_dir() {
                local
            } else {
                PathBuf::from(hard::SOURCE_DIR)
            }
        });
        cases = hard::list(&dir)?;
        let size = Size {
            width: 64,
            height: 64,
        };
        eprintln!(
            "twinray accuracy: {} hard cases at {size}, {} strategies x 2 APIs",
            cases.len(),
            hard_strategies().len()
        );
        for case in &cases {
            hard_rows.extend(run_hard(case, size, &args.out)?);
        }
    }

    let random_n = args.random.unwrap_or(if args.quick { 10 } else { 100 });
    let random_rows = if random_n > 0 {
        let size = random_size(args.quick);
        eprintln!("twinray accuracy: {random_n} random scenes at {size} x (2 APIs + reference)");
        let r = run_random(random_n, size, &args.out)?;
        std::fs::write(args.out.join("random.csv"), random_csv(&r))
            .context("writing random.csv")?;
        r
    } else {
        Vec::new()
    };

    let cpu = crate::report::cpu_model();
    std::fs::write(args.out.join("hard_cases.csv"), hard_csv(&hard_rows))
        .context("writing hard_cases.csv")?;
    // With the hard cases known, numerics that fail any of them leave the front.
    // (The world-origin column is not a numerical choice of the sweeps: every
    // sweep runs with the local origin.)
    let unsound: Vec<Numerics> = hard_strategies()
        .into_iter()
        .filter(|st| st.origin == OriginMode::Local)
        .filter(|st| {
            hard_rows.iter().filter(|r| r.strategy == st.label).any(|r| {
                !matches!(&r.result, Ok((w, _, _, nan)) if 100.0 * w <= r.tolerance_pct && *nan == 0)
            })
        })
        .map(|st| st.numerics)
        .collect();
    mark_pareto(&mut rows, &unsound);
    std::fs::write(args.out.join("accuracy.csv"), csv(&rows)).context("writing accuracy.csv")?;
    let mut plots = Vec::new();
    for (scene_name, _, _) in scenes(args.quick) {
        let file = format!("accuracy-{scene_name}.svg");
        let these: Vec<&Row> = rows.iter().filter(|r| r.scene == scene_name).collect();
        plot(&args.out.join(&file), scene_name, &these)
            .with_context(|| format!("plotting {file}"))?;
        plots.push(file);
    }
    let mut md = markdown(
        args,
        &rows,
        &hard_rows,
        &cases,
        &plots,
        &cpu,
        started.elapsed().as_secs_f64(),
    );
    if !random_rows.is_empty() {
        // Before the closing line that names the files.
        let at = md.rfind("Every row is in").unwrap_or(md.len());
        md.insert_str(at, &random_markdown(&random_rows, random_size(args.quick)));
    }
    std::fs::write(args.out.join("report.md"), md).context("writing report.md")?;
    eprintln!(
        "twinray accuracy: report: {}",
        args.out.join("report.md").display()
    );
    Ok(())
}

/// One column of the hard-case table: numerical choices and where the GPU's
/// coordinates are measured from.
#[derive(Debug, Clone, PartialEq)]
pub struct HardStrategy {
    pub label: String,
    pub numerics: Numerics,
    pub origin: OriginMode,
}

impl HardStrategy {
    /// `--set` overrides whatever the scene file's [render] section chose.
    pub fn set_args(&self) -> Vec<String> {
        let mut v = self.numerics.set_args();
        v.push(format!("origin={}", self.origin.name()));
        v
    }
}

/// The strategies of the hard-case table: the default, the default without
/// the local origin (what f32 world coordinates cost: the "before" of
/// camera-relative rendering), then one numerical knob changed.
pub fn hard_strategies() -> Vec<HardStrategy> {
    let d = Numerics::default();
    let st = |label: String, numerics: Numerics| HardStrategy {
        label,
        numerics,
        origin: OriginMode::Local,
    };
    let mut v = vec![
        st("default".into(), d),
        HardStrategy {
            label: format!("origin={}", OriginMode::World.name()),
            numerics: d,
            origin: OriginMode::World,
        },
    ];
    for offset in Offset::ALL {
        if offset != d.offset {
            v.push(st(
                format!("offset={}", offset.name()),
                Numerics { offset, ..d },
            ));
        }
    }
    for triangle in TriangleTest::ALL {
        if triangle != d.triangle {
            v.push(st(
                format!("triangle={}", triangle.name()),
                Numerics { triangle, ..d },
            ));
        }
    }
    for sphere in SphereTest::ALL {
        if sphere != d.sphere {
            v.push(st(
                format!("sphere={}", sphere.name()),
                Numerics { sphere, ..d },
            ));
        }
    }
    v
}

fn run_hard(case: &HardCase, size: Size, out: &Path) -> anyhow::Result<Vec<HardRow>> {
    let path = case.path.to_string_lossy().to_string();
    let scene = Scene::load(&path, &[])?;
    let truth = reference::render_truth(&scene, size.width, size.height);
    truth.save_png(&out.join(format!("images/hard-{}-truth.png", case.name)))?;
    let truth = truth.to_rgb8();
    let bg = twinray_common::reference::image_io::FloatImage {
        width: 1,
        height: 1,
        pixels: vec![scene.background.as_vec3().to_array()],
    }
    .to_rgb8();
    let background = bg.get_pixel(0, 0).0;
    let cracks = case.extra.iter().any(|e| e == "cracks");
    let mut rows = Vec::new();
    for strategy in hard_strategies() {
        let label = &strategy.label;
        for api in [Api::Vulkan, Api::Opengl] {
            let png = out.join(format!(
                "images/hard-{}-{}-{}.png",
                case.name,
                label.replace('=', "-"),
                api_name(api)
            ));
            let result = render_app(api, &path, size, strategy.set_args(), 1, &png)
                .map(|(g, w, nan, img)| {
                    let crack = cracks.then(|| hard::crack_pixels(&img, &truth, background));
                    (hard::wrong_share(&img, &truth), crack, g.unwrap_or(w), nan)
                })
                .map_err(|e| format!("{e:#}"));
            rows.push(HardRow {
                case: case.name.clone(),
                tolerance_pct: case.tolerance_pct,
                strategy: label.clone(),
                api,
                result,
            });
        }
    }
    Ok(rows)
}

fn q(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

fn opt(v: Option<f64>) -> String {
    v.map(|x| format!("{x}")).unwrap_or_default()
}

pub fn csv(rows: &[Row]) -> String {
    let mut s = String::from(
        "scene,width,height,api,max_depth,offset,triangle,sphere,sweeps,default,pareto,point_ms,repeat_ms,status,gpu_min_ms,wall_min_ms,rmse,max_abs,above_1,above_8,flip_mean,nonfinite_pixels\n",
    );
    for (i, r) in rows.iter().enumerate() {
        let n = &r.config.numerics;
        let head = format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{}",
            r.scene,
            r.size.width,
            r.size.height,
            api_name(r.api),
            r.config.max_depth,
            n.offset.name(),
            n.triangle.name(),
            n.sphere.name(),
            r.sweeps.join("+"),
            r.is_default,
            r.pareto,
            opt(point(rows, i).map(|p| p.0)),
            r.repeats
                .iter()
                .map(|t| t.to_string())
                .collect::<Vec<_>>()
                .join(";")
        );
        match &r.result {
            Ok((g, w, e, nan)) => {
                let _ = writeln!(
                    s,
                    "{head},ok,{},{w},{},{},{},{},{},{nan}",
                    opt(*g),
                    e.rmse,
                    e.max_abs,
                    e.above_1,
                    e.wrong,
                    opt(e.flip)
                );
            }
            Err(e) => {
                let _ = writeln!(s, "{head},{},,,,,,,,", q(&format!("failed: {e}")));
            }
        }
    }
    s
}

fn hard_csv(rows: &[HardRow]) -> String {
    let mut s = String::from(
        "case,tolerance_pct,strategy,api,status,wrong_pct,crack_pixels,time_ms,nonfinite_pixels\n",
    );
    for r in rows {
        let head = format!(
            "{},{},{},{}",
            r.case,
            r.tolerance_pct,
            q(&r.strategy),
            api_name(r.api)
        );
        match &r.result {
            Ok((w, c, t, nan)) => {
                let _ = writeln!(
                    s,
                    "{head},ok,{},{},{t},{nan}",
                    100.0 * w,
                    c.map(|c| c.to_string()).unwrap_or_default()
                );
            }
            Err(e) => {
                let _ = writeln!(s, "{head},{},,,,", q(&format!("failed: {e}")));
            }
        }
    }
    s
}

fn f3(v: f64) -> String {
    format!("{v:.3}")
}

fn markdown(
    args: &AccuracyArgs,
    rows: &[Row],
    hard_rows: &[HardRow],
    cases: &[HardCase],
    plots: &[String],
    cpu: &str,
    secs: f64,
) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# twinray accuracy — speed against error\n");
    let _ = writeln!(
        s,
        "Preset: {}. CPU: {cpu}. Run time: {:.0} s. Command: `twinray accuracy{} --out {}`.\n",
        if args.quick { "quick" } else { "full" },
        secs,
        if args.quick { " --quick" } else { "" },
        args.out.display()
    );
    let d = Numerics::default();
    let _ = writeln!(
        s,
        "**Default configuration**: offset `{}`, triangle test `{}`, sphere test `{}` (each scene's own max depth).\n",
        d.offset.name(),
        d.triangle.name(),
        d.sphere.name()
    );
    let _ = writeln!(
        s,
        "Error is measured against the *truth*: the f64 reference (`reference::render_truth`) with a 1e-8 offset \
         along the normal, watertight triangles, the stable sphere test, and max depth 16 — so the depth sweep shows \
         what stopping early costs and the numerical sweeps what f32 costs. RMSE and max abs are over 8-bit channels \
         (0..1 and 1/255 steps); `>1/255` and `wrong` are shares of pixels off by more than 1 and {WRONG_ABOVE} steps; FLIP is \
         the mean of NVIDIA's perceptual FLIP error (nv-flip 0.1.2, 67 pixels per degree). Time is the fastest frame's GPU \
         time where the driver has timers, else its wall time (submit + wait); the minimum, because other load on a \
         shared machine only adds time. Every sweep changes one knob from the default; ★ marks the Pareto front of \
         (time, RMSE) per scene and API, ◆ the default. Configurations that compile to the same shader on a scene \
         (a max depth that no mirror or glass can use) are one point, marked = when it is the default's, and a point's \
         time is the median of its timings; the default runs three times (first, in the middle and last), and the \
         spread of its timings (at least 1%) is the time tie: times closer than what the same work scatters from run \
         to run count as equal, as do RMSE within 1%. Numerical choices that render any hard case (below) outside its \
         tolerance are not candidates for the front: correctness on the hard cases is a constraint, not a cost to \
         trade.\n"
    );

    // Summary: where the default stands.
    let _ = writeln!(s, "## Summary\n");
    for api in [Api::Vulkan, Api::Opengl] {
        for scene in rows
            .iter()
            .map(|r| r.scene.clone())
            .collect::<std::collections::BTreeSet<_>>()
        {
            let these: Vec<usize> = (0..rows.len())
                .filter(|&i| rows[i].scene == scene && rows[i].api == api && rows[i].result.is_ok())
                .collect();
            let Some(def) = these.iter().copied().find(|&i| rows[i].is_default) else {
                continue;
            };
            let Some(cheap) = these.iter().copied().min_by(|&a, &b| {
                let t = |i| point(rows, i).map_or(f64::MAX, |p| p.0);
                t(a).total_cmp(&t(b))
            }) else {
                continue;
            };
            let (dt, de) = point(rows, def).unwrap_or((f64::NAN, f64::NAN));
            let (ct, ce) = point(rows, cheap).unwrap_or((f64::NAN, f64::NAN));
            let (tie, times) = time_tie(rows, &scene, api);
            let _ = writeln!(
                s,
                "- {scene}, {}: default {} ms (median of {}: {}; time tie ±{:.1}%), RMSE {:.5}{}; cheapest ({}) {} ms, RMSE {:.5}: the default costs {:.2}×.",
                api_name(api),
                f3(dt),
                times.len(),
                times.iter().map(|t| f3(*t)).collect::<Vec<_>>().join(", "),
                100.0 * tie,
                de,
                if rows[def].pareto { " (on the Pareto front)" } else { " (**not** on the Pareto front)" },
                if rows[cheap].program == rows[def].program { "the default's own shader".to_string() } else { rows[cheap].config.label() },
                f3(ct),
                ce,
                dt / ct
            );
        }
    }
    let _ = writeln!(s);

    let _ = writeln!(s, "## Why this default\n");
    let _ = writeln!(
        s,
        "The numerical knobs decide correctness, the depth decides cost: every numerical choice costs about the same \
         per ray (the sweeps below differ by noise except where noted), so the default takes the choice that keeps the \
         hard cases right, and each scene keeps its own max depth.\n"
    );
    if !hard_rows.is_empty() {
        for HardStrategy { label, .. } in hard_strategies() {
            let these: Vec<&HardRow> = hard_rows.iter().filter(|r| r.strategy == label).collect();
            let ok = these.iter().filter(|r| matches!(&r.result, Ok((w, _, _, nan)) if 100.0 * w <= r.tolerance_pct && *nan == 0)).count();
            let failed: Vec<String> = these
                .iter()
                .filter(|r| !matches!(&r.result, Ok((w, _, _, nan)) if 100.0 * w <= r.tolerance_pct && *nan == 0))
                .map(|r| r.case.clone())
                .fold(Vec::new(), |mut v, c| {
                    if !v.contains(&c) {
                        v.push(c);
                    }
                    v
                });
            let _ = writeln!(
                s,
                "- `{label}`: {ok} of {} hard-case renders within tolerance{}",
                these.len(),
                if failed.is_empty() {
                    String::new()
                } else {
                    format!("; fails {}", failed.join(", "))
                }
            );
        }
        let _ = writeln!(s);
    }
    for (i, r) in rows
        .iter()
        .enumerate()
        .filter(|(_, r)| r.is_default && r.result.is_ok())
    {
        let by: Vec<String> = dominators(rows, i)
            .into_iter()
            .map(|j| rows[j].config.label())
            .collect();
        let _ = writeln!(
            s,
            "- {} {}: {}",
            r.scene,
            api_name(r.api),
            if by.is_empty() {
                "the default is on the Pareto front".to_string()
            } else {
                format!("the default is dominated by {}", by.join("; "))
            }
        );
    }
    let _ = writeln!(
        s,
        "\nWhere a configuration with a *smaller max depth* dominates, the scene simply needs fewer bounces than it allows \
         (no mirror or glass in view beyond that depth): max depth is a per-scene setting, not part of the numerical \
         default. On a shared software driver the time tie is wide and the timings scatter more than it says; the GPU \
         report is the one to read for speed.\n"
    );

    for scene in rows
        .iter()
        .map(|r| r.scene.clone())
        .collect::<Vec<_>>()
        .iter()
        .fold(Vec::<String>::new(), |mut v, x| {
            if !v.contains(x) {
                v.push(x.clone());
            }
            v
        })
    {
        let these: Vec<&Row> = rows.iter().filter(|r| r.scene == scene).collect();
        let size = these
            .first()
            .map(|r| r.size.to_string())
            .unwrap_or_default();
        let _ = writeln!(s, "## {scene} ({size})\n");
        if let Some(p) = plots.iter().find(|p| p.contains(&format!("-{scene}."))) {
            let _ = writeln!(s, "![{scene}]({p})\n");
        }
        let _ = writeln!(s, "| sweep | max depth | offset | triangle | sphere | API | GPU ms (min) | wall ms (min) | RMSE | max abs | >1/255 | wrong | FLIP | NaN | |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
        for r in these {
            let n = &r.config.numerics;
            let same = !r.is_default
                && rows.iter().any(|d| {
                    d.is_default && d.scene == r.scene && d.api == r.api && d.program == r.program
                });
            let mark = format!(
                "{}{}",
                if r.pareto { "★" } else { "" },
                if r.is_default {
                    "◆"
                } else if same {
                    "="
                } else {
                    ""
                }
            );
            let head = format!(
                "| {} | {} | {} | {} | {} | {} |",
                r.sweeps.join(", "),
                r.config.max_depth,
                n.offset.name(),
                n.triangle.name(),
                n.sphere.name(),
                api_name(r.api)
            );
            match &r.result {
                Ok((g, w, e, nan)) => {
                    let _ = writeln!(
                        s,
                        "{head} {} | {} | {:.5} | {} | {:.2}% | {:.2}% | {} | {} | {mark} |",
                        g.map(f3).unwrap_or_else(|| "–".into()),
                        f3(*w),
                        e.rmse,
                        e.max_abs,
                        100.0 * e.above_1,
                        100.0 * e.wrong,
                        e.flip
                            .map(|f| format!("{f:.4}"))
                            .unwrap_or_else(|| "–".into()),
                        nan
                    );
                }
                Err(e) => {
                    let _ = writeln!(
                        s,
                        "{head} failed: {} | | | | | | | | |",
                        e.replace('|', "/")
                    );
                }
            }
        }
        let _ = writeln!(s);
    }

    if !hard_rows.is_empty() {
        let strategies: Vec<String> = hard_strategies().into_iter().map(|st| st.label).collect();
        let _ = writeln!(
            s,
            "## Hard cases (scenes/hard/, 64x64)\n\nShare of wrong pixels (off by more than {WRONG_ABOVE}/255 against the truth) per case, \
             strategy and API (Vulkan / OpenGL); crack pixels in brackets where the case counts them. **Bold**: above the case's \
             tolerance. The default must pass every case (tests/tests/hard_cases.rs checks it).\n"
        );
        let _ = write!(s, "| case | tolerance |");
        for st in &strategies {
            let _ = write!(s, " {st} |");
        }
        let _ = writeln!(s, "\n|---|---|{}", "---|".repeat(strategies.len()));
        for case in cases {
            let _ = write!(s, "| {} | {}% |", case.name, case.tolerance_pct);
            for st in &strategies {
                let cell: Vec<String> = [Api::Vulkan, Api::Opengl]
                    .iter()
                    .map(|api| {
                        match hard_rows
                            .iter()
                            .find(|r| r.case == case.name && &r.strategy == st && r.api == *api)
                            .map(|r| &r.result)
                        {
                            Some(Ok((w, c, _, nan))) => {
                                let v = format!("{:.2}", 100.0 * w);
                                let v = if 100.0 * w > case.tolerance_pct {
                                    format!("**{v}**")
                                } else {
                                    v
                                };
                                let c = c.map(|c| format!(" [{c}]")).unwrap_or_default();
                                let nan = if *nan > 0 {
                                    format!(" NaN {nan}")
                                } else {
                                    String::new()
                                };
                                format!("{v}{c}{nan}")
                            }
                            Some(Err(_)) => "failed".into(),
                            None => "–".into(),
                        }
                    })
                    .collect();
                let _ = write!(s, " {} |", cell.join(" / "));
            }
            let _ = writeln!(s);
        }
        let _ = write!(s, "{}", origin_table(hard_rows, cases));
        // What each strategy costs: total time over all cases, and how many cases it fails.
        let _ = writeln!(s, "\n| strategy | cases within tolerance (VK / GL) | total time over the cases, ms (VK / GL) | worst case |\n|---|---|---|---|");
        for st in &strategies {
            let mut cells = Vec::new();
            let mut times = Vec::new();
            for api in [Api::Vulkan, Api::Opengl] {
                let these: Vec<&HardRow> = hard_rows
                    .iter()
                    .filter(|r| &r.strategy == st && r.api == api)
                    .collect();
                let ok = these.iter().filter(|r| matches!(&r.result, Ok((w, _, _, nan)) if 100.0 * w <= r.tolerance_pct && *nan == 0)).count();
                cells.push(format!("{ok}/{}", these.len()));
                times.push(f3(these
                    .iter()
                    .filter_map(|r| r.result.as_ref().ok().map(|x| x.2))
                    .sum::<f64>()));
            }
            let worst = hard_rows
                .iter()
                .filter(|r| &r.strategy == st)
                .filter_map(|r| r.result.as_ref().ok().map(|x| (r, x.0)))
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .map(|(r, w)| format!("{} ({}): {:.2}% wrong", r.case, api_name(r.api), 100.0 * w))
                .unwrap_or_default();
            let _ = writeln!(
                s,
                "| {st} | {} | {} | {worst} |",
                cells.join(" / "),
                times.join(" / ")
            );
        }
        let _ = writeln!(s);
    }
    let _ = writeln!(
        s,
        "Every row is in `accuracy.csv` and `hard_cases.csv` (the random scenes' in `random.csv`); the images are in `images/`."
    );
    s
}

/// Before / after camera-relative rendering: the cases whose local origin is
/// not zero, rendered with world coordinates in f32 (`origin=world`, before)
/// and relative to the local origin (the default, after), measured as rows.
fn origin_table(hard_rows: &[HardRow], cases: &[HardCase]) -> String {
    let mut s = String::new();
    let moved: Vec<(&HardCase, [f64; 3])> = cases
        .iter()
        .filter_map(|c| {
            let scene = Scene::load(&c.path.to_string_lossy(), &[]).ok()?;
            let o = twinray_common::scene::camera::local_origin(&scene).to_array();
            (o != [0.0; 3]).then_some((c, o))
        })
        .collect();
    if moved.is_empty() {
        return s;
    }
    let _ = writeln!(
        s,
        "\n### Local origin: before and after\n\nThe cases whose local origin (the camera's look-at point on a power-of-two \
         grid, `camera::local_origin`) is not zero; every other case has origin zero and identical images in both columns. \
         Wrong pixels (off by more than {WRONG_ABOVE}/255), Vulkan / OpenGL, against the one truth: the f64 reference in the local frame.\n\n\
         | case | local origin | tolerance | before: world coordinates in f32 (`origin=world`) | after: relative to the local origin (default) |\n|---|---|---|---|---|"
    );
    let cell = |case: &str, st: &str| -> String {
        [Api::Vulkan, Api::Opengl]
            .iter()
            .map(|api| {
                match hard_rows
                    .iter()
                    .find(|r| r.case == case && r.strategy == st && r.api == *api)
                    .map(|r| &r.result)
                {
                    Some(Ok((w, _, _, _))) => format!("{:.3}%", 100.0 * w),
                    Some(Err(_)) => "failed".into(),
                    None => "–".into(),
                }
            })
            .collect::<Vec<_>>()
            .join(" / ")
    };
    for (c, o) in moved {
        let _ = writeln!(
            s,
            "| {} | ({:e}, {:e}, {:e}) | {}% | {} | {} |",
            c.name,
            o[0],
            o[1],
            o[2],
            c.tolerance_pct,
            cell(&c.name, &format!("origin={}", OriginMode::World.name())),
            cell(&c.name, "default")
        );
    }
    let _ = writeln!(s);
    s
}

fn plot(path: &Path, scene: &str, rows: &[&Row]) -> anyhow::Result<()> {
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
    let mut chart = crate::report::log_log_chart(
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
    crate::report::finish_chart(&mut chart, &root, SeriesLabelPosition::UpperRight)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sweeps_change_one_knob_and_include_the_default_once() {
        let d = Config {
            max_depth: 5,
            numerics: Numerics::default(),
        };
        let c = configs(&d);
        assert_eq!(c.iter().filter(|x| **x == d).count(), 1);
        assert_eq!(c.len(), 8 + (Offset::ALL.len() - 1) + 1 + 1);
        assert_eq!(
            sweeps_of(&d, &d),
            vec!["depth", "offset", "triangle", "sphere"]
        );
    }

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
