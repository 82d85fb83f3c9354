//! The hard cases (scenes/hard/) under each strategy: the default, the
//! default with world coordinates in f32, and one numerical knob changed,
//! with both apps, as the share of wrong pixels against the f64 truth.

use super::sweeps::render_app;
use crate::apps::api_name;
use crate::apps::Api;
use std::path::{Path, PathBuf};
use twinray_common::cli::Size;
use twinray_common::reference;
use twinray_common::scene::hard::{self, HardCase};
use twinray_common::scene::numerics::{Numerics, Offset, SphereTest, TriangleTest};
use twinray_common::scene::OriginMode;
use twinray_common::scene::Scene;
use twinray_common::value_name::ValueName;

/// One hard case under one strategy and API.
#[derive(Debug, Clone)]
pub struct HardRow {
    pub case: String,
    pub tolerance_pct: f64,
    pub strategy: String,
    pub api: Api,
    /// (wrong share, crack pixels if checked, time ms, non-finite pixels)
    pub result: Result<(f64, Option<usize>, f64, u64), String>,
    /// The same image over the pixels outside the truth's unsettled mask
    /// (its `above_8` is the wrong share there).
    pub outside: Option<super::sweeps::Outside>,
}

impl HardRow {
    /// Within the case's tolerance and without a NaN/Inf pixel.
    pub fn passes(&self) -> bool {
        matches!(&self.result, Ok((w, _, _, nan)) if 100.0 * w <= self.tolerance_pct && *nan == 0)
    }
}

/// The hard cases of `dir` (default: scenes/hard of this source tree), read
/// before any sweep runs, so that a bad `--hard` costs nothing.
pub fn cases(dir: Option<&Path>) -> anyhow::Result<Vec<HardCase>> {
    let dir = dir.map(Path::to_path_buf).unwrap_or_else(|| {
        let local = PathBuf::from("scenes/hard");
        if local.is_dir() {
            local
        } else {
            PathBuf::from(hard::SOURCE_DIR)
        }
    });
    hard::list(&dir)
}

/// Every hard case at 64x64 under every strategy.
pub fn run_all(
    cases: &[HardCase],
    out: &Path,
    stop: &std::sync::atomic::AtomicBool,
) -> anyhow::Result<Vec<HardRow>> {
    let size = Size {
        width: 64,
        height: 64,
    };
    eprintln!(
        "twinray accuracy: {} hard cases at {size}, {} strategies x 2 APIs",
        cases.len(),
        hard_strategies().len()
    );
    let mut rows = Vec::new();
    for case in cases {
        if stop.load(std::sync::atomic::Ordering::SeqCst) {
            break;
        }
        rows.extend(run_hard(case, size, out, stop)?);
    }
    Ok(rows)
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
    /// `--set` overrides whatever the scene file's `[render]` section chose.
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

fn run_hard(
    case: &HardCase,
    size: Size,
    out: &Path,
    stop: &std::sync::atomic::AtomicBool,
) -> anyhow::Result<Vec<HardRow>> {
    let path = case.path.to_string_lossy().to_string();
    let scene = Scene::load(&path, &[])?;
    let truth = reference::render_truth(&scene, size.width, size.height);
    truth.save_png(&out.join(format!("images/hard-{}-truth.png", case.name)))?;
    let truth = truth.to_rgb8();
    let mask = super::sweeps::truth_mask(&scene, size);
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
            let mut outside = None;
            let result = render_app(api, &path, size, strategy.set_args(), 1, &png)
                .map(|(g, w, nan, img)| {
                    let crack = cracks.then(|| hard::crack_pixels(&img, &truth, background));
                    outside = super::sweeps::outside(&img, &truth, &mask).ok();
                    (hard::wrong_share(&img, &truth), crack, g.unwrap_or(w), nan)
                })
                .map_err(|e| format!("{e:#}"));
            if stop.load(std::sync::atomic::Ordering::SeqCst) && result.is_err() {
                // Stopped by the signal, not failed: not a row of the table.
                return Ok(rows);
            }
            rows.push(HardRow {
                case: case.name.clone(),
                tolerance_pct: case.tolerance_pct,
                strategy: label.clone(),
                api,
                result,
                outside,
            });
        }
    }
    Ok(rows)
}
