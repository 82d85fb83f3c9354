//! `twinray diff A.png B.png`: the image metrics of common::metrics, as a table or JSON,
//! over every pixel or (`--exclude`) those a mask does not name.

use std::path::Path;
use twinray_common::reference::image_io::load_png;
use twinray_common::reference::metrics::{compare_outside, Metrics};
use twinray_common::reference::unsettled::mask_from_image;

pub fn run(
    a: &Path,
    b: &Path,
    json: bool,
    heatmap: Option<&Path>,
    exclude: Option<&Path>,
) -> anyhow::Result<()> {
    // Checked first: a bad --heatmap path is said before any image is read
    // (that it names no input, `main` has checked with every command's outputs).
    if let Some(path) = heatmap {
        twinray_common::reference::image_io::check_output_file("--heatmap", path)?;
    }
    let (ia, ib) = (load_png(a)?, load_png(b)?);
    let left_out = match exclude {
        Some(path) => {
            let mask = load_png(path)?;
            if mask.dimensions() != ia.dimensions() {
                return Err(twinray_common::error::bad_input(format!(
                    "--exclude '{}' is {}x{}, the images {}x{}: a mask must be of the images' size",
                    path.display(),
                    mask.width(),
                    mask.height(),
                    ia.width(),
                    ia.height()
                )));
            }
            let left_out = mask_from_image(&mask);
            if left_out.iter().all(|&l| l) {
                return Err(twinray_common::error::bad_input(format!(
                    "--exclude '{}' names every pixel (white throughout): nothing is left to compare",
                    path.display()
                )));
            }
            left_out
        }
        None => Vec::new(),
    };
    let m = compare_outside(&ia, &ib, &left_out).map_err(|e| {
        twinray_common::error::bad_input(format!("'{}' vs '{}': {e}", a.display(), b.display()))
    })?;
    let left = left_out.iter().filter(|&&l| l).count();
    if let Some(path) = heatmap {
        let mut out = image::RgbImage::new(ia.width(), ia.height());
        for (x, y, p) in out.enumerate_pixels_mut() {
            let (pa, pb) = (ia.get_pixel(x, y), ib.get_pixel(x, y));
            let worst = (0..3).map(|c| pa[c].abs_diff(pb[c])).max().unwrap_or(0);
            let grey = ((pa[0] as u32 + pa[1] as u32 + pa[2] as u32) / 9) as u8;
            *p = if worst > 1 {
                image::Rgb([128u8.saturating_add(worst.saturating_mul(2)), 0, 0])
            } else {
                image::Rgb([grey; 3])
            };
        }
        twinray_common::reference::image_io::write_png(&out, "--heatmap", path)?;
    }
    if json {
        if exclude.is_some() {
            let mut v = serde_json::to_value(m)?;
            v["left_out"] = left.into();
            println!("{v}");
        } else {
            println!("{}", serde_json::to_string(&m)?);
        }
    } else {
        println!(
            "{} vs {} ({}x{})",
            a.display(),
            b.display(),
            m.width,
            m.height
        );
        if let Some(path) = exclude {
            println!(
                "{left} pixels left out (named by {}); the shares are of the other {}",
                path.display(),
                (m.width as usize * m.height as usize) - left
            );
        }
        print_table(&[("", m)]);
    }
    Ok(())
}

pub fn print_table(rows: &[(&str, Metrics)]) {
    println!(
        "{:<28} {:>10} {:>9} {:>8} {:>10} {:>10} {:>6}",
        "", "RMSE", "PSNR dB", "max abs", ">1/255", ">8/255", "NaN"
    );
    for (name, m) in rows {
        println!(
            "{:<28} {:>10.6} {:>9.2} {:>8} {:>9.4}% {:>9.4}% {:>6}",
            name,
            m.rmse,
            m.psnr_db,
            m.max_abs,
            100.0 * m.above_1,
            100.0 * m.above_8,
            m.nan_pixels
        );
    }
}
