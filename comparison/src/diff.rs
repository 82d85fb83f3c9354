//! `twinray diff A.png B.png`: the image metrics of common::metrics, as a table or JSON.

use std::path::Path;
use twinray_common::image_io::load_png;
use twinray_common::metrics::{compare, Metrics};

pub fn run(a: &Path, b: &Path, json: bool) -> anyhow::Result<()> {
    let m = compare(&load_png(a)?, &load_png(b)?).map_err(|e| {
        twinray_common::error::bad_input(format!("'{}' vs '{}': {e}", a.display(), b.display()))
    })?;
    if json {
        println!("{}", serde_json::to_string(&m)?);
    } else {
        println!("{} vs {} ({}x{})", a.display(), b.display(), m.width, m.height);
        print_table(&[("", m)]);
    }
    Ok(())
}

pub fn print_table(rows: &[(&str, Metrics)]) {
    println!("{:<28} {:>10} {:>9} {:>8} {:>10} {:>10} {:>6}", "", "RMSE", "PSNR dB", "max abs", ">1/255", ">8/255", "NaN");
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
