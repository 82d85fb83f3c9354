//! Rays counted by kind: what the counting variant (COUNT_RAYS) and the f64
//! reference count, the `rays` object of `--json`, and Grays/s. The counts
//! come from one untimed frame; the rate divides them by the timed frames'
//! median.

use crate::gpu::layout::GpuRayCount;
use serde::{Deserialize, Serialize};

/// A frame's rays by the kind the tracer gave them.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RayKinds {
    pub primary: u64,
    /// Each shadow query traced (a light facing the surface).
    pub shadow: u64,
    /// Reflected from a surface that is not glass.
    pub mirror: u64,
    pub glass_reflected: u64,
    pub glass_refracted: u64,
}

impl RayKinds {
    /// Adds up the counting frame's per-pixel slots.
    pub fn from_pixels(pixels: &[GpuRayCount]) -> RayKinds {
        pixels.iter().fold(RayKinds::default(), |sum, p| {
            sum + RayKinds {
                primary: p.primary.into(),
                shadow: p.shadow.into(),
                mirror: p.mirror.into(),
                glass_reflected: p.glass_reflected.into(),
                glass_refracted: p.glass_refracted.into(),
            }
        })
    }

    pub fn secondary(&self) -> u64 {
        self.mirror + self.glass_reflected + self.glass_refracted
    }

    pub fn total(&self) -> u64 {
        self.primary + self.shadow + self.secondary()
    }

    /// As `--json` reports them.
    pub fn counts(&self) -> RayCounts {
        RayCounts {
            primary: self.primary,
            shadow: self.shadow,
            secondary: self.secondary(),
            total: self.total(),
            mirror: self.mirror,
            glass_reflected: self.glass_reflected,
            glass_refracted: self.glass_refracted,
        }
    }
}

/// One line for `--explain`: the total, then each kind.
impl std::fmt::Display for RayKinds {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(
            f,
            "{} rays: {} primary, {} shadow, {} mirror, {} glass reflected, {} glass refracted",
            self.total(),
            self.primary,
            self.shadow,
            self.mirror,
            self.glass_reflected,
            self.glass_refracted
        )
    }
}

impl std::ops::Add for RayKinds {
    type Output = RayKinds;
    fn add(self, o: RayKinds) -> RayKinds {
        RayKinds {
            primary: self.primary + o.primary,
            shadow: self.shadow + o.shadow,
            mirror: self.mirror + o.mirror,
            glass_reflected: self.glass_reflected + o.glass_reflected,
            glass_refracted: self.glass_refracted + o.glass_refracted,
        }
    }
}

/// `--json`'s `rays`: the four figures first (secondary = mirror +
/// glass reflected + glass refracted; total = all of them), then the
/// secondary rays' split.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct RayCounts {
    pub primary: u64,
    pub shadow: u64,
    pub secondary: u64,
    pub total: u64,
    pub mirror: u64,
    pub glass_reflected: u64,
    pub glass_refracted: u64,
}

/// Which frame time `grays_per_s` divides by: the GPU's own timer where the
/// run has one, else the wall clock around submit and wait.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RateClock {
    Gpu,
    Wall,
}

/// Billions of rays per second: `total` rays in `ms` milliseconds.
pub fn grays_per_s(total: u64, ms: f64) -> f64 {
    total as f64 / (ms * 1e-3) / 1e9
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixels_add_up_by_kind() {
        let px = GpuRayCount {
            primary: 1,
            shadow: 2,
            mirror: 3,
            glass_reflected: 4,
            glass_refracted: 5,
        };
        let k = RayKinds::from_pixels(&[px, px]);
        assert_eq!(
            k.counts(),
            RayCounts {
                primary: 2,
                shadow: 4,
                secondary: 24,
                total: 30,
                mirror: 6,
                glass_reflected: 8,
                glass_refracted: 10,
            }
        );
        assert!((grays_per_s(2_000_000_000, 1000.0) - 2.0).abs() < 1e-12);
    }
}
