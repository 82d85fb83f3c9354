//! The numerical hard cases (scenes/hard/): their machine-readable header
//! (`# checks:`, `# tolerance:`, `# check:`), and the two measures their
//! tests and the accuracy report share: the share of wrong pixels against the
//! f64 truth, and crack pixels inside a silhouette.

use crate::error::bad_input;
use std::path::{Path, PathBuf};

/// A pixel is wrong when some channel is off by more than this many 1/255
/// steps: visible defects (acne, a detached or missing shadow, a crack, a lost
/// hit) are far above it, f32-vs-f64 rounding of smooth shading stays below.
pub const WRONG_ABOVE: u8 = 8;

/// Where the hard cases live in this source tree (the default for tools).
pub const SOURCE_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/hard");

/// The runs besides the default that every hard case must also pass, as app
/// options: a per-pixel tracer's image must not depend on the path, the
/// workgroup or a user's choice of acceleration, and Mesa once lost whole
/// objects with small BVH trees (a one-element stack) and a wall where a
/// workgroup is narrower than its vector. tests/tests/hard_cases.rs renders
/// them, and `twinray hard-runs` prints them for
/// comparison/investigations/accuracy/gpu-tolerances.sh, which measures the
/// tolerances on each driver.
pub const RUNS: [&[&str]; 7] = [
    &["--path", "compute"],
    &["--path", "compute", "--workgroup", "4x4"],
    &["--accel", "bvh"],
    &["--accel", "bvh", "--path", "compute"],
    &["--accel", "bvh", "--path", "compute", "--workgroup", "4x4"],
    // The wide trees: each width on one path, both paths between them.
    &["--accel", "bvh4", "--path", "compute", "--workgroup", "4x4"],
    &["--accel", "bvh8"],
];

#[derive(Debug, Clone, PartialEq)]
pub struct HardCase {
    pub name: String,
    pub path: PathBuf,
    /// The property the case checks, one line.
    pub checks: String,
    /// The largest share of wrong pixels allowed, in percent.
    pub tolerance_pct: f64,
    /// Extra checks: `deterministic` (repeated renders identical), `cracks`.
    pub extra: Vec<String>,
}

/// Reads the header comment lines of a hard-case scene file.
pub fn parse(path: &Path) -> anyhow::Result<HardCase> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        bad_input(format!(
            "hard case '{}' cannot be read: {e}",
            path.display()
        ))
    })?;
    let name = path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("case")
        .to_string();
    let (mut checks, mut tolerance, mut extra) = (None, None, Vec::new());
    for line in text.lines().take_while(|l| l.starts_with('#')) {
        let body = line.trim_start_matches('#').trim();
        if let Some(v) = body.strip_prefix("checks:") {
            checks = Some(v.trim().to_string());
        } else if let Some(v) = body.strip_prefix("tolerance:") {
            let v = v.trim().trim_end_matches('%').trim();
            tolerance = Some(
                v.parse::<f64>()
                    .ok()
                    .filter(|t| (0.0..=100.0).contains(t))
                    .ok_or_else(|| {
                        bad_input(format!(
                            "hard case '{}': '# tolerance: {v}' is not a percentage",
                            path.display()
                        ))
                    })?,
            );
        } else if let Some(v) = body.strip_prefix("check:") {
            extra.push(v.trim().to_string());
        }
    }
    let missing = |what: &str| {
        bad_input(format!(
            "hard case '{}' has no '# {what}:' line at the top",
            path.display()
        ))
    };
    Ok(HardCase {
        name,
        path: path.to_path_buf(),
        checks: checks.ok_or_else(|| missing("checks"))?,
        tolerance_pct: tolerance.ok_or_else(|| missing("tolerance"))?,
        extra,
    })
}

/// Every `*.toml` in `dir`, sorted by name.
pub fn list(dir: &Path) -> anyhow::Result<Vec<HardCase>> {
    let entries = std::fs::read_dir(dir).map_err(|e| {
        bad_input(format!(
            "hard-case folder '{}' cannot be read: {e}",
            dir.display()
        ))
    })?;
    let mut paths: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    paths.iter().map(|p| parse(p)).collect()
}

fn worst(a: &image::Rgb<u8>, b: &image::Rgb<u8>) -> u8 {
    (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap_or(0)
}

/// Share of pixels (0..1) off by more than `WRONG_ABOVE` on some channel.
pub fn wrong_share(test: &image::RgbImage, truth: &image::RgbImage) -> f64 {
    let n = test
        .pixels()
        .zip(truth.pixels())
        .filter(|(a, b)| worst(a, b) > WRONG_ABOVE)
        .count();
    n as f64 / (truth.width() as f64 * truth.height() as f64).max(1.0)
}

/// Wrong pixels strictly inside the truth's silhouette: pixels whose 3×3
/// neighbourhood in the truth shows no `background`, yet differ in `test`.
/// A ray through a crack shows the background or the inside of the mesh.
pub fn crack_pixels(test: &image::RgbImage, truth: &image::RgbImage, background: [u8; 3]) -> usize {
    let (w, h) = truth.dimensions();
    let bg = image::Rgb(background);
    let mut n = 0;
    for y in 1..h.saturating_sub(1) {
        for x in 1..w.saturating_sub(1) {
            let inside = (0..3).all(|dy| {
                (0..3).all(|dx| worst(truth.get_pixel(x + dx - 1, y + dy - 1), &bg) > WRONG_ABOVE)
            });
            if inside && worst(test.get_pixel(x, y), truth.get_pixel(x, y)) > WRONG_ABOVE {
                n += 1;
            }
        }
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_hard_case_has_a_header() {
        let cases = list(Path::new(SOURCE_DIR)).unwrap();
        assert!(cases.len() >= 12, "{} hard cases", cases.len());
        for c in &cases {
            assert!(!c.checks.is_empty(), "{}", c.name);
            crate::scene::Scene::load(c.path.to_str().unwrap(), &[])
                .unwrap_or_else(|e| panic!("{}: {e:#}", c.name));
        }
    }

    #[test]
    fn a_bad_tolerance_is_bad_input() {
        let dir = std::env::temp_dir().join(format!("twinray-hard-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("x.toml");
        std::fs::write(&p, "# checks: x\n# tolerance: lots\n").unwrap();
        let e = parse(&p).unwrap_err();
        assert_eq!(crate::error::exit_code_of(&e), 2);
        assert!(e.to_string().contains("lots"));
    }
}
