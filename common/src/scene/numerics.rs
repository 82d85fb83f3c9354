//! The numerical choices of the tracer: where secondary rays start, which
//! ray-triangle test and which ray-sphere test run. Each is a compile-time
//! define of the one shader (shaders/trace/*.glsl) and a run-time branch of the
//! f64 reference (reference.rs), so both always take the same path.
//!
//! Scene files set them in `[render]` (`offset`, `triangle`, `sphere`), and both
//! apps take the same keys through `--set` (e.g. `--set triangle=watertight`).

use crate::error::bad_input;
use crate::value_name::ValueName;
use serde::Serialize;

/// Where a secondary ray (shadow, mirror, refraction) starts, given the hit
/// point `p`, the geometric normal `n` on the side the ray leaves from, and the
/// new direction `d`.
// ValueEnum for its names only (`ValueName`): `--set` and scene files parse them with aliases.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, clap::ValueEnum)]
pub enum Offset {
    /// `p + epsilon * d`: a fixed distance along the new ray.
    Ray,
    /// `p + epsilon * n`: a fixed distance along the normal.
    Normal,
    /// `p + epsilon * max(1, |p|_inf) * n`: along the normal, growing with the
    /// distance from the origin (twinray's first default).
    NormalScaled,
    /// Wächter & Binder (Ray Tracing Gems, ch. 6): 256 f32 ULPs per unit of
    /// normal, component by component, in integer space; a fixed 1/65536 near
    /// the origin (|p_i| < 1/32). On triangles it starts from the hit point
    /// rebuilt from the barycentrics, as the chapter does. Ignores `epsilon`.
    Ulp,
    /// Along the normal, `2^-22 * max(|o|, |p|, |vertices|)` for triangles and
    /// `2^-20 * max(|o|, |p|)` for spheres (max norms, o the ray origin): a few
    /// f32 ULPs of the largest coordinate the hit was computed from (more for
    /// spheres, whose test squares its inputs), with no absolute floor, so it follows the scene's scale both ways
    /// (far and tiny). On triangles it starts from the hit point rebuilt from
    /// the barycentrics, whose error is a few ULPs of the vertices' coordinates
    /// wherever the ray came from. Ignores `epsilon`.
    ScaleAware,
}

/// The ray-triangle test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, clap::ValueEnum)]
pub enum TriangleTest {
    /// Möller & Trumbore 1997: fast, but a ray through a shared edge can miss both triangles.
    MollerTrumbore,
    /// Woop, Benthin & Wald 2013: edge functions in a ray-aligned, sheared frame,
    /// so adjacent triangles never both miss (without the paper's f64 fallback).
    Watertight,
}

/// The ray-sphere test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, clap::ValueEnum)]
pub enum SphereTest {
    /// `t = (-b ± sqrt(b² - 4ac)) / 2a`: cancels badly for far or small spheres.
    Quadratic,
    /// Haines et al. (Ray Tracing Gems, ch. 7): the discriminant from the centre's
    /// distance to the ray, the near root as c/q.
    Stable,
}

/// One numerical configuration of the tracer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub struct Numerics {
    pub offset: Offset,
    pub triangle: TriangleTest,
    pub sphere: SphereTest,
}

impl Default for Numerics {
    /// The default configuration; `twinray accuracy` shows why (comparison/results/*/accuracy/report.md):
    /// the scale-aware offset is the only one that passes every hard case; the
    /// stable sphere test costs nothing measurable and the quadratic fails three
    /// cases; the watertight triangle test fixed no case that Moller-Trumbore
    /// failed here and is slower on the 19,200-triangle teapot (the reports'
    /// time column).
    fn default() -> Self {
        Numerics {
            offset: Offset::ScaleAware,
            triangle: TriangleTest::MollerTrumbore,
            sphere: SphereTest::Stable,
        }
    }
}

impl Offset {
    pub const ALL: [Offset; 5] = [
        Offset::Ray,
        Offset::Normal,
        Offset::NormalScaled,
        Offset::Ulp,
        Offset::ScaleAware,
    ];
    fn define(self) -> &'static str {
        match self {
            Offset::Ray => "OFFSET_RAY",
            Offset::Normal => "OFFSET_NORMAL",
            Offset::NormalScaled => "OFFSET_NORMAL_SCALED",
            Offset::Ulp => "OFFSET_ULP",
            Offset::ScaleAware => "OFFSET_SCALE_AWARE",
        }
    }
}

impl TriangleTest {
    pub const ALL: [TriangleTest; 2] = [TriangleTest::MollerTrumbore, TriangleTest::Watertight];
    fn define(self) -> &'static str {
        match self {
            TriangleTest::MollerTrumbore => "TRIANGLE_MOLLER_TRUMBORE",
            TriangleTest::Watertight => "TRIANGLE_WATERTIGHT",
        }
    }
}

impl SphereTest {
    pub const ALL: [SphereTest; 2] = [SphereTest::Quadratic, SphereTest::Stable];
    fn define(self) -> &'static str {
        match self {
            SphereTest::Quadratic => "SPHERE_QUADRATIC",
            SphereTest::Stable => "SPHERE_STABLE",
        }
    }
}

/// Parses one of `names` (case-insensitive; `_` and `-` alike) or says which are allowed.
fn pick<T: Copy + ValueName>(key: &str, value: &str, all: &[T]) -> anyhow::Result<T> {
    let v = value.trim().to_ascii_lowercase().replace('_', "-");
    let v = match v.as_str() {
        "mt" | "moller" | "möller-trumbore" => "moller-trumbore".to_string(),
        "wbw" => "watertight".into(),
        "wachter-binder" => "ulp".into(),
        _ => v,
    };
    all.iter().copied().find(|t| t.name() == v).ok_or_else(|| {
        let names: Vec<String> = all.iter().map(ValueName::name).collect();
        bad_input(format!(
            "{key}: '{value}' is not one of {}",
            names.join(", ")
        ))
    })
}

impl Numerics {
    /// The keys shared by `[render]` in scene files and `--set`.
    pub const KEYS: [&'static str; 3] = ["offset", "triangle", "sphere"];

    /// Every configuration, the offset changing slowest and the sphere test fastest.
    pub fn all() -> impl Iterator<Item = Numerics> {
        Offset::ALL.into_iter().flat_map(|offset| {
            TriangleTest::ALL.into_iter().flat_map(move |triangle| {
                SphereTest::ALL.into_iter().map(move |sphere| Numerics {
                    offset,
                    triangle,
                    sphere,
                })
            })
        })
    }

    /// Applies `key = value` if `key` is one of `KEYS`; returns whether it was.
    /// `what` names the source in the error (e.g. `--set offset`).
    pub fn set(&mut self, key: &str, value: &str, what: &str) -> anyhow::Result<bool> {
        match key {
            "offset" => self.offset = pick(what, value, &Offset::ALL)?,
            "triangle" => self.triangle = pick(what, value, &TriangleTest::ALL)?,
            "sphere" => self.sphere = pick(what, value, &SphereTest::ALL)?,
            _ => return Ok(false),
        }
        Ok(true)
    }

    /// The shader defines of this configuration (one per choice).
    pub fn defines(&self) -> [&'static str; 3] {
        [
            self.offset.define(),
            self.triangle.define(),
            self.sphere.define(),
        ]
    }

    /// `normal-scaled/watertight/stable`.
    pub fn label(&self) -> String {
        format!(
            "{}/{}/{}",
            self.offset.name(),
            self.triangle.name(),
            self.sphere.name()
        )
    }

    /// The `--set` arguments that select this configuration.
    pub fn set_args(&self) -> Vec<String> {
        vec![
            format!("offset={}", self.offset.name()),
            format!("triangle={}", self.triangle.name()),
            format!("sphere={}", self.sphere.name()),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_names_and_refuse_others() {
        let mut n = Numerics::default();
        assert!(n.set("triangle", "MT", "--set triangle").unwrap());
        assert_eq!(n.triangle, TriangleTest::MollerTrumbore);
        assert!(n.set("offset", "normal_scaled", "--set offset").unwrap());
        assert_eq!(n.offset, Offset::NormalScaled);
        assert!(!n.set("max_depth", "3", "--set max_depth").unwrap());
        let e = n.set("sphere", "cubic", "--set sphere").unwrap_err();
        assert!(e.to_string().contains("quadratic, stable"), "{e}");
        assert_eq!(crate::error::exit_code_of(&e), 2);
    }

    #[test]
    fn labels_round_trip_through_set_args() {
        let n = Numerics {
            offset: Offset::Ulp,
            triangle: TriangleTest::MollerTrumbore,
            sphere: SphereTest::Quadratic,
        };
        let mut m = Numerics::default();
        for kv in n.set_args() {
            let (k, v) = kv.split_once('=').unwrap();
            m.set(k, v, k).unwrap();
        }
        assert_eq!(n, m);
    }
}
