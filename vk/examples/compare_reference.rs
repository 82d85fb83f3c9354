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
    let m = compare(&refimg.to_rgb8(), &load_png(std::path::Path::new(&a[2]))?)?;
    println!("{}: within 1/255 {:.4}%, above 8/255 {:.4}%, max {} psnr {:.1} dB", a[0], m.within_1() * 100.0, m.above_8 * 100.0, m.max_abs, m.psnr_db);
    Ok(())
}
