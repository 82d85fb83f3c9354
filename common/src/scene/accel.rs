//! Acceleration: `--accel` and the scene's choice of a BVH; `build` makes the
//! bounding volume hierarchy itself (`gpu::layout::Bvh`), which
//! shaders/trace/bvh.glsl walks, `split` its split of one node, and `wide`
//! collapses it into the 4- and 8-wide trees that shaders/trace/bvh.glsl walks too.

mod build;
mod split;
pub mod wide;

pub use split::MAX_LEAF;

use crate::scene::Scene;

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Accel {
    Auto,
    None,
    Bvh,
    Bvh4,
    Bvh8,
}

/// `--accel auto` builds a BVH for scenes with at least this many primitives.
/// On an H200 auto's 4-wide tree is faster from the fewest measured (8), in
/// both APIs and on both paths; on Mesa's llvmpipe brute force is as fast up
/// to about a dozen and the tree faster from 17 in three of the four app and
/// path pairs. So the box (32 primitives) takes the tree, a third of its
/// brute-force time on the GPU (docs/findings/bvh.md#where-the-bvh-starts-to-pay-h200;
/// `twinray sweep comparison/plans/auto-threshold.toml --out OUT`). It was 64,
/// from an older traversal.
pub const AUTO_BVH_MIN_PRIMITIVES: usize = 16;

impl Accel {
    /// Whether a run with this `--accel` traces `scene` through a BVH (none:
    /// brute force; bvh: a BVH; auto: a BVH from the threshold on).
    pub fn wants_bvh(self, scene: &Scene) -> bool {
        match self {
            Accel::None => false,
            Accel::Bvh | Accel::Bvh4 | Accel::Bvh8 => scene.primitive_count() > 0,
            Accel::Auto => scene.primitive_count() >= AUTO_BVH_MIN_PRIMITIVES,
        }
    }

    /// Children per node of the BVH this choice traces through `scene`.
    /// `auto` takes the 4-wide tree: it is the faster tree at every point
    /// measured on the H100 in both APIs. On the teapot at 1080p it is 23 %
    /// faster than the binary tree in Vulkan and 20 % in OpenGL, and past a
    /// million triangles about 10 % in Vulkan and 4 to 7 % in OpenGL
    /// (docs/findings/bvh.md#the-tree-auto-takes; data:
    /// f8d14ba:comparison/results/nvidia-h100/investigation/gl-gap/unrolled/).
    /// One rule for both APIs keeps the comparison honest: both trace the
    /// same tree; `--accel bvh` still gives the binary one.
    pub fn width(self) -> u32 {
        match self {
            Accel::Auto | Accel::Bvh4 => 4,
            Accel::Bvh8 => 8,
            Accel::None | Accel::Bvh => 2,
        }
    }
}

#[cfg(test)]
mod tests;
