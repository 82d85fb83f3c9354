//! Float images (what the tracer writes before quantisation), their conversion
//! to 8-bit PNG — identical for both APIs and the reference — PNG loading, and
//! the one way every output file is written: checked before the render, encoded
//! in memory, written beside the target, synced and renamed, so that a failed
//! write never leaves a truncated or empty file behind.

use crate::error::bad_input;
use image::ImageEncoder as _;
use std::io::Write;
use std::path::{Path, PathBuf};

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
        assert_eq!(
            Some(rgba.len()),
            crate::limits::pixel_count(width, height).checked_mul(4),
            "readback size"
        );
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

    /// Saves as PNG; errors name the file.
    pub fn save_png(&self, path: &Path) -> anyhow::Result<()> {
        save_png(&self.to_rgb8(), path)
    }

    /// Saves as PNG; errors name `option` (`--out`) and the file.
    pub fn save_png_for(&self, option: &str, path: &Path) -> anyhow::Result<()> {
        write_png(&self.to_rgb8(), option, path)
    }
}

pub fn quantize(c: f32) -> u8 {
    if c.is_nan() {
        0
    } else {
        (c.clamp(0.0, 1.0) * 255.0).round() as u8
    }
}

/// Saves an 8-bit image as PNG (see `write_png`); errors name the file.
pub fn save_png(img: &image::RgbImage, path: &Path) -> anyhow::Result<()> {
    write_png(img, "image", path)
}

/// Encodes `img` in memory, then writes it atomically (`write_file`). Every
/// failure is bad input (exit 2) naming `option` and the path, and leaves no file.
pub fn write_png(img: &image::RgbImage, option: &str, path: &Path) -> anyhow::Result<()> {
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(
            img.as_raw(),
            img.width(),
            img.height(),
            image::ExtendedColorType::Rgb8,
        )
        .map_err(|e| {
            bad_input(format!(
                "{option} '{}': PNG encoding failed: {e}",
                path.display()
            ))
        })?;
    write_file(option, path, &png)
}

/// Writes `bytes` to `path` so that the file is either complete or absent: a
/// temporary file in the same folder, written, flushed and synced, then renamed
/// over the target (atomic on one file system). `option` names the option the
/// path came from in the error. Errors are bad input (exit 2): the user chose the
/// place, and on a full or read-only disk only the user can choose another.
pub fn write_file(option: &str, path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    let target = check_output_file(option, path)?;
    let fail = |what: &str, e: std::io::Error| {
        bad_input(format!(
            "{option} '{}': {what} failed ({e}); no file was written",
            path.display()
        ))
    };
    let tmp = temp_beside(&target);
    let result = (|| {
        let mut f = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)
            .map_err(|e| fail("creating a temporary file beside it", e))?;
        f.write_all(bytes).map_err(|e| fail("writing", e))?;
        f.flush().map_err(|e| fail("flushing", e))?;
        f.sync_all().map_err(|e| fail("syncing to disk", e))?;
        drop(f);
        std::fs::rename(&tmp, &target).map_err(|e| fail("renaming the temporary file", e))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    } else if let Some(dir) = target.parent() {
        // The rename itself is durable only once the folder is synced; a failure
        // here loses nothing that is not already in place.
        if let Ok(d) = std::fs::File::open(dir) {
            let _ = d.sync_all();
        }
    }
    result
}

/// A hidden name in the target's folder, unique to this process and write.
fn temp_beside(target: &Path) -> PathBuf {
    use std::sync::atomic::{AtomicU32, Ordering};
    static N: AtomicU32 = AtomicU32::new(0);
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    let n = N.fetch_add(1, Ordering::Relaxed);
    target.with_file_name(format!(".{name}.{}.{n}.tmp", std::process::id()))
}

/// Checks, before any work is spent, that a file can be written at `path`: it is
/// not a folder or a device, its folder exists and is writable. Returns the path
/// to write (a symbolic link's target, so the link survives the rename).
/// `option` names where the path came from (`--out`, `--heatmap`).
pub fn check_output_file(option: &str, path: &Path) -> anyhow::Result<PathBuf> {
    let shown = path.display();
    if path.as_os_str().is_empty() {
        return Err(bad_input(format!("{option} is empty; give a file name")));
    }
    let target = match std::fs::metadata(path) {
        Ok(meta) if meta.is_dir() => {
            return Err(bad_input(format!(
                "{option} '{shown}' is a folder; give a file name such as '{}'",
                path.join("image.png").display()
            )))
        }
        Ok(meta) if !meta.is_file() => {
            return Err(bad_input(format!(
            "{option} '{shown}' is not a regular file (a device, pipe or socket); give a file name"
        )))
        }
        Ok(_) => std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf()),
        Err(_) => path.to_path_buf(),
    };
    if target.file_name().is_none() {
        return Err(bad_input(format!(
            "{option} '{shown}' names no file; give a file name"
        )));
    }
    let dir = match target.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(d) => d.to_path_buf(),
        None => PathBuf::from("."),
    };
    check_writable_dir(option, &shown.to_string(), &dir)?;
    Ok(target)
}

/// Checks (and creates, like `mkdir -p`) an output folder for reports (`compare
/// --out`, `accuracy --out`), before any work is spent.
pub fn prepare_output_dir(option: &str, dir: &Path) -> anyhow::Result<()> {
    let shown = dir.display();
    if dir.exists() && !dir.is_dir() {
        return Err(bad_input(format!(
            "{option} '{shown}' exists and is not a folder"
        )));
    }
    std::fs::create_dir_all(dir).map_err(|e| {
        bad_input(format!(
            "{option} '{shown}': the folder cannot be created ({e})"
        ))
    })?;
    check_writable_dir(option, &shown.to_string(), dir)
}

/// Proves that `dir` exists and accepts a new file by creating and removing one
/// (permission bits alone miss read-only mounts and ACLs).
fn check_writable_dir(option: &str, shown: &str, dir: &Path) -> anyhow::Result<()> {
    if !dir.is_dir() {
        return Err(bad_input(format!(
            "{option} '{shown}': folder '{}' does not exist",
            dir.display()
        )));
    }
    let probe = temp_beside(&dir.join("probe"));
    match std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
    {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) => Err(bad_input(format!(
            "{option} '{shown}': folder '{}' is not writable ({e})",
            dir.display()
        ))),
    }
}

pub fn load_png(path: &Path) -> anyhow::Result<image::RgbImage> {
    if std::fs::metadata(path).is_ok_and(|m| !m.is_file()) {
        return Err(bad_input(format!(
            "image '{}' is not a regular file",
            path.display()
        )));
    }
    let img = image::open(path).map_err(|e| {
        bad_input(format!(
            "image '{}' cannot be read as PNG: {e}",
            path.display()
        ))
    })?;
    Ok(img.to_rgb8())
}
