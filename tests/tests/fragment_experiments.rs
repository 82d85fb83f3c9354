//! The fragment-path experiments are measurement-only: on lavapipe and
//! llvmpipe, `quad`, `load-clear` and (Vulkan) `dynamic-viewport` render the
//! default image bit for bit and
//! `rgba8` within 1/255 (the GPU rounds to 8 bits instead of the CPU), with the
//! Khronos validation layer / GL debug context silent and the experiment named
//! in the report's variant. Every run that cannot honour one of them (the
//! other path, a window, OpenGL or a device without a compute-only queue for
//! `compute-queue`) exits 2 with one sentence saying why.

use twinray_common::reference::metrics::compare;
use twinray_tests::{refused, render, scratch, App};

/// Odd sizes, so that the quad's diagonal crosses pixel centres unevenly and
/// no row or column is a multiple of anything.
fn same_image(scene: &str, size: &str, extra: &[&str]) {
    let dir = scratch(&format!("fragment-experiments-{scene}"));
    for app in App::BOTH {
        let (base_report, base) = render(app, scene, size, extra, &dir.join("default.png"));
        let vulkan_only: &[&str] = match app {
            App::Vulkan => &["dynamic-viewport"],
            App::OpenGl => &[],
        };
        for &experiment in ["quad", "load-clear", "rgba8"].iter().chain(vulkan_only) {
            let mut args = extra.to_vec();
            args.extend(["--experiment", experiment]);
            let (report, img) = render(app, scene, size, &args, &dir.join("experiment.png"));
            assert_eq!(
                report.validation_messages, 0,
                "{scene} {app:?} --experiment {experiment}: validation messages"
            );
            assert!(
                report.variant.ends_with(&format!("/{experiment}")),
                "{app:?}: the variant {} must name the experiment {experiment}",
                report.variant
            );
            assert_eq!(
                report.variant,
                format!("{}/{experiment}", base_report.variant),
                "{app:?}: only the experiment is added to the variant"
            );
            let m = compare(&img, &base).unwrap();
            let differing = img.pixels().zip(base.pixels()).filter(|(a, b)| a != b);
            println!(
                "{scene} {app:?} {experiment} vs default: {} of {} pixels differ, max {}/255",
                differing.count(),
                img.pixels().len(),
                m.max_abs
            );
            if experiment == "rgba8" {
                assert!(
                    m.max_abs <= 1,
                    "{scene} {app:?} rgba8: {}/255 from the default, more than 1/255",
                    m.max_abs
                );
            } else {
                assert!(
                    img == base,
                    "{scene} {app:?} {experiment}: the image differs from the default (max {}/255)",
                    m.max_abs
                );
            }
        }
    }
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn box_renders_the_default_image_with_each_experiment() {
    same_image("box", "161x121", &[]);
}

#[test]
fn runs_that_cannot_honour_an_experiment_refuse_it() {
    let headless = ["--headless", "--size", "32x24"];
    let with = |extra: &[&'static str]| [&headless[..], extra].concat();
    refused(
        App::OpenGl,
        &with(&["--path", "compute", "--experiment", "compute-queue"]),
        "--experiment compute-queue is Vulkan only: OpenGL has no queues to choose from",
    );
    // lavapipe's one queue family draws and dispatches: there is no other.
    refused(
        App::Vulkan,
        &with(&["--path", "compute", "--experiment", "compute-queue"]),
        "has no compute-only queue family (one with COMPUTE but not GRAPHICS)",
    );
    refused(
        App::OpenGl,
        &with(&["--experiment", "dynamic-viewport"]),
        "--experiment dynamic-viewport is Vulkan only: OpenGL's viewport is always state set before the draw",
    );
    refused(
        App::Vulkan,
        &with(&["--experiment", "compute-queue"]),
        "--experiment compute-queue applies to --path compute only",
    );
    for app in App::BOTH {
        for experiment in ["quad", "load-clear", "rgba8"] {
            refused(
                app,
                &with(&["--path", "compute", "--experiment", experiment]),
                &format!("--experiment {experiment} applies to --path fragment only"),
            );
            // Refused before any window opens: no display is needed to see it.
            refused(
                app,
                &["--experiment", experiment],
                &format!(
                    "--experiment {experiment} is a headless measurement; run it with --headless"
                ),
            );
        }
    }
}

/// The BVH traversal too: the pass experiments must not touch what the shader does.
#[test]
fn teapot_bvh_renders_the_default_image_with_each_experiment() {
    same_image("teapot", "65x49", &["--accel", "bvh"]);
}
