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
/// Below it the brute-force loop is as fast or faster: see the comparison
/// report's acceleration section for the measurements behind the number.
pub const AUTO_BVH_MIN_PRIMITIVES: usize = 64;

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
    /// `auto` takes the 4-wide tree where spheres are at least half of the
    /// primitives and the binary tree otherwise: the crossover measured on the
    /// H100 (comparison/results/nvidia-h100/FINDINGS.md#where-the-4-wide-tree-pays-investigationcrossover).
    /// On sphere lists of 100 to 10,000 spheres the 4-wide tree is 15 to 27 %
    /// faster in Vulkan and 5 to 17 % in OpenGL (one point excepted: 10,000 at
    /// 1000² on OpenGL's compute path, 3 % slower); on triangle scenes (the
    /// teapot, the box) it is 4 to 11 % faster in Vulkan but 2 to 5 % slower in
    /// OpenGL. One rule for both APIs keeps the comparison honest: both trace
    /// the same tree.
    pub fn width(self, scene: &Scene) -> u32 {
        match self {
            Accel::Bvh4 => 4,
            Accel::Bvh8 => 8,
            Accel::Auto if 2 * scene.spheres.len() >= scene.primitive_count() => 4,
            Accel::Auto | Accel::None | Accel::Bvh => 2,
        }
    }
}

#[cfg(test)]
mod tests;
