//! Upright and unmirrored in both APIs and on both paths (the 2018 study's Vulkan images were
//! mirrored): a scene with a red ball top-left, a green ball top-right and a
//! blue ball bottom-left must show them there, in the PNG's top-row-first order.

use twinray_tests::{render, scratch, App};

#[test]
fn both_apis_and_paths_are_upright_and_not_mirrored() {
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/data/orientation.toml");
    let dir = scratch("orientation");
    for (app, path) in App::BOTH
        .into_iter()
        .flat_map(|a| ["fragment", "compute"].map(|p| (a, p)))
    {
        let (_, img) = render(app, scene, "80x60", &["--path", path], &dir.join("o.png"));
        let app = format!("{app:?} {path}");
        let at = |x: u32, y: u32| img.get_pixel(x, y).0;
        let dominant = |p: [u8; 3]| (0..3).max_by_key(|&c| p[c]).unwrap();
        assert_eq!(
            dominant(at(20, 15)),
            0,
            "{app}: top-left should be red, got {:?}",
            at(20, 15)
        );
        assert_eq!(
            dominant(at(60, 15)),
            1,
            "{app}: top-right should be green, got {:?}",
            at(60, 15)
        );
        assert_eq!(
            dominant(at(20, 45)),
            2,
            "{app}: bottom-left should be blue, got {:?}",
            at(20, 45)
        );
        assert!(
            at(60, 45).iter().all(|&c| c < 20),
            "{app}: bottom-right is empty background, got {:?}",
            at(60, 45)
        );
    }
}
