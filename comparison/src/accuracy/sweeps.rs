//! The accuracy sweeps: each standard scene rendered by both apps in every
//! configuration that changes one knob from its default (maximum depth, the
//! secondary-ray offset, the triangle and sphere tests), each image measured
//! against the f64 truth.

use crate::apps::{api_name, overrides};
use crate::apps::{run_json, Api};
use std::path::Path;
use twinray_common::cli::RenderPath;
use twinray_common::cli::{RenderArgs, Size};
use twinray_common::limits::MAX_DEPTH;
use twinray_common::plan::build_bvh;
use twinray_common::plan::requests::Api as AppApi;
use twinray_common::plan::Planner;
use twinray_common::reference;
use twinray_common::reference::metrics;
use twinray_common::scene::hard;
use twinray_common::scene::numerics::{Numerics, Offset, SphereTest, TriangleTest};
use twinray_common::scene::Scene;

/// One point of a sweep: a maximum depth and a numerical configuration.
#[derive(Debug, Clone, PartialEq)]
pub struct Config {
    pub max_depth: u32,
    pub numerics: Numerics,
}

impl Config {
    pub fn set_args(&self) -> Vec<String> {
        let mut v = self.numerics.set_args();
        v.push(format!("max_depth={}", self.max_depth));
        v
    }
    pub fn label(&self) -> String {
        format!("depth {} {}", self.max_depth, self.numerics.label())
    }
}

/// What a sweep varies; a config may belong to several (the default to all).
pub fn sweeps_of(c: &Config, default: &Config) -> Vec<&'static str> {
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
pub fn scenes(quick: bool) -> Vec<(&'static str, Size, Vec<String>)> {
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

/// Error of one image against the truth: over every pixel, and over the
/// pixels outside the truth's unsettled mask, the ones an f32 tracer can be
/// held to (`Outside`).
#[derive(Debug, Clone, Copy)]
pub struct Error {
    pub rmse: f64,
    pub max_abs: u8,
    pub above_1: f64,
    pub wrong: f64,
    pub flip: Option<f64>,
    pub outside: Outside,
}

/// The error outside the unsettled mask, and the mask's size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outside {
    /// Pixels in the mask: left out of the figures below.
    pub mask_pixels: usize,
    /// The largest channel difference outside the mask, in 1/255 steps.
    pub max_abs: u8,
    /// Share of the pixels outside the mask off by more than 8/255.
    pub above_8: f64,
}

/// `test` against `truth` over the pixels `mask` leaves (true: unsettled).
pub fn outside(
    test: &image::RgbImage,
    truth: &image::RgbImage,
    mask: &[bool],
) -> anyhow::Result<Outside> {
    let m = metrics::compare_outside(test, truth, mask)?;
    Ok(Outside {
        mask_pixels: mask.iter().filter(|&&m| m).count(),
        max_abs: m.max_abs,
        above_8: m.above_8,
    })
}

/// The truth's unsettled mask: pixels whose f64 colour moves by more than
/// 8/255 when the primary ray turns by 4 f32 ULPs, at the truth's numerics.
pub fn truth_mask(scene: &Scene, size: Size) -> Vec<bool> {
    twinray_common::reference::unsettled::unsettled_with(
        scene,
        size.width,
        size.height,
        &reference::truth_numerics(),
        twinray_common::reference::unsettled::TURN,
    )
}

fn error_of(
    test: &image::RgbImage,
    truth: &image::RgbImage,
    mask: &[bool],
) -> anyhow::Result<Error> {
    let m = metrics::compare(test, truth)?;
    Ok(Error {
        rmse: m.rmse,
        max_abs: m.max_abs,
        above_1: m.above_1,
        wrong: hard::wrong_share(test, truth),
        flip: flip_mean(test, truth),
        outside: outside(test, truth, mask)?,
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
    pub fn time(&self) -> Option<f64> {
        self.result
            .as_ref()
            .ok()
            .map(|(g, w, _, _)| g.unwrap_or(*w))
    }
    pub fn error(&self) -> Option<&Error> {
        self.result.as_ref().ok().map(|r| &r.2)
    }
}

pub fn render_app(
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

/// The shader a config compiles to on a scene, as its sorted defines.
pub fn program_of(scene: &str, set: &[String]) -> anyhow::Result<String> {
    let scene = Scene::load(scene, &overrides(set))?;
    // The variant the apps would compile for this scene with default options.
    let args = RenderArgs::headless(
        &scene.name,
        Size {
            width: 1,
            height: 1,
        },
    );
    let planner = Planner::new(&args, AppApi::Vulkan)?;
    let bvh = args.accel.wants_bvh(&scene).then(|| build_bvh(&scene));
    let v = planner.variant(&scene, bvh.as_ref(), RenderPath::Fragment, 0);
    Ok(v.defines()
        .iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect::<Vec<_>>()
        .join(" "))
}

/// Renders one scene's truth, then every configuration with both apps (the
/// default three times: its spread is the front's time tie).
pub fn run_scene(
    scene_name: &'static str,
    size: Size,
    set: &[String],
    frames: u32,
    out: &Path,
    stop: &std::sync::atomic::AtomicBool,
) -> anyhow::Result<Vec<Row>> {
    let mut rows: Vec<Row> = Vec::new();
    let scene = Scene::load(scene_name, &overrides(set))?;
    let default = Config {
        max_depth: scene.max_depth,
        numerics: scene.numerics,
    };
    let mut deep = scene.clone();
    deep.max_depth = MAX_DEPTH;
    let truth = reference::render_truth(&deep, size.width, size.height);
    truth.save_png(&out.join(format!("images/{scene_name}-truth.png")))?;
    let truth = truth.to_rgb8();
    let mask = truth_mask(&deep, size);
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
        let png = out.join(format!("images/{scene_name}-warmup.png"));
        let mut s = set.to_vec();
        s.extend(default.set_args());
        let _ = render_app(api, scene_name, size, s, 2, &png);
        let _ = std::fs::remove_file(&png);
    }
    eprintln!(
        "twinray accuracy: {scene_name} at {size}: {} configurations x 2 APIs",
        list.len()
    );
    'runs: for (slot, &(k, repeat)) in order.iter().enumerate() {
        // A signal stops the sweep between runs; the finished rows are kept.
        if stop.load(std::sync::atomic::Ordering::SeqCst) {
            break;
        }
        let c = &list[k];
        for api in if slot % 2 == 0 {
            [Api::Vulkan, Api::Opengl]
        } else {
            [Api::Opengl, Api::Vulkan]
        } {
            let mut s = set.to_vec();
            s.extend(c.set_args());
            if repeat {
                let png = out.join(format!("images/{scene_name}-{}-repeat.png", api_name(api)));
                match render_app(api, scene_name, size, s, frames, &png) {
                    Ok((g, w, _, _)) => repeats.push((api, g.unwrap_or(w))),
                    Err(_) if stop.load(std::sync::atomic::Ordering::SeqCst) => break 'runs,
                    Err(e) => eprintln!(
                        "  {scene_name} default (repeat) {}: FAILED: {e:#}",
                        api_name(api)
                    ),
                }
                let _ = std::fs::remove_file(&png);
                continue;
            }
            let png = out.join(format!("images/{scene_name}-{}-{k}.png", api_name(api)));
            let program = program_of(scene_name, &s)?;
            let result = render_app(api, scene_name, size, s, frames, &png)
                .and_then(|(g, w, nan, img)| Ok((g, w, error_of(&img, &truth, &mask)?, nan)))
                .map_err(|e| format!("{e:#}"));
            if stop.load(std::sync::atomic::Ordering::SeqCst) && result.is_err() {
                // Stopped by the signal, not failed: not a row of accuracy.csv.
                let _ = std::fs::remove_file(&png);
                break 'runs;
            }
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
    Ok(rows)
}

#[cfg(test)]
mod outside_tests {
    use super::*;

    /// A flat image with one pixel changed by `by` at `at`.
    fn flat(at: Option<(u32, u32)>, by: u8) -> image::RgbImage {
        let mut img = image::RgbImage::from_pixel(8, 4, image::Rgb([100, 100, 100]));
        if let Some((x, y)) = at {
            img.put_pixel(x, y, image::Rgb([100 + by, 100, 100]));
        }
        img
    }

    #[test]
    fn a_flip_inside_the_mask_leaves_the_outside_figure_alone() {
        let truth = flat(None, 0);
        let mut mask = vec![false; 32];
        mask[8 + 3] = true; // (3, 1)
        let clean = outside(&flat(None, 0), &truth, &mask).unwrap();
        let inside = outside(&flat(Some((3, 1)), 40), &truth, &mask).unwrap();
        let beyond = outside(&flat(Some((5, 2)), 40), &truth, &mask).unwrap();
        assert_eq!(clean.mask_pixels, 1);
        assert_eq!(inside, clean, "a pixel the mask names must not count");
        assert_eq!(beyond.max_abs, 40);
        assert!((beyond.above_8 - 1.0 / 31.0).abs() < 1e-12, "{beyond:?}");
        // Over every pixel, the flip inside the mask does count.
        let all = metrics::compare(&flat(Some((3, 1)), 40), &truth).unwrap();
        assert_eq!(all.max_abs, 40);
    }
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
}
