//! The shader is valid GLSL by compilers other than naga: for every shader
//! variant's source — fragment and compute, every numerical choice, the
//! generic and the specialization-constant forms, with and without the BVH,
//! every feature subset (see `variants` for which stage gets which) — Khronos' glslangValidator compiles the concatenated
//! source with the variant's defines; `spirv-val` accepts naga's SPIR-V for
//! Vulkan 1.0 and, as `--gl-spirv` loads it (`spirv_for_opengl`), for OpenGL
//! 4.5; and glslangValidator accepts naga's GLSL 450. Every tool must print
//! nothing but the file name and exit 0. (Debian: glslang-tools, spirv-tools;
//! scripts/setup.sh installs them.)

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;
use twinray_common::cli::{RenderArgs, RenderPath, Size};
use twinray_common::lab::experiment::Experiment;
use twinray_common::plan::build_bvh;
use twinray_common::plan::requests::Api;
use twinray_common::plan::Planner;
use twinray_common::scene::accel::Accel;
use twinray_common::scene::numerics::Numerics;
use twinray_common::scene::{Features, Scene};
use twinray_common::shader::build::{self, build_compute, compute_source, fragment_source};
use twinray_common::shader::post::spirv_for_opengl;
use twinray_common::shader::variant::{SpirvCompiler, Variant};
use twinray_common::value_name::ValueName;
use twinray_tests::{assert_none, scratch};

/// One validator run: the program, its arguments, the file it checks.
struct Job {
    what: String,
    program: &'static str,
    args: Vec<String>,
    file: PathBuf,
}

fn write(path: &Path, bytes: &[u8]) -> PathBuf {
    std::fs::write(path, bytes).unwrap();
    path.to_path_buf()
}

fn words_to_bytes(words: &[u32]) -> Vec<u8> {
    words.iter().flat_map(|w| w.to_le_bytes()).collect()
}

/// The variants the apps build (`Planner::variant`) for the box scene — every
/// numerical choice with the generic shader (`--generic`) and the BVH, and
/// with specialization constants (`--specialize`) — plus the generic shader
/// with the counts read from the uniform (`Variant::generic`) for every
/// numerical choice, every feature subset of the scene-specific variants, and
/// the `--experiment` switches that change naga's output.
fn variants() -> Vec<(String, Variant)> {
    let mut v = Vec::new();
    let chosen = |n: Numerics, accel: Accel, generic: bool, experiment: Vec<Experiment>| {
        let set: Vec<(String, String)> = n
            .set_args()
            .iter()
            .filter_map(|kv| kv.split_once('='))
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        let scene = Scene::load("box", &set).unwrap();
        let bvh = accel
            .wants_bvh(&scene)
            .then(|| build_bvh(&scene).widen(accel.width()));
        let args = RenderArgs {
            generic,
            specialize: !generic,
            experiment,
            ..RenderArgs::headless(
                "box",
                Size {
                    width: 8,
                    height: 8,
                },
            )
        };
        // OpenGL's planner: it takes every experiment listed below.
        let planner = Planner::new(&args, Api::OpenGl).unwrap();
        planner.variant(&scene, bvh.as_ref(), RenderPath::Fragment, 0)
    };
    for n in Numerics::all() {
        v.push((format!("generic {}", n.label()), Variant::generic(n)));
        v.push((
            format!("generic+bvh {}", n.label()),
            chosen(n, Accel::Bvh, true, vec![]),
        ));
    }
    for bits in 0..16u32 {
        let f = Features {
            spheres: bits & 1 != 0,
            triangles: bits & 2 != 0,
            mirror: bits & 4 != 0,
            glass: bits & 8 != 0,
        };
        v.push((
            format!("features {bits:04b}"),
            Variant::from_features(f, 5, Numerics::default()),
        ));
    }
    let d = Numerics::default();
    v.push(("specialize".into(), chosen(d, Accel::None, false, vec![])));
    v.push((
        "specialize+bvh".into(),
        chosen(d, Accel::Bvh, false, vec![]),
    ));
    // The wide trees' walk, plain and with the stack experiments.
    for (label, accel) in [("bvh4", Accel::Bvh4), ("bvh8", Accel::Bvh8)] {
        v.push((format!("generic+{label}"), chosen(d, accel, true, vec![])));
        v.push((
            format!("specialize+{label}"),
            chosen(d, accel, false, vec![]),
        ));
        v.push((
            format!("generic+{label} local stack"),
            chosen(d, accel, true, vec![Experiment::LocalBvhStack]),
        ));
    }
    use Experiment::*;
    for experiments in [
        vec![NagaLoopBounding, SharedBvhStack, UniformCounts],
        vec![NoLoopBounding],
        vec![NagaAliasing, LocalBvhStack, SplitRayStack],
        vec![NoContraction],
        vec![Glslang],
        vec![FloatControls],
    ] {
        let label = experiments
            .iter()
            .map(|e| e.name())
            .collect::<Vec<_>>()
            .join(",");
        v.push((
            format!("generic+bvh experiments {label}"),
            chosen(d, Accel::Bvh, true, experiments),
        ));
    }
    // The ray-counting variant (--count-rays) of brute force and the BVH.
    for (label, accel, experiments) in [
        ("generic", Accel::None, vec![]),
        ("generic+bvh", Accel::Bvh, vec![]),
        ("generic+bvh4", Accel::Bvh4, vec![]),
    ] {
        v.push((
            format!("{label} counting rays"),
            chosen(d, accel, true, experiments).counting(),
        ));
    }
    v
}

fn define_args(defines: &std::collections::BTreeMap<String, String>) -> Vec<String> {
    defines.iter().map(|(k, v)| format!("-D{k}={v}")).collect()
}

// Long function: it lists every job (variant × stage × output × tool) in one
// pass, then runs them and checks the counts; the list is its one data structure.
#[test]
fn glslang_and_spirv_val_accept_every_variant() {
    for tool in ["glslangValidator", "spirv-val"] {
        assert!(
            Command::new(tool).arg("--version").output().is_ok(),
            "{tool} is not installed: install Debian's glslang-tools and spirv-tools (scripts/setup.sh does)"
        );
    }
    let dir = scratch("external-validators");
    let mut jobs = Vec::new();
    // The fullscreen triangle.
    let file = write(
        &dir.join("fullscreen.vert"),
        build::FULLSCREEN_VERT.as_bytes(),
    );
    jobs.push(Job {
        what: "vertex source fullscreen".into(),
        program: "glslangValidator",
        args: vec!["-V".into(), "--target-env".into(), "vulkan1.0".into()],
        file,
    });
    let list = variants();
    let mut fragment_sources = 0;
    let mut compute_sources = 0;
    for (i, (label, variant)) in list.iter().enumerate() {
        // The compute entry point wraps the same tracer: it is checked with
        // every numerical choice on the largest form (generic + BVH) and with
        // specialization constants; the fragment stage with everything.
        let stages: &[&str] = if label.starts_with("generic+bvh") || label.starts_with("specialize")
        {
            &["frag", "comp"]
        } else {
            &["frag"]
        };
        for &stage in stages {
            let (source, defines, spirv, glsl) = if stage == "frag" {
                let s = build::build(variant).unwrap_or_else(|e| panic!("{label}: {e:#}"));
                fragment_sources += 1;
                (
                    fragment_source(),
                    variant.defines(),
                    s.fragment.spirv,
                    s.fragment.glsl,
                )
            } else {
                let s = build_compute(variant, Api::Vulkan.default_workgroup(true))
                    .unwrap_or_else(|e| panic!("{label} compute: {e:#}"));
                compute_sources += 1;
                // The compute variant adds WG_X, WG_Y (and BVH_STACK_SHARED).
                (
                    compute_source(),
                    s.variant.defines(),
                    s.stage.spirv,
                    s.stage.glsl,
                )
            };
            let what = format!("{label} ({stage})");
            let base = dir.join(format!("v{i}"));
            let src = write(&base.with_extension(stage), source.as_bytes());
            let mut args = vec!["-V".into(), "--target-env".into(), "vulkan1.0".into()];
            args.extend(define_args(&defines));
            jobs.push(Job {
                what: format!("{what}: source"),
                program: "glslangValidator",
                args,
                file: src,
            });
            let vk = write(
                &dir.join(format!("v{i}-{stage}.vk.spv")),
                &words_to_bytes(&spirv),
            );
            // glslang's SPIR-V targets Vulkan 1.1 (SPIR-V 1.3), which OpenGL
            // cannot load (the GL app refuses --gl-spirv with it).
            let glslang = variant.passes.compiler == SpirvCompiler::Glslang;
            jobs.push(Job {
                what: format!("{what}: SPIR-V for Vulkan"),
                program: "spirv-val",
                args: vec![
                    "--target-env".into(),
                    if glslang { "vulkan1.1" } else { "vulkan1.0" }.into(),
                ],
                file: vk,
            });
            if glslang {
                continue;
            }
            let gl = write(
                &dir.join(format!("v{i}-{stage}.gl.spv")),
                &words_to_bytes(&spirv_for_opengl(&spirv, variant.passes.restrict)),
            );
            jobs.push(Job {
                what: format!("{what}: naga SPIR-V as OpenGL loads it"),
                program: "spirv-val",
                args: vec!["--target-env".into(), "opengl4.5".into()],
                file: gl,
            });
            // glslangValidator picks the stage from the extension.
            let out = write(&dir.join(format!("v{i}-naga.{stage}")), glsl.as_bytes());
            jobs.push(Job {
                what: format!("{what}: naga GLSL"),
                program: "glslangValidator",
                args: vec![],
                file: out,
            });
        }
    }
    assert!(fragment_sources >= 60 && compute_sources >= 24);

    let total = jobs.len();
    let queue = Mutex::new(jobs);
    let failures = Mutex::new(Vec::new());
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get().min(8));
    std::thread::scope(|s| {
        for _ in 0..threads {
            s.spawn(|| loop {
                let Some(job) = queue.lock().unwrap().pop() else {
                    break;
                };
                // glslangValidator -V writes <stage>.spv unless told otherwise.
                let mut cmd = Command::new(job.program);
                cmd.args(&job.args);
                if job.program == "glslangValidator" && job.args.iter().any(|a| a == "-V") {
                    cmd.arg("-o").arg(job.file.with_extension("glslang.spv"));
                }
                let out = cmd.arg(&job.file).output().unwrap();
                let text = format!(
                    "{}{}",
                    String::from_utf8_lossy(&out.stdout),
                    String::from_utf8_lossy(&out.stderr)
                );
                // glslangValidator names the file it read; anything else is a message.
                let messages: Vec<&str> = text
                    .lines()
                    .filter(|l| !l.trim().is_empty() && Path::new(l.trim()) != job.file)
                    .collect();
                if !out.status.success() || !messages.is_empty() {
                    failures.lock().unwrap().push(format!(
                        "{} ({} {} {}): {}",
                        job.what,
                        job.program,
                        job.args.join(" "),
                        job.file.display(),
                        messages.join(" | ")
                    ));
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap();
    println!(
        "{total} validator runs over {fragment_sources} fragment and {compute_sources} compute variants, {} with messages",
        failures.len()
    );
    assert_none(
        &format!("validator runs (of {total}) that printed messages or failed"),
        &failures,
    );
    std::fs::remove_dir_all(dir).ok();
}
