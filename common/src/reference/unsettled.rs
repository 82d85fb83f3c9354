//! Which pixels f32 cannot settle: those whose f64 colour moves by more than
//! 8/255 when the primary ray turns by a few f32 ULPs. There the image is a
//! knife-edge (a pixel centre on a silhouette, a shadow edge or a total
//! internal reflection boundary, or a path whose bounces magnify any error a
//! millionfold), and no f32 tracer, however it is written, can be held to the
//! f64 colour. `twinray render --api reference --unsettled MASK.png` writes
//! the mask and `twinray diff --exclude MASK.png` leaves those pixels out, so
//! an accuracy target can state how many it excludes and hold the rest.

use super::{render_turned, Picture};
use crate::scene::numerics::Numerics;
use crate::scene::Scene;
use glam::DVec2;
use std::sync::atomic::AtomicUsize;

/// How far the primary ray turns, in radians: 4 f32 ULPs of a unit vector's
/// largest component (2^-22). Rounding the f64 direction to f32 alone moves
/// it by about half of one, a GPU's `normalize` by 2 to 3 (`twinray ulp`), and
/// each bounce's hit point and normal add their own.
pub const TURN: f64 = 1.0 / 4_194_304.0;

/// A pixel is unsettled where some turn changes a channel by more than this, in 1/255 steps.
pub const MOVES_BY: u8 = 8;

/// The unsettled pixels of `scene` at width × height with its own numerics
/// (the image `render` gives), row by row, top row first: true where turning
/// the primary ray by `TURN` right, left, down or up changes the colour by
/// more than `MOVES_BY`/255.
pub fn unsettled(scene: &Scene, width: u32, height: u32) -> Vec<bool> {
    unsettled_with(scene, width, height, &scene.numerics, TURN)
}

/// `unsettled` with the given numerics and turn.
pub fn unsettled_with(
    scene: &Scene,
    width: u32,
    height: u32,
    numerics: &Numerics,
    turn: f64,
) -> Vec<bool> {
    let picture = Picture {
        scene,
        width,
        height,
        numerics,
    };
    let draw = |by: DVec2| render_turned(&picture, Some(2), &AtomicUsize::new(0), by).to_rgb8();
    let base = draw(DVec2::ZERO);
    let mut mask = vec![false; base.pixels().len()];
    for by in [DVec2::X, -DVec2::X, DVec2::Y, -DVec2::Y] {
        let turned = draw(by * turn);
        for (m, (a, b)) in mask.iter_mut().zip(base.pixels().zip(turned.pixels())) {
            *m |= (0..3).any(|c| a[c].abs_diff(b[c]) > MOVES_BY);
        }
    }
    mask
}

/// The mask as a PNG's pixels: white where unsettled, black elsewhere.
pub fn mask_image(mask: &[bool], width: u32, height: u32) -> image::RgbImage {
    image::RgbImage::from_fn(width, height, |x, y| {
        let on = mask[(y * width + x) as usize];
        image::Rgb([if on { 255 } else { 0 }; 3])
    })
}

/// A mask read back from its PNG: a pixel is unsettled where any channel is
/// above half (so a mask drawn over with a paint program still reads).
pub fn mask_from_image(img: &image::RgbImage) -> Vec<bool> {
    img.pixels().map(|p| p.0.iter().any(|&c| c > 127)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Random scene 6's pixel (81, 108) at 160x120 looks into the mirror
    /// teapot's lid, whose reflection enters the pot between lid and body and
    /// bounces six times inside: rounding its primary direction to f32 alone
    /// turns it from 32/255 blue to 2/255 (lavapipe and llvmpipe render the
    /// latter, the f64 reference the former). The mask names it, and
    /// leaves the rest of the image alone.
    #[test]
    fn the_teapots_cavity_is_unsettled_and_little_else() {
        let scene = Scene::load("random:6", &[]).unwrap();
        let (w, h) = (160, 120);
        let mask = unsettled(&scene, w, h);
        assert!(mask[(108 * w + 81) as usize], "(81, 108) is not unsettled");
        let count = mask.iter().filter(|&&m| m).count();
        assert!(
            count * 1000 < (w * h) as usize,
            "{count} pixels unsettled: more than 0.1 %"
        );
    }

    /// No turn, no change: the mask of a zero turn is empty, so whatever it
    /// names comes from the turn, not from rendering twice.
    #[test]
    fn a_zero_turn_unsettles_nothing() {
        let scene = Scene::load("random:6", &[]).unwrap();
        let mask = unsettled_with(&scene, 40, 30, &scene.numerics, 0.0);
        assert!(mask.iter().all(|&m| !m));
    }
}
