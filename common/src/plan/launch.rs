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
//!
//! The order also marks the tiles that cannot see the scene (`EMPTY_TILE`):
//! their workgroups store the background without a walk. That is what a walk
//! would return for each of their pixels, so no image changes.

use crate::cli::Workgroup;
use crate::gpu::layout::{Bounds, Bvh};
use crate::reference::sampled::{ray_enters, sampled_rays, RaySamples};
use crate::scene::camera::RayFrame;
use crate::scene::Scene;
use glam::DVec3;
use rayon::prelude::*;
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

/// A tile's flag in the launch order (shaders/trace.comp's EMPTY_TILE): the
/// primary ray of every pixel in it misses every box of the tree's root's
/// children, so each of its pixels is the background. A walk would find that
/// after one node step, and at 4K the teapot's rays miss it for five pixels
/// in six. Storing it without the walk took the H200's 4K teapot frame 5 %
/// (Vulkan) and 2 % (OpenGL) shorter, the box's 1080p one 8 % in Vulkan
/// (docs/findings/rays-per-second.md#tiles-that-see-nothing-h200).
pub const EMPTY_TILE: u32 = 1 << 31;

/// How far past a root child's box a ray must pass to count as missing it:
/// this share of the box's size plus its farthest corner's distance from the
/// eye. The GPU's ray is the f32 rounding of the reference's (a few parts in
/// 10^7 of that distance), and its tests are conservative; the margin is a
/// hundred times that, so a tile marked empty is empty on the GPU too.
const MISS_MARGIN: f64 = 1e-4;

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
    // A grid of 2^31 tiles or more (never, at the sizes the limits allow with
    // the workgroups used) would need the flag's bit for its indices.
    if let Some(bvh) = bvh.filter(|_| grid.0 as u64 * grid.1 as u64 <= EMPTY_TILE as u64) {
        let empty = empty_tiles(scene, bvh, size, workgroup, grid);
        for t in &mut tiles {
            if empty[*t as usize] {
                *t |= EMPTY_TILE;
            }
        }
    }
    LaunchOrder { grid, tiles }
}

/// For each tile, whether the primary ray of each of its pixels (in the image)
/// misses every box of `bvh`'s root's children: rays through the pixels'
/// centres, as the shader's and the reference's are.
fn empty_tiles(
    scene: &Scene,
    bvh: &Bvh,
    (width, height): (u32, u32),
    wg: Workgroup,
    (across, down): (u32, u32),
) -> Vec<bool> {
    let frame = RayFrame::local(scene, &scene.camera, width, height);
    let root: Vec<Bounds> = if bvh.width > 2 {
        bvh.wide_children(0).map(|(b, _)| b).collect()
    } else {
        bvh.nodes
            .first()
            .map(|n| vec![(n.left_min, n.left_max), (n.right_min, n.right_max)])
            .unwrap_or_default()
    };
    // Each box widened by the margin and rounded outwards to f32 again.
    let boxes: Vec<Bounds> = root
        .iter()
        .map(|&(lo, hi)| {
            let (lo, hi) = (
                DVec3::from(lo.map(f64::from)),
                DVec3::from(hi.map(f64::from)),
            );
            let far = (lo - frame.eye).abs().max((hi - frame.eye).abs()).length();
            let m = MISS_MARGIN * ((hi - lo).max_element() + far);
            (
                (lo - m).to_array().map(|v| (v as f32).next_down()),
                (hi + m).to_array().map(|v| (v as f32).next_up()),
            )
        })
        .collect();
    let misses = |x: u32, y: u32| {
        let d = frame.dir(x as f64, y as f64);
        !boxes
            .iter()
            .any(|&(lo, hi)| ray_enters(lo, hi, frame.eye, d))
    };
    (0..across * down)
        .into_par_iter()
        .map(|t| {
            let (tx, ty) = (t % across, t / across);
            let xs = tx * wg.x..((tx + 1) * wg.x).min(width);
            (ty * wg.y..((ty + 1) * wg.y).min(height)).all(|y| xs.clone().all(|x| misses(x, y)))
        })
        .collect()
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
                let mut tiles: Vec<u32> = order.tiles.iter().map(|t| t & !EMPTY_TILE).collect();
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
            .map(|&t| t & !EMPTY_TILE)
            .map(|t| tile_cost(&samples, (t % grid_x, t / grid_x), wg))
            .collect();
        assert_eq!(costs[0].0, most);
        assert!(
            costs.windows(2).all(|w| w[0] >= w[1]),
            "not costliest first"
        );
        assert_eq!(costs.last().unwrap().0, 1, "the background's tiles last");
    }

    /// A tile is flagged empty only where brute force finds nothing for the
    /// primary ray of any of its pixels, in every study scene and through
    /// either tree; the teapot's and the box's frames have such tiles.
    #[test]
    fn a_tile_is_empty_only_where_brute_force_sees_nothing() {
        let (size, wg) = ((120, 90), Workgroup { x: 4, y: 4 });
        for scene_name in ["teapot", "box", "spherelist"] {
            let scene = Scene::load(scene_name, &[]).unwrap();
            let local = crate::scene::camera::in_local_frame(&scene);
            let frame = RayFrame::local(&scene, &scene.camera, size.0, size.1);
            for width in [2, 4] {
                let bvh = crate::plan::build_bvh(&scene).widen(width);
                let order = launch_order(&scene, Some(&bvh), size, wg);
                let empty: Vec<u32> = order
                    .tiles
                    .iter()
                    .filter(|&&t| t & EMPTY_TILE != 0)
                    .map(|t| t & !EMPTY_TILE)
                    .collect();
                if scene_name != "spherelist" {
                    assert!(
                        empty.len() > 50,
                        "{scene_name}, width {width}: {} empty tiles",
                        empty.len()
                    );
                }
                for t in empty {
                    let (tx, ty) = (t % order.grid.0, t / order.grid.0);
                    for y in ty * wg.y..((ty + 1) * wg.y).min(size.1) {
                        for x in tx * wg.x..((tx + 1) * wg.x).min(size.0) {
                            let d = frame.dir(x as f64, y as f64);
                            assert!(
                                !crate::reference::sampled::hits_by_brute_force(&local, frame.eye, d),
                                "{scene_name}, width {width}: pixel ({x}, {y}) of empty tile {t} sees the scene"
                            );
                        }
                    }
                }
            }
        }
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
