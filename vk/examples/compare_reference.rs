//! Throwaway check: compares a twinray-vk PNG with the f64 CPU reference (saved
//! as /tmp/ref-SCENE.png), or two PNGs with each other.
//!   cargo run -p twinray-vk --example compare_reference -- SCENE WxH VK.png [KEY=VALUE...]
//!   cargo run -p twinray-vk --example compare_reference -- diff A.png B.png
use std::path::Path;
use twinray_common::{cli::parse_size, image_io::load_png, metrics::compare, reference, scene::Scene};

fn main() -> anyhow::Result<()> {
    let a: Vec<String> = std::env::args().skip(1).collect();
    anyhow::ensure!(a.len() >= 3, "usage: SCENE WxH VK.png [KEY=VALUE...] | diff A.png B.png");
    let (name, m) = if a[0] == "diff" {
        ("diff".to_string(), compare(&load_png(Path::new(&a[1]))?, &load_png(Path::new(&a[2]))?)?)
    } else {
        let size = parse_size(&a[1]).map_err(anyhow::Error::msg)?;
        let set: Vec<(String, String)> =
            a[3..].iter().filter_map(|kv| kv.split_once('=')).map(|(k, v)| (k.into(), v.into())).collect();
        let scene = Scene::load(&a[0], &set)?;
        let reference = reference::render(&scene, size.width, size.height);
        let stem = Path::new(&a[0]).file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        reference.save_png(Path::new(&format!("/tmp/ref-{stem}.png")))?;
        (a[0].clone(), compare(&reference.to_rgb8(), &load_png(Path::new(&a[2]))?)?)
    };
    println!(
        "{name}: {:.4}% within 1/255, {:.4}% above 8/255, max {}",
        100.0 * m.within_1(),
        100.0 * m.above_8,
        m.max_abs
    );
    Ok(())
}
