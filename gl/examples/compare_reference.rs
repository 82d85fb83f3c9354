//! Throwaway check: renders the f64 CPU reference for a scene and compares a
//! twinray-gl PNG against it.
//! Usage: compare_reference SCENE WxH GL.png [KEY=VALUE ...]

use std::path::Path;
use twinray_common::{cli::parse_size, image_io::load_png, metrics::compare, reference, scene::Scene};

fn main() -> anyhow::Result<()> {
    let a: Vec<String> = std::env::args().skip(1).collect();
    anyhow::ensure!(a.len() >= 3, "usage: compare_reference SCENE WxH GL.png [KEY=VALUE ...]");
    let size = parse_size(&a[1]).map_err(anyhow::Error::msg)?;
    let overrides: Vec<(String, String)> =
        a[3..].iter().filter_map(|kv| kv.split_once('=')).map(|(k, v)| (k.into(), v.into())).collect();
    let scene = Scene::load(&a[0], &overrides)?;
    let reference = reference::render(&scene, size.width, size.height).to_rgb8();
    let ref_path = Path::new(&a[2]).with_extension("ref.png");
    twinray_common::image_io::save_png(&reference, &ref_path)?;
    let gl = load_png(Path::new(&a[2]))?;
    let m = compare(&gl, &reference)?;
    // Where they differ by more than 1/255: white; else the reference, dimmed.
    let mut mask = reference.clone();
    for (p, q) in mask.pixels_mut().zip(gl.pixels()) {
        let off = (0..3).any(|c| p.0[c].abs_diff(q.0[c]) > 1);
        for c in 0..3 {
            p.0[c] = if off { 255 } else { p.0[c] / 3 };
        }
    }
    twinray_common::image_io::save_png(&mask, &Path::new(&a[2]).with_extension("diff.png"))?;
    println!(
        "{} {}: within 1/255 {:.4}%, above 8/255 {:.4}%, max {} , psnr {:.1} dB (reference: {})",
        a[0],
        a[1],
        m.within_1() * 100.0,
        m.above_8 * 100.0,
        m.max_abs,
        m.psnr_db,
        ref_path.display()
    );
    Ok(())
}
