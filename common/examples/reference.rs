//! Renders a scene with the f64 CPU reference: `cargo run --release -p twinray-common --example reference -- box 320x240 out.png`.
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let scene = twinray_common::scene::Scene::load(&a[1], &[]).unwrap_or_else(|e| panic!("{e:#}"));
    let size = twinray_common::cli::parse_size(&a[2]).unwrap();
    let t = std::time::Instant::now();
    let img = twinray_common::reference::render(&scene, size.width, size.height);
    eprintln!(
        "{} in {:?}, nonfinite {}",
        a[1],
        t.elapsed(),
        img.nonfinite_pixels()
    );
    img.save_png(std::path::Path::new(&a[3])).unwrap();
}
