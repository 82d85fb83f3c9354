//! Rays per pixel on a sparse grid of the image: what the compute path's
//! launch order (`plan::launch`) ranks the image's tiles by. The walk is the
//! reference image's, through the run's own tree, but only the rays are kept,
//! of one pixel in each `step`×`step` cell.

use super::intersect::Tracer;
use super::trace_with;
use crate::gpu::layout::Bvh;
use crate::rays::RayKinds;
use crate::scene::camera::{in_local_frame, RayFrame};
use crate::scene::Scene;
use rayon::prelude::*;

/// Cell (i, j) covers pixels [i·step, (i+1)·step) × [j·step, (j+1)·step);
/// `rays[j * cols + i]` are the rays of every kind that its centre pixel
/// (clamped into the image) traces.
pub struct RaySamples {
    pub step: u32,
    pub cols: u32,
    pub rows: u32,
    pub rays: Vec<u32>,
}

/// The samples of `scene` at width × height. `bvh` is the run's tree, built
/// over the local frame (`plan::build_bvh`); without one (a run by brute
/// force) the reference builds its own above a leaf's worth of primitives,
/// so that no estimate tests every triangle for every ray.
pub fn sampled_rays(
    scene: &Scene,
    bvh: Option<&Bvh>,
    (width, height): (u32, u32),
    step: u32,
) -> RaySamples {
    let frame = RayFrame::local(scene, &scene.camera, width, height);
    let local = in_local_frame(scene);
    let tracer = match bvh {
        Some(bvh) => Tracer::through(&local, bvh),
        None => Tracer::with_width(&local, 4),
    };
    let (cols, rows) = (width.div_ceil(step), height.div_ceil(step));
    let centre = |cell: u32, size: u32| (cell * step + step / 2).min(size - 1) as f64;
    let rays = (0..rows)
        .into_par_iter()
        .flat_map_iter(|j| {
            let tracer = &tracer;
            (0..cols).map(move |i| {
                let mut kinds = RayKinds::default();
                let dir = frame.dir(centre(i, width), centre(j, height));
                trace_with(tracer, frame.eye, dir, &mut kinds, &mut |_| {});
                kinds.total().min(u32::MAX as u64) as u32
            })
        })
        .collect();
    RaySamples {
        step,
        cols,
        rows,
        rays,
    }
}

/// Whether the ray from `o` along `d` enters the box, by the reference's own
/// (padded) test of a node's box: the launch order's test of a tile's rays.
pub(crate) fn ray_enters(min: [f32; 3], max: [f32; 3], o: glam::DVec3, d: glam::DVec3) -> bool {
    super::intersect::enter_box(min, max, o, d, f64::INFINITY).is_some()
}

/// Whether the ray from `o` along `d` hits anything in `scene` (in its local
/// frame), by brute force: what the launch order's empty tiles are held to.
#[cfg(test)]
pub(crate) fn hits_by_brute_force(scene: &Scene, o: glam::DVec3, d: glam::DVec3) -> bool {
    super::intersect::closest_hit(&Tracer::brute_force(scene), o, d).is_some()
}
