//! Image error metrics between two renders of the same scene: RMSE, PSNR, the
//! largest channel difference, the share of pixels off by more than 1/255 and
//! 8/255, and how many pixels were NaN/Inf before quantisation.

use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq)]
pub struct Metrics {
    pub width: u32,
    pub height: u32,
    /// Root-mean-square channel error, on a 0..1 scale.
    pub rmse: f64,
    /// Peak signal-to-noise ratio in dB (infinite for identical images).
    pub psnr_db: f64,
    /// Largest absolute channel difference, in 1/255 steps.
    pub max_abs: u8,
    /// Share of pixels whose largest channel difference exceeds 1/255.
    pub above_1: f64,
    /// Share of pixels whose largest channel difference exceeds 8/255.
    pub above_8: f64,
    /// NaN/Inf pixels seen before quantisation (from the apps' JSON; 0 for PNG-only diffs).
    pub nan_pixels: u64,
}

impl Metrics {
    /// Share of pixels within 1/255 on every channel.
    pub fn within_1(&self) -> f64 {
        1.0 - self.above_1
    }
}

/// Compares two 8-bit RGB images of the same size.
pub fn compare(a: &image::RgbImage, b: &image::RgbImage) -> anyhow::Result<Metrics> {
    compare_outside(a, b, &[])
}

/// `compare` over the pixels `left_out` does not name (row by row, top row
/// first; empty: none left out): the shares are of the pixels compared.
pub fn compare_outside(
    a: &image::RgbImage,
    b: &image::RgbImage,
    left_out: &[bool],
) -> anyhow::Result<Metrics> {
    if a.dimensions() != b.dimensions() {
        return Err(crate::error::bad_input(format!(
            "the images differ in size ({}x{} vs {}x{})",
            a.width(),
            a.height(),
            b.width(),
            b.height()
        )));
    }
    let skip = |i: usize| left_out.get(i).copied().unwrap_or(false);
    let (mut sq, mut max_abs, mut above_1, mut above_8) = (0.0f64, 0u8, 0usize, 0usize);
    let mut n = 0usize;
    for (i, (pa, pb)) in a.pixels().zip(b.pixels()).enumerate() {
        if skip(i) {
            continue;
        }
        n += 1;
        let mut worst = 0u8;
        for c in 0..3 {
            let d = pa[c].abs_diff(pb[c]);
            worst = worst.max(d);
            sq += (d as f64 / 255.0).powi(2);
        }
        max_abs = max_abs.max(worst);
        above_1 += (worst > 1) as usize;
        above_8 += (worst > 8) as usize;
    }
    // Nothing compared is no evidence of a match: an RMSE of 0 over no pixels
    // read as a perfect one.
    if n == 0 {
        return Err(crate::error::bad_input(
            "the mask leaves out every pixel: nothing is left to compare",
        ));
    }
    let rmse = (sq / (n * 3) as f64).sqrt();
    let psnr_db = if rmse == 0.0 {
        f64::INFINITY
    } else {
        -20.0 * rmse.log10()
    };
    Ok(Metrics {
        width: a.width(),
        height: a.height(),
        rmse,
        psnr_db,
        max_abs,
        above_1: above_1 as f64 / n as f64,
        above_8: above_8 as f64 / n as f64,
        nan_pixels: 0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_and_known_difference() {
        let a = image::RgbImage::from_pixel(10, 10, image::Rgb([100, 100, 100]));
        let m = compare(&a, &a).unwrap();
        assert_eq!(m.rmse, 0.0);
        assert!(m.psnr_db.is_infinite());
        let mut b = a.clone();
        b.put_pixel(0, 0, image::Rgb([102, 100, 100]));
        b.put_pixel(1, 0, image::Rgb([100, 110, 100]));
        b.put_pixel(2, 0, image::Rgb([101, 100, 100]));
        let m = compare(&a, &b).unwrap();
        assert_eq!(m.max_abs, 10);
        assert!((m.above_1 - 0.02).abs() < 1e-12);
        assert!((m.above_8 - 0.01).abs() < 1e-12);
        assert!((m.within_1() - 0.98).abs() < 1e-12);
    }

    #[test]
    fn pixels_left_out_are_not_compared() {
        let a = image::RgbImage::from_pixel(10, 10, image::Rgb([100, 100, 100]));
        let mut b = a.clone();
        b.put_pixel(3, 0, image::Rgb([200, 100, 100]));
        b.put_pixel(4, 0, image::Rgb([102, 100, 100]));
        let mut left_out = vec![false; 100];
        left_out[3] = true;
        let m = compare_outside(&a, &b, &left_out).unwrap();
        assert_eq!(m.max_abs, 2);
        assert!((m.above_1 - 1.0 / 99.0).abs() < 1e-12);
        assert_eq!(m.above_8, 0.0);
        assert_eq!(compare(&a, &b).unwrap().max_abs, 100);
        let e = compare_outside(&a, &b, &[true; 100]).unwrap_err();
        assert_eq!(crate::error::exit_code_of(&e), 2, "{e}");
    }

    #[test]
    fn size_mismatch_is_bad_input() {
        let a = image::RgbImage::new(2, 2);
        let b = image::RgbImage::new(3, 2);
        let e = compare(&a, &b).unwrap_err();
        assert_eq!(crate::error::exit_code_of(&e), 2);
    }
}
