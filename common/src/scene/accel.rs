//! Acceleration: `--accel` and the scene's choice of a BVH; `build` makes the
//! bounding volume hierarchy itself (`gpu::layout::Bvh`), which
//! shaders/trace/bvh.glsl walks, and `split` its split of one node.

mod build;
mod split;

pub use split::MAX_LEAF;

use crate::scene::Scene;

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Accel {
    Auto,
    None,
    Bvh,
}

/// `--accel auto` builds a BVH for scenes with at least this many primitives.
/// Below it the brute-force loop is as fast or faster: see the comparison
/// report's acceleration section for the measurements behind the number.
pub const AUTO_BVH_MIN_PRIMITIVES: usize = 64;

impl Accel {
    /// Whether a run with this `--accel` traces `scene` through a BVH (none:
    /// brute force; bvh: a BVH; auto: a BVH from the threshold on).
    pub fn wants_bvh(self, scene: &Scene) -> bool {
        match self {
            Accel::None => false,
            Accel::Bvh => scene.primitive_count() > 0,
            Accel::Auto => scene.primitive_count() >= AUTO_BVH_MIN_PRIMITIVES,
        }
    }
}

#[cfg(test)]
mod tests;
