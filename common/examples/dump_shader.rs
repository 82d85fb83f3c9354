//! Prints the GLSL naga writes for a scene's fragment shader (for reading, not used by the apps).
fn main() {
    let scene = std::env::args().nth(1).unwrap_or_else(|| "box".into());
    let s = twinray_common::scene::Scene::load(&scene, &[]).unwrap_or_else(|e| panic!("{e:#}"));
    let v = twinray_common::shader::variant::Variant::for_scene(&s);
    let sh = twinray_common::shader::build::build(&v).unwrap_or_else(|e| panic!("{e:#}"));
    println!(
        "// variant {}\n{}\n{}",
        v.label(),
        sh.vertex_glsl,
        sh.fragment_glsl
    );
}
