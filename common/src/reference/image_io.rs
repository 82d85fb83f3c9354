//! Float images (what the tracer writes before quantisation), their conversion
//! to 8-bit PNG — identical for both APIs and the reference — PNG loading, and
//! the one way every output file is written: checked before the render, encoded
//! in memory, written beside the target under a recognisable temporary name,
//! synced and renamed, so that a failed write never leaves a truncated or empty
//! file behind and an interrupted one leaves a name the next write removes.

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
///
/// An existing target keeps its permission bits. Its other hard links, if it
/// has any, keep the previous contents: the rename gives the name a new file,
/// and writing in place to keep the links would give up the promise that a
/// failed write leaves the old image whole.
pub fn write_file(option: &str, path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    let target = check_output_file(option, path)?;
    let fail = |what: &str, e: std::io::Error| {
        bad_input(format!(
            "{option} '{}': {what} failed ({e}); no file was written",
            path.display()
        ))
    };
    remove_stale_temps(&target);
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
        if let Ok(meta) = std::fs::metadata(&target) {
            std::fs::set_permissions(&tmp, meta.permissions())
                .map_err(|e| fail("keeping the file's permissions", e))?;
        }
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

/// The longest file name most file systems take (Linux's NAME_MAX).
const NAME_MAX: usize = 255;

/// What `.STEM.PID.N.tmp` adds to the stem at most: a dot, two dots and up to
/// ten digits each, `.tmp`.
const TEMP_EXTRA: usize = 1 + 2 * (1 + 10) + 4;

/// The stem of the target's temporary names: the target's own name, or, where
/// that would take the temporary name past `NAME_MAX`, its start and a hash of
/// the whole, so that a legal name of 255 bytes still gets a temporary one.
fn temp_stem(target: &Path) -> String {
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    if name.len() + TEMP_EXTRA <= NAME_MAX {
        return name;
    }
    // FNV-1a: stable across runs and builds, so a later write finds the stem again.
    let hash = name.bytes().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    });
    let mut cut = NAME_MAX - TEMP_EXTRA - 17;
    while !name.is_char_boundary(cut) {
        cut -= 1;
    }
    format!("{}~{hash:016x}", &name[..cut])
}

/// A hidden name in the target's folder, unique to this process and write:
/// `.STEM.PID.N.tmp`, which `remove_stale_temps` recognises.
fn temp_beside(target: &Path) -> PathBuf {
    use std::sync::atomic::{AtomicU32, Ordering};
    static N: AtomicU32 = AtomicU32::new(0);
    let n = N.fetch_add(1, Ordering::Relaxed);
    target.with_file_name(format!(
        ".{}.{}.{n}.tmp",
        temp_stem(target),
        std::process::id()
    ))
}

/// Removes the target's temporary files that a killed writer left: those named
/// `.STEM.PID.N.tmp` whose process is gone. A live writer's file is left alone.
/// Best effort: a file that cannot be removed costs nothing but its space.
fn remove_stale_temps(target: &Path) {
    let Some(dir) = target.parent() else { return };
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let prefix = format!(".{}.", temp_stem(target));
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().to_string();
        let Some(rest) = name
            .strip_prefix(&prefix)
            .and_then(|r| r.strip_suffix(".tmp"))
        else {
            continue;
        };
        let Some((pid, n)) = rest.split_once('.') else {
            continue;
        };
        let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
        if digits(pid) && digits(n) && !process_alive(pid) {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Whether process `pid` (decimal) is running; where that cannot be known
/// (no /proc), it is taken to be, so that nothing is removed on a guess.
fn process_alive(pid: &str) -> bool {
    if pid == std::process::id().to_string() {
        return true;
    }
    let proc = Path::new("/proc");
    !proc.join("self").exists() || proc.join(pid).exists()
}

/// Whether two paths name one existing file, through links and other
/// spellings of the path: on Unix the same device and inode.
pub fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (std::fs::metadata(a), std::fs::metadata(b)) {
            (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
            (Ok(x), Ok(y)) => x == y,
            _ => false,
        }
    }
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
    // Path drops a trailing slash ("out/" has the file name "out"), and the
    // rename after the render would then fail on it.
    if path.to_string_lossy().ends_with('/') {
        return Err(bad_input(format!(
            "{option} '{shown}' ends with '/', which names a folder; give a file name"
        )));
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
    let Some(name) = target.file_name() else {
        return Err(bad_input(format!(
            "{option} '{shown}' names no file; give a file name"
        )));
    };
    if name.len() > NAME_MAX {
        return Err(bad_input(format!(
            "{option} '{shown}': the file name is {} bytes, more than the limit of {NAME_MAX}",
            name.len()
        )));
    }
    let dir = match target.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(d) => d.to_path_buf(),
        None => PathBuf::from("."),
    };
    // Probed with the very temporary name the write will use.
    check_writable_dir(option, &shown.to_string(), &dir, &temp_beside(&target))?;
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
    check_writable_dir(
        option,
        &shown.to_string(),
        dir,
        &temp_beside(&dir.join("probe")),
    )
}

/// Proves that `dir` exists and accepts a new file by creating and removing
/// `probe` in it (permission bits alone miss read-only mounts and ACLs).
fn check_writable_dir(option: &str, shown: &str, dir: &Path, probe: &Path) -> anyhow::Result<()> {
    if !dir.is_dir() {
        return Err(bad_input(format!(
            "{option} '{shown}': folder '{}' does not exist",
            dir.display()
        )));
    }
    match std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(probe)
    {
        Ok(_) => {
            let _ = std::fs::remove_file(probe);
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

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("twinray-io-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_rewrite_keeps_the_targets_mode() {
        use std::os::unix::fs::PermissionsExt;
        let dir = scratch("mode");
        let out = dir.join("out.png");
        write_file("--out", &out, b"one").unwrap();
        std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o600)).unwrap();
        write_file("--out", &out, b"two").unwrap();
        let mode = std::fs::metadata(&out).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o600, "{mode:o}");
        assert_eq!(std::fs::read(&out).unwrap(), b"two");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_write_removes_the_temporary_files_of_dead_writers_only() {
        let dir = scratch("stale");
        let out = dir.join("out.png");
        // PIDs stop below 2^22 on Linux, so this writer cannot be alive; PID 1 always is.
        let dead = format!(".out.png.{}.3.tmp", 1u64 << 40);
        let alive = ".out.png.1.0.tmp".to_string();
        let other = ".other.png.99999999999.0.tmp".to_string();
        for name in [&dead, &alive, &other] {
            std::fs::write(dir.join(name), b"partial").unwrap();
        }
        write_file("--out", &out, b"png").unwrap();
        assert_eq!(names(&dir), vec![other, alive, "out.png".to_string()]);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_legal_name_of_255_bytes_is_written_and_a_longer_one_refused_first() {
        let dir = scratch("long");
        let out = dir.join(format!("{}.png", "é".repeat(125) + "a")); // 255 bytes
        assert_eq!(out.file_name().unwrap().len(), 255);
        check_output_file("--out", &out).unwrap();
        write_file("--out", &out, b"png").unwrap();
        write_file("--out", &out, b"png").unwrap();
        assert_eq!(names(&dir).len(), 1);
        let longer = dir.join(format!("{}.png", "a".repeat(252)));
        let e = check_output_file("--out", &longer).unwrap_err().to_string();
        assert!(e.contains("256 bytes") && e.contains("255"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_trailing_slash_is_refused_before_any_work() {
        let dir = scratch("slash");
        for out in [
            dir.join("new/"),
            PathBuf::from(format!("{}/", dir.display())),
        ] {
            let e = check_output_file("--out", &out).unwrap_err().to_string();
            assert!(e.contains("ends with '/'"), "{e}");
        }
        assert!(names(&dir).is_empty());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
