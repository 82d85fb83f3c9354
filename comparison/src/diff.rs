//! `twinray diff A.png B.png`: the image metrics of common::metrics, as a table or JSON.

use std::path::Path;
use twinray_common::reference::image_io::load_png;
use twinray_common::reference::metrics::{compare, Metrics};

pub fn run(a: &Path, b: &Path, json: bool, heatmap: Option<&Path>) -> anyhow::Result<()> {
    // Checked first: a bad --heatmap path is said before any image is read.
    if let Some(path) = heatmap {
        twinray_common::reference::image_io::check_output_file("--heatmap", path)?;
        for input in [a, b] {
            if twinray_common::reference::image_io::same_file(path, input) {
                return Err(twinray_common::error::bad_input(format!(
                    "--heatmap '{}' is the input image '{}': writing it would replace an input; choose another file name",
                    path.display(),
                    input.display()
                )));
            }
        }
    }
    let (ia, ib) = (load_png(a)?, load_png(b)?);
    let m = compare(&ia, &ib).map_err(|e| {
        twinray_common::error::bad_input(format!("'{}' vs '{}': {e}", a.display(), b.display()))
    })?;
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
        println!("{}", serde_json::to_string(&m)?);
    } else {
        println!(
            "{} vs {} ({}x{})",
            a.display(),
            b.display(),
            m.width,
            m.height
        );
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
