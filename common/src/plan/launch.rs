//! The compute path's launch order: which tile of the image each workgroup
//! traces. A GPU starts workgroups in about the order of their index, and a
//! frame ends when its slowest last ones do, on an otherwise idle GPU; so the
//! costliest tiles are handed out first, the cheapest last. A tile's cost is
//! the most rays of the reference's samples in or beside it, then the sum of
//! those in it (`reference::sampled`), traced through the run's own tree. Which tile a
//! workgroup takes never changes what a pixel computes, so every image is the
//! same in any order; `--experiment row-order` hands the tiles out in rows,
//! top-down, as the dispatch numbers them, with no order at all.
//!
//! The buffer (binding 8, read by shaders/trace.comp) holds the tiles in
//! launch order, each `y * across + x`; the frame's uniform names the grid it
//! was made for (`GpuFrame::launch_grid`). A frame without one (a window,
//! whose camera moves) or of another grid takes the tiles in rows.

use crate::cli::Workgroup;
use crate::gpu::layout::Bvh;
use crate::reference::sampled::{sampled_rays, RaySamples};
use crate::scene::Scene;
use std::cmp::Reverse;

/// The most pixels that trace their rays for the estimate: every pixel of a
/// frame up to 362², then one in 4, 16 (1000², 1080p), 64 (4K) and so on.
/// On an H200 host's 16 cores that added 10-160 ms to a 1000², 1080p or 4K
/// start; one in four pixels, or every pixel, ranked no better
/// (`docs/findings/frame-end.md`).
pub const MOST_SAMPLES: u32 = 1 << 17;

/// A frame of fewer tiles keeps its rows: a large GPU holds all their
/// workgroups at once, so none is launched last (the H200: 132
/// multiprocessors, each holding several workgroups of the tracer), and
/// reading the order only delays each workgroup's first ray.
pub const FEWEST_TILES: u32 = 4096;

/// The side of the square of pixels of which one is sampled at `size`: a
/// power of two, so that the workgroups' sides (4, 8, 16) hold whole cells.
pub fn sample_step((width, height): (u32, u32)) -> u32 {
    let mut step = 1;
    while width.div_ceil(step) as u64 * height.div_ceil(step) as u64 > MOST_SAMPLES as u64 {
        step *= 2;
    }
    step
}

/// Whether a frame of `size` in workgroups of `workgroup` takes an order.
pub fn worth_ordering(size: (u32, u32), workgroup: Workgroup) -> bool {
    let (across, down) = workgroup.tiles(size);
    across as u64 * down as u64 >= FEWEST_TILES as u64
}

/// A frame's tiles in the order its workgroups take them.
pub struct LaunchOrder {
    /// Tiles across and down.
    pub grid: (u32, u32),
    /// Each a tile's index, `y * grid.0 + x`.
    pub tiles: Vec<u32>,
}

/// The tiles of `scene` at `size` in workgroups of `workgroup`, costliest first.
pub fn launch_order(
    scene: &Scene,
    bvh: Option<&Bvh>,
    size: (u32, u32),
    workgroup: Workgroup,
) -> LaunchOrder {
    let grid = workgroup.tiles(size);
    let mut tiles: Vec<u32> = (0..grid.0 * grid.1).collect();
    let samples = sampled_rays(scene, bvh, size, sample_step(size));
    let cost: Vec<(u32, u32)> = tiles
        .iter()
        .map(|&t| tile_cost(&samples, (t % grid.0, t / grid.0), workgroup))
        .collect();
    // Stable: tiles of equal cost keep their rows, and their neighbours
    // their share of the caches.
    tiles.sort_by_key(|&t| Reverse(cost[t as usize]));
    LaunchOrder { grid, tiles }
}

/// The most rays of one sample in or beside the tile at `(tx, ty)`, then
/// the sum of those in it: a warp lasts as long as its longest pixel, and
/// among tiles whose longest pixels match, the fuller one runs longer. The
/// cells beside the tile count for the most because a sample stands for
/// pixels it did not trace: a tile that only grazes the teapot's edge, or a
/// shadow's, is costly though its own samples missed, and one launched last
/// would hold up the frame.
fn tile_cost(s: &RaySamples, (tx, ty): (u32, u32), wg: Workgroup) -> (u32, u32) {
    // The cells the tile overlaps, and with `pad` more on each side.
    let cells = |t: u32, w: u32, n: u32, pad: u32| {
        let first = (t * w / s.step).min(n - 1);
        let last = (((t + 1) * w - 1) / s.step).min(n - 1);
        first.saturating_sub(pad)..=(last + pad).min(n - 1)
    };
    let ray = |i: u32, j: u32| s.rays[(j * s.cols + i) as usize];
    let mut most = 0;
    for j in cells(ty, wg.y, s.rows, 1) {
        for i in cells(tx, wg.x, s.cols, 1) {
            most = most.max(ray(i, j));
        }
    }
    let mut sum = 0u32;
    for j in cells(ty, wg.y, s.rows, 0) {
        for i in cells(tx, wg.x, s.cols, 0) {
            sum = sum.saturating_add(ray(i, j));
        }
    }
    (most, sum)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn order(scene: &str, size: (u32, u32), wg: (u32, u32)) -> LaunchOrder {
        let scene = Scene::load(scene, &[]).unwrap();
        let bvh = crate::plan::build_bvh(&scene).widen(4);
        launch_order(&scene, Some(&bvh), size, Workgroup { x: wg.0, y: wg.1 })
    }

    #[test]
    fn every_tile_is_launched_once_at_any_size_and_workgroup() {
        for (size, wg) in [
            ((64, 48), (8, 16)),
            ((67, 45), (4, 8)),
            ((33, 7), (8, 4)),
            ((50, 30), (3, 5)),
            ((1, 1), (8, 16)),
        ] {
            for scene in ["teapot", "box"] {
                let order = order(scene, size, wg);
                let grid = (size.0.div_ceil(wg.0), size.1.div_ceil(wg.1));
                assert_eq!(order.grid, grid);
                let mut tiles = order.tiles;
                tiles.sort_unstable();
                let all: Vec<u32> = (0..grid.0 * grid.1).collect();
                assert_eq!(tiles, all, "{scene}, {size:?} in {wg:?}");
            }
        }
    }

    /// The teapot's tiles that miss it (one ray each) go last, and the first
    /// tile launched holds a pixel with the most rays of any sample.
    #[test]
    fn the_costliest_tiles_go_first() {
        let scene = Scene::load("teapot", &[]).unwrap();
        let bvh = crate::plan::build_bvh(&scene).widen(4);
        let (size, wg) = ((96, 72), Workgroup { x: 8, y: 4 });
        let order = launch_order(&scene, Some(&bvh), size, wg);
        let samples = sampled_rays(&scene, Some(&bvh), size, sample_step(size));
        let most = *samples.rays.iter().max().unwrap();
        assert!(most > 1, "the teapot casts shadow rays");
        let grid_x = order.grid.0;
        let costs: Vec<(u32, u32)> = order
            .tiles
            .iter()
            .map(|&t| tile_cost(&samples, (t % grid_x, t / grid_x), wg))
            .collect();
        assert_eq!(costs[0].0, most);
        assert!(
            costs.windows(2).all(|w| w[0] >= w[1]),
            "not costliest first"
        );
        assert_eq!(costs.last().unwrap().0, 1, "the background's tiles last");
    }

    /// The sphere lists' 300² frames fit on an H200 at once (722 workgroups of
    /// 8×16, 2,850 of 4×8) and keep their rows; 1000² and larger are ordered.
    #[test]
    fn only_frames_of_many_tiles_take_an_order() {
        let wg = |x, y| Workgroup { x, y };
        assert!(!worth_ordering((300, 300), wg(8, 16)));
        assert!(!worth_ordering((300, 300), wg(4, 8)));
        assert!(worth_ordering((1000, 1000), wg(8, 16)));
        assert!(worth_ordering((1920, 1080), wg(4, 8)));
        assert_eq!(sample_step((300, 300)), 1);
        assert_eq!(sample_step((1920, 1080)), 4);
        assert_eq!(sample_step((3840, 2160)), 8);
    }
}
