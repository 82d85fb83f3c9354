//! Throwaway check: renders the CPU reference and compares a twinray-vk PNG with it.
//! cargo run -p twinray-vk --example compare_reference -- SCENE WxH VK.png [KEY=VALUE...]
use twinray_common::{cli::parse_size, image_io::load_png, metrics::compare, reference, scene::Scene};

fn main() -> anyhow::Result<()> {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let size = parse_size(&a[1]).map_err(anyhow::Error::msg)?;
    let overrides: Vec<(String, String)> =
        a[3..].iter().filter_map(|kv| kv.split_once('=')).map(|(k, v)| (k.into(), v.into())).collect();
    let scene = Scene::load(&a[0], &overrides)?;
    let refimg = reference::render(&scene, size.width, size.height);
    refimg.save_png(std::path::Path::new(&format!("/tmp/ref-{}.png", a[0])))?;
    let vk = load_png(std::path::Path::new(&a[2]))?;
    let m = compare(&refimg.to_rgb8(), &vk)?;
    // side by side, 4x: vk | reference | diff (white = >8/255, grey = >1/255)
    let (w, h, s) = (size.width, size.height, 4u32);
    let r8 = refimg.to_rgb8();
    let mut pixels = vec![[0f32; 3]; (w * s * 3 * h * s) as usize];
    for y in 0..h * s { for x in 0..w * s {
        let (px, py) = (x / s, y / s);
        let v = vk.get_pixel(px, py).0; let r = r8.get_pixel(px, py).0;
        let d = (0..3).map(|c| v[c].abs_diff(r[c])).max().unwrap();
        if d > 8 && x % s == 0 && y % s == 0 && px % 3 == 0 { eprintln!("({px},{py}) vk {v:?} ref {r:?}"); }
        let row = (y * w * s * 3) as usize;
        pixels[row + x as usize] = v.map(|c| c as f32 / 255.0);
        pixels[row + (w * s + x) as usize] = r.map(|c| c as f32 / 255.0);
        pixels[row + (2 * w * s + x) as usize] = if d > 8 { [1.0; 3] } else if d > 1 { [0.4; 3] } else { [0.0; 3] };
    }}
    twinray_common::image_io::FloatImage { width: w * s * 3, height: h * s, pixels }.save_png(std::path::Path::new(&format!("/tmp/side-{}.png", a[0])))?;
    println!("{}: within 1/255 {:.4}%, above 8/255 {:.4}%, max {} psnr {:.1} dB", a[0], m.within_1() * 100.0, m.above_8 * 100.0, m.max_abs, m.psnr_db);
    Ok(())
}
