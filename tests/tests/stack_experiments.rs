//! The measurements that came with OpenGL's compute path reaching all of an
//! H100's multiprocessors (docs/findings/opengl-compute.md, "What closed the
//! gap") change only where the tracer keeps
//! what it stores, or what the driver is told: on lavapipe and llvmpipe each
//! renders the default image bit for bit, with the validation layer / GL debug
//! context silent. `local-bvh-stack` and `split-ray-stack` put back the old
//! stacks, `unpaired-bvh-stack` gives OpenGL Vulkan's form of the BVH stack,
//! `naga-aliasing` naga's declarations without `restrict`,
//! `naga-loop-bounding` naga's loop counters on the BVH variants too,
//! `--shared-pad` unused workgroup memory, and `--gl-spirv` loads the SPIR-V
//! that `Restrict` now decorates.
//! Every run that cannot honour one exits 2 with one sentence saying why, and
//! `--dump-shaders` with `--gl-spirv` no longer crashes Mesa.

use twinray_tests::{assert_identical, refused, render, run, scratch, App};

/// One measurement: what it adds to the command line, what the run it is
/// compared with adds (nothing: the default), and whether it exists on the
/// compute path only.
struct Variant {
    args: &'static [&'static str],
    base: &'static [&'static str],
    compute_only: bool,
}

/// Each of `variants` against its base, for one scene, both APIs, both paths,
/// in a scratch folder of the test's own (`name`: tests run in parallel).
fn same_image(name: &str, scene: &str, size: &str, extra: &[&str], variants: &[Variant]) {
    let dir = scratch(&format!("stack-experiments-{name}"));
    for app in App::BOTH {
        for path in ["fragment", "compute"] {
            for v in variants {
                let opengl_only = [v.args, v.base]
                    .concat()
                    .iter()
                    .any(|a| *a == "naga-aliasing" || *a == "--gl-spirv");
                if (v.compute_only && path == "fragment")
                    || (opengl_only && matches!(app, App::Vulkan))
                {
                    continue;
                }
                let base_args = [extra, &["--path", path], v.base].concat();
                let (_, base) = render(app, scene, size, &base_args, &dir.join("base.png"));
                let args = [extra, &["--path", path], v.args].concat();
                let (report, img) = render(app, scene, size, &args, &dir.join("variant.png"));
                assert_eq!(
                    report.validation_messages, 0,
                    "{scene} {app:?} {path} {:?}: validation messages",
                    v.args
                );
                let what = format!("{scene} {app:?} {path} {:?} against {:?}", v.args, v.base);
                assert_identical(&img, &base, &what);
            }
        }
    }
    std::fs::remove_dir_all(dir).ok();
}

const fn everywhere(args: &'static [&'static str]) -> Variant {
    Variant {
        args,
        base: &[],
        compute_only: false,
    }
}

const VARIANTS: &[Variant] = &[
    everywhere(&[
        "--experiment",
        "local-bvh-stack",
        "--experiment",
        "split-ray-stack",
    ]),
    everywhere(&["--experiment", "naga-aliasing"]),
    everywhere(&["--experiment", "unpaired-bvh-stack"]),
    everywhere(&["--experiment", "capped-bvh-stack"]),
    everywhere(&["--experiment", "naga-loop-bounding"]),
    // Mesa's GLSL and SPIR-V compilers may round a pixel differently (they
    // did on the box before `Restrict` existed), so the SPIR-V with `Restrict`
    // is held to the SPIR-V without it.
    Variant {
        args: &["--gl-spirv"],
        base: &["--gl-spirv", "--experiment", "naga-aliasing"],
        compute_only: false,
    },
    Variant {
        args: &["--shared-pad", "8"],
        base: &[],
        compute_only: true,
    },
    Variant {
        args: &["--workgroup", "16x16", "--shared-pad", "1"],
        base: &["--workgroup", "16x16"],
        compute_only: true,
    },
];

/// The box has glass, so its ray stack holds several rays; odd sizes, so the
/// compute path's edge workgroups are partial.
#[test]
fn box_bvh_renders_the_default_image_with_each_stack_and_declaration() {
    same_image("box", "box", "97x61", &["--accel", "bvh"], VARIANTS);
}

#[test]
fn teapot_bvh_renders_the_default_image_with_each_stack_and_declaration() {
    same_image("teapot", "teapot", "65x49", &["--accel", "bvh"], VARIANTS);
}

/// `capped-bvh-stack` on a tree deeper than its cap (the 307k-triangle
/// teapot's stack needs 40 entries; the cap is the default teapot's 31): the
/// label says the shader declares 31, and no frame here needs more, so the
/// image is the default's.
#[test]
fn a_capped_stack_renders_the_deep_teapots_image() {
    let deep = ["--set", "tessellation=80x60"];
    let capped = everywhere(&["--experiment", "capped-bvh-stack"]);
    same_image("deep-teapot", "teapot", "40x30", &deep, &[capped]);
    let dir = scratch("stack-experiments-capped-label");
    let args = [
        &deep[..],
        &["--path", "compute", "--experiment", "capped-bvh-stack"],
    ]
    .concat();
    for app in App::BOTH {
        let (report, _) = render(app, "teapot", "8x8", &args, &dir.join("capped.png"));
        assert!(
            report.variant.contains("/bvh31") && report.variant.ends_with("/capped-bvh-stack"),
            "{app:?}: {}",
            report.variant
        );
    }
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn runs_that_cannot_honour_a_measurement_refuse_it() {
    let compute = ["--headless", "--size", "32x24", "--path", "compute"];
    let with = |extra: &[&'static str]| [&compute[..], extra].concat();
    refused(
        App::Vulkan,
        &with(&["--experiment", "naga-aliasing"]),
        "--experiment naga-aliasing is OpenGL only",
    );
    refused(
        App::Vulkan,
        &with(&["--experiment", "warp-probe"]),
        "--experiment warp-probe is OpenGL only",
    );
    // Mesa has no GL_NV_shader_thread_group: refused before the compile.
    refused(
        App::OpenGl,
        &with(&["--experiment", "warp-probe"]),
        "the warp probe needs GL_NV_shader_thread_group",
    );
    refused(
        App::OpenGl,
        &with(&["--experiment", "warp-probe", "--gl-spirv"]),
        "--gl-spirv with --experiment warp-probe",
    );
    refused(
        App::OpenGl,
        &["--headless", "--experiment", "warp-probe"],
        "--experiment warp-probe applies to --path compute only",
    );
    for app in App::BOTH {
        refused(
            app,
            &["--headless", "--shared-pad", "8"],
            "--shared-pad applies to --path compute only",
        );
        for kib in ["0", "33", "eight"] {
            refused(app, &with(&["--shared-pad", kib]), "--shared-pad");
        }
    }
}

/// Mesa 22.3's glGetProgramBinary crashed on a program linked from SPIR-V; the
/// app no longer asks it for one, and says so in the statistics.
#[test]
fn dumping_a_spirv_program_on_mesa_says_what_it_cannot_save() {
    let dir = scratch("stack-experiments-dump");
    for path in ["fragment", "compute"] {
        let dump = dir.join(path);
        let dump_s = dump.to_str().unwrap();
        let o = run(
            &App::OpenGl.exe(),
            &[
                "--headless",
                "--size",
                "32x24",
                "--gl-spirv",
                "--path",
                path,
                "--dump-shaders",
                dump_s,
            ],
            &[],
        );
        assert!(
            o.status.success(),
            "{path}: {} {}",
            o.status,
            String::from_utf8_lossy(&o.stderr)
        );
        let stats = std::fs::read_to_string(dump.join("statistics.json")).unwrap();
        assert!(
            stats.contains("Mesa cannot save a SPIR-V program's binary"),
            "{path}: {stats}"
        );
    }
    std::fs::remove_dir_all(dir).ok();
}
