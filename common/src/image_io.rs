//! Float images (what the tracer writes before quantisation), their conversion
//! to 8-bit PNG — identical for both APIs and the reference — and PNG loading.

use crate::error::bad_input;
use anyhow::Context;
use std::path::Path;

/// Linear RGB, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct FloatImage {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 3]>,
}

impl FloatImage {
    /// From RGBA32F rows as read back from the GPU (alpha dropped).
    pub fn from_rgba(width: u32, height: u32, rgba: &[f32]) -> FloatImage {
        assert_eq!(rgba.len(), (width * height * 4) as usize, "readback size");
        FloatImage {
            width,
            height,
            pixels: rgba.chunks_exact(4).map(|p| [p[0], p[1], p[2]]).collect(),
        }
    }

    /// Reverses the row order: for a readback that came bottom row first.
    pub fn flip_rows(mut self) -> FloatImage {
        let w = self.width as usize;
        let rows: Vec<Vec<[f32; 3]>> = self
            .pixels
            .chunks_exact(w)
            .rev()
            .map(<[_]>::to_vec)
            .collect();
        self.pixels = rows.concat();
        self
    }

    /// Pixels with any NaN or infinite channel.
    pub fn nonfinite_pixels(&self) -> u64 {
        self.pixels
            .iter()
            .filter(|p| p.iter().any(|c| !c.is_finite()))
            .count() as u64
    }

    /// Clamp to [0, 1] and round to 8 bits; NaN becomes 0.
    pub fn to_rgb8(&self) -> image::RgbImage {
        let mut raw = Vec::with_capacity(self.pixels.len() * 3);
        for p in &self.pixels {
            for &c in p {
                raw.push(quantize(c));
            }
        }
        image::RgbImage::from_raw(self.width, self.height, raw).expect("buffer matches size")
    }

    pub fn save_png(&self, path: &Path) -> anyhow::Result<()> {
        save_png(&self.to_rgb8(), path)
    }
}

pub fn quantize(c: f32) -> u8 {
    if c.is_nan() {
        0
    } else {
        (c.clamp(0.0, 1.0) * 255.0).round() as u8
    }
}

pub fn save_png(img: &image::RgbImage, path: &Path) -> anyhow::Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        if !dir.is_dir() {
            return Err(bad_input(format!(
                "--out '{}': folder '{}' does not exist",
                path.display(),
                dir.display()
            )));
        }
    }
    img.save_with_format(path, image::ImageFormat::Png)
        .with_context(|| format!("writing PNG '{}'", path.display()))
}

pub fn load_png(path: &Path) -> anyhow::Result<image::RgbImage> {
    let img = image::open(path).map_err(|e| {
        bad_input(format!(
            "image '{}' cannot be read as PNG: {e}",
            path.display()
        ))
    })?;
    Ok(img.to_rgb8())
}
