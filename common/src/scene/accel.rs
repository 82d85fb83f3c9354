//! Acceleration: `--accel` and the scene's choice of a BVH; `build` makes the
//! bounding volume hierarchy itself (`gpu::layout::Bvh`), which
//! shaders/trace/bvh.glsl walks, and `split` its split of one node.

mod build;
mod split;

pub use split::MAX_LEAF;

use crate::gpu::layout::Bvh;
use crate::scene::camera::in_local_frame;
use crate::scene::{BvhCache, Scene};

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

impl Scene {
    /// The scene's BVH where it traces through one (built on first use, then
    /// kept). Primitives changed after that call would not be seen: scenes are
    /// not edited once loaded, except for `--accel` and the ray depth.
    pub fn bvh_tree(&self) -> Option<&Bvh> {
        self.bvh.then(|| {
            &**self
                .bvh_cache
                .0
                // Over the primitives as the GPU holds them: relative to the local origin.
                .get_or_init(|| {
                    let local = in_local_frame(self);
                    std::sync::Arc::new(Bvh::build(&local))
                })
        })
    }

    /// Applies `--accel` (none: brute force; bvh: a BVH; auto: a BVH from the threshold on).
    pub fn set_accel(&mut self, accel: Accel) {
        self.bvh_cache = BvhCache::default();
        self.bvh = match accel {
            Accel::None => false,
            Accel::Bvh => self.primitive_count() > 0,
            Accel::Auto => self.primitive_count() >= AUTO_BVH_MIN_PRIMITIVES,
        };
    }
}

#[cfg(test)]
mod tests;
