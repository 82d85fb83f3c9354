//! `twinray compare`'s why step: the Vulkan/OpenGL gaps the study leaves and
//! the experiments that each isolate one candidate cause (`CASES`, one line
//! per gap × experiment), run at each gap point in fresh processes with the
//! order alternating, like the sweeps. The report's "Why the gaps" section and
//! why.csv are written from what this returns (report/why_table.rs).

use crate::apps::{run_json, Api};
use crate::compare::gaps::{
    floor_file, write_floor_files, BOX_BVH_COMPUTE, BOX_BVH_LARGE, BOX_COMPUTE, BOX_FRAGMENT,
    BOX_IMAGES, SPHERELIST_BVH_COMPUTE, SPHERELIST_BVH_SMALL, TEAPOT_BVH_COMPUTE, TEAPOT_BVH_LARGE,
    TEAPOT_BVH_LARGEST, TEAPOT_DEEPEST_BVH_COMPUTE, TEAPOT_DEEP_BVH_COMPUTE, TEAPOT_FRAGMENT,
};
use crate::compare::runs::{
    baselines, run_label, runs_of, Case, Gap, GapFrame, GapMeasure, Hold, Measured, Run, Why,
    WhyRow,
};
use std::ffi::OsStr;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use twinray_common::cli::{RenderArgs, RenderPath, Size, Workgroup};
use twinray_common::error::{Failure, FailureKind};
use twinray_common::lab::experiment::Experiment;
use twinray_common::scene::accel::Accel;

/// What each API runs at `gap` instead of its default.
const fn case(
    gap: &'static Gap,
    vulkan: &'static [Experiment],
    opengl: &'static [Experiment],
    opengl_api: Api,
) -> Case {
    Case {
        gap,
        vulkan,
        opengl,
        opengl_api,
        hold: None,
    }
}

/// Both APIs at one workgroup: OpenGL's default for BVH walks (4x8), where
/// Vulkan's own (8x16) lets its driver hold the ray's constants in shared
/// memory and the tracer in fewer registers.
const fn one_workgroup(gap: &'static Gap) -> Case {
    Case {
        hold: Some(Hold::Workgroup(4, 8)),
        ..case(gap, &[], &[], Api::Opengl)
    }
}

/// Both APIs at a maximum depth of 1: no mirror ray, and so no ray loop,
/// which NVIDIA's OpenGL compiler holds in more registers than the walk
/// alone needs (fewer warps a multiprocessor than Vulkan's).
const fn no_ray_loop(gap: &'static Gap) -> Case {
    Case {
        hold: Some(Hold::Set("max_depth=1")),
        ..case(gap, &[], &[], Api::Opengl)
    }
}

/// Each API's empty frame of the gap's size taken off its time (`Hold::Floor`).
const fn floor(gap: &'static Gap) -> Case {
    Case {
        hold: Some(Hold::Floor),
        ..case(gap, &[], &[], Api::Opengl)
    }
}

/// The second of two frames back to back (`--experiment back-to-back`), less
/// the first, in both APIs, at each one's own workgroup or at `workgroup`:
/// one frame's tracing without a lone dispatch's start and end
/// (`Hold::SecondFrame`).
const fn second_frame(gap: &'static Gap, workgroup: Option<(u32, u32)>) -> Case {
    Case {
        hold: Some(Hold::SecondFrame(workgroup)),
        ..case(gap, &[], &[], Api::Opengl)
    }
}

/// Vulkan alone runs the experiment; OpenGL as shipped.
const fn vulkan(gap: &'static Gap, e: &'static [Experiment]) -> Case {
    case(gap, e, &[], Api::Opengl)
}

/// Both APIs run the experiment.
const fn both(gap: &'static Gap, e: &'static [Experiment]) -> Case {
    case(gap, e, e, Api::Opengl)
}

/// OpenGL alone runs the experiment; Vulkan as shipped.
const fn opengl(gap: &'static Gap, e: &'static [Experiment]) -> Case {
    case(gap, &[], e, Api::Opengl)
}

/// OpenGL runs naga's SPIR-V (`--gl-spirv`), the very binary Vulkan runs.
const fn gl_spirv(gap: &'static Gap) -> Case {
    case(gap, &[], &[], Api::OpenglSpirv)
}

/// The deep teapots' stacks held to the default teapot's 31 entries, in the
/// form OpenGL takes on deep trees (one entry a `uvec2`): NVIDIA's OpenGL then
/// runs the tracer on every multiprocessor, with the same warps on each, and
/// nothing else in the walk changes. `capped-bvh-stack` alone also takes
/// OpenGL back to its pairs, which cost it on deep trees.
const SMALL_STACK: &[Experiment] = &[Experiment::CappedBvhStack, Experiment::UnpairedBvhStack];

/// Every gap × experiment the step measures, in the report's order.
pub const CASES: &[Case] = &[
    vulkan(&BOX_FRAGMENT, &[Experiment::Glslang]),
    vulkan(&BOX_FRAGMENT, &[Experiment::NoLoopBounding]),
    gl_spirv(&BOX_FRAGMENT),
    gl_spirv(&BOX_COMPUTE),
    both(&BOX_COMPUTE, &[Experiment::SplitRayStack]),
    one_workgroup(&BOX_BVH_COMPUTE),
    second_frame(&BOX_BVH_COMPUTE, None),
    one_workgroup(&BOX_BVH_LARGE),
    second_frame(&BOX_BVH_LARGE, None),
    vulkan(&TEAPOT_FRAGMENT, &[Experiment::Glslang]),
    vulkan(&TEAPOT_FRAGMENT, &[Experiment::NoLoopBounding]),
    gl_spirv(&TEAPOT_FRAGMENT),
    both(&TEAPOT_BVH_COMPUTE, &[Experiment::SharedBvhStack]),
    both(&TEAPOT_BVH_COMPUTE, &[Experiment::LocalBvhStack]),
    opengl(&TEAPOT_BVH_COMPUTE, &[Experiment::NagaAliasing]),
    gl_spirv(&TEAPOT_BVH_COMPUTE),
    one_workgroup(&TEAPOT_BVH_COMPUTE),
    floor(&TEAPOT_BVH_COMPUTE),
    second_frame(&TEAPOT_BVH_COMPUTE, None),
    second_frame(&TEAPOT_BVH_COMPUTE, Some((4, 8))),
    opengl(&TEAPOT_BVH_COMPUTE, &[Experiment::StorageNodes]),
    one_workgroup(&TEAPOT_BVH_LARGE),
    second_frame(&TEAPOT_BVH_LARGE, Some((4, 8))),
    one_workgroup(&TEAPOT_BVH_LARGEST),
    both(&TEAPOT_DEEP_BVH_COMPUTE, &[Experiment::CappedBvhStack]),
    opengl(&TEAPOT_DEEP_BVH_COMPUTE, &[Experiment::StorageNodes]),
    one_workgroup(&TEAPOT_DEEP_BVH_COMPUTE),
    both(&TEAPOT_DEEP_BVH_COMPUTE, SMALL_STACK),
    both(&TEAPOT_DEEPEST_BVH_COMPUTE, &[Experiment::CappedBvhStack]),
    both(&TEAPOT_DEEPEST_BVH_COMPUTE, SMALL_STACK),
    both(&SPHERELIST_BVH_COMPUTE, &[Experiment::FirstOfEquals]),
    both(&SPHERELIST_BVH_COMPUTE, &[Experiment::WalkThenShade]),
    both(&SPHERELIST_BVH_COMPUTE, &[Experiment::LocalBvhStack]),
    gl_spirv(&SPHERELIST_BVH_COMPUTE),
    one_workgroup(&SPHERELIST_BVH_COMPUTE),
    no_ray_loop(&SPHERELIST_BVH_COMPUTE),
    both(&SPHERELIST_BVH_SMALL, &[Experiment::TimedBarrier]),
    floor(&SPHERELIST_BVH_SMALL),
    one_workgroup(&SPHERELIST_BVH_SMALL),
    second_frame(&SPHERELIST_BVH_SMALL, None),
    second_frame(&SPHERELIST_BVH_SMALL, Some((4, 8))),
    both(&BOX_IMAGES, &[Experiment::NoContraction]),
    vulkan(&BOX_IMAGES, &[Experiment::NoContraction]),
    vulkan(&BOX_IMAGES, &[Experiment::FloatControls]),
];

/// The why step's share of a preset: the side of each scene's gap points,
/// frames per run, the longest one app may take at a point, and rounds.
#[derive(Debug, Clone, Copy)]
pub struct WhyPlan {
    pub box_side: u32,
    pub teapot_side: u32,
    /// The brute-force teapot's side: its frames cost seconds at 1000².
    pub teapot_brute_side: u32,
    /// The frame of the gaps measured where users trace large frames.
    pub large_frame: (u32, u32),
    /// The frame of the gaps measured at the largest frame users trace.
    pub largest_frame: (u32, u32),
    /// Whether to measure the 4.9M-triangle teapot, whose 472 MB of
    /// triangles a software driver's storage buffers cannot hold.
    pub deepest: bool,
    /// The side of the gaps measured in a frame of one wave.
    pub small_side: u32,
    /// Frames per run at most; each stops once settled (`settle`, per cent).
    pub frames: u32,
    pub settle: f64,
    pub seconds_per_point: f64,
    pub rounds: u32,
}

impl WhyPlan {
    /// A software driver's share: small frames, few of them.
    pub const QUICK: WhyPlan = WhyPlan {
        box_side: 100,
        teapot_side: 16,
        teapot_brute_side: 16,
        large_frame: (64, 36),
        largest_frame: (128, 72),
        deepest: false,
        small_side: 100,
        frames: 8,
        settle: 2.0,
        seconds_per_point: 2.0,
        rounds: 1,
    };
    /// A GPU's share. The brute-force teapot's fragment frame takes seconds
    /// at 1000²: its gap is measured at 400², where its ratio is the sweep's
    /// (report: the teapot table). One round: each run's interval already
    /// says how far its median can be trusted.
    pub const FULL: WhyPlan = WhyPlan {
        box_side: 1000,
        teapot_side: 1000,
        teapot_brute_side: 400,
        large_frame: (1920, 1080),
        largest_frame: (3840, 2160),
        deepest: true,
        small_side: 300,
        frames: 60,
        settle: 1.0,
        seconds_per_point: 30.0,
        rounds: 1,
    };
}

/// The tool an experiment needs on PATH, if any.
fn tool_needed(run: Run) -> Option<&'static str> {
    run.1
        .contains(&Experiment::Glslang)
        .then_some("glslangValidator")
}

/// Whether `tool` is an executable file in one of PATH's folders (`path`).
pub fn on_path(tool: &str, path: Option<&OsStr>) -> bool {
    use std::os::unix::fs::PermissionsExt;
    path.map(|p| {
        std::env::split_paths(p).any(|dir| {
            std::fs::metadata(dir.join(tool))
                .is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
        })
    })
    .unwrap_or(false)
}

/// Every case whose gap is on one of `paths`, measured; images go under `out/why/`.
pub fn run(out: &Path, plan: &WhyPlan, paths: &[RenderPath], stop: &AtomicBool) -> Why {
    let mut why = Why::default();
    let dir = out.join("why");
    if let Err(e) = write_floor_files(&dir) {
        eprintln!("twinray compare: why step skipped: {e}");
        return why;
    }
    let mut gaps: Vec<&'static Gap> = Vec::new();
    let measured = |c: &&Case| {
        paths.contains(&c.gap.path)
            && (plan.deepest || !std::ptr::eq(c.gap, &TEAPOT_DEEPEST_BVH_COMPUTE))
    };
    for case in CASES.iter().filter(measured) {
        if !gaps.iter().any(|g| std::ptr::eq(*g, case.gap)) {
            gaps.push(case.gap);
        }
    }
    eprintln!(
        "twinray compare: why step: {} gaps, {} experiments",
        gaps.len(),
        CASES
            .iter()
            .filter(|c| gaps.iter().any(|g| std::ptr::eq(*g, c.gap)))
            .count()
    );
    for (i, gap) in gaps.into_iter().enumerate() {
        if stop.load(Ordering::SeqCst) {
            break;
        }
        let side = match (gap.scene, gap.accel) {
            ("teapot", Accel::None) => plan.teapot_brute_side,
            ("teapot", _) => plan.teapot_side,
            _ => plan.box_side,
        };
        let (width, height) = match gap.frame {
            GapFrame::Square => (side, side),
            GapFrame::Large => plan.large_frame,
            GapFrame::Largest => plan.largest_frame,
            GapFrame::Small => (plan.small_side, plan.small_side),
        };
        let size = Size { width, height };
        let cases: Vec<Case> = CASES
            .iter()
            .filter(|c| std::ptr::eq(c.gap, gap))
            .copied()
            .collect();
        // Every case is read against the defaults, whether a case runs them or not.
        let mut order: Vec<Run> = vec![(Api::Vulkan, &[], None), (Api::Opengl, &[], None)];
        for run in cases
            .iter()
            .flat_map(|c| baselines(c).into_iter().chain(runs_of(c)))
        {
            if !order.contains(&run) {
                order.push(run);
            }
        }
        let measured = measure(&dir, gap, size, plan, &order, i, stop);
        note_devices(&mut why, &order, &measured);
        for case in cases {
            let result = crate::compare::why_figures::figures(gap, &case, &measured, &dir);
            if let Err(e) = &result {
                let [vk, gl] = runs_of(&case);
                eprintln!(
                    "  {} / {} + {}: {e}",
                    gap.name,
                    run_label(vk),
                    run_label(gl)
                );
            }
            why.rows.push(WhyRow { case, size, result });
        }
    }
    why
}

/// Keeps the device of the gap's first Vulkan run and first OpenGL run that
/// succeeded where no earlier gap gave one, so the title can prefer Vulkan's
/// name whichever API a gap's runs reached first.
fn note_devices(why: &mut Why, order: &[Run], measured: &Measured) {
    let first = |vulkan: bool| {
        order
            .iter()
            .filter(|run| (run.0 == Api::Vulkan) == vulkan)
            .find_map(|&run| {
                measured
                    .get(&run_label(run))?
                    .iter()
                    .find_map(|r| r.as_ref().ok())
            })
    };
    let (vk, gl) = (first(true), first(false));
    why.software |= vk
        .iter()
        .chain(&gl)
        .any(|r| crate::apps::is_software(&r.device));
    for (slot, r) in [(&mut why.vulkan_device, vk), (&mut why.opengl_device, gl)] {
        if let (None, Some(r)) = (&slot, r) {
            *slot = Some(r.device.clone());
        }
    }
}

/// Runs every one of `order` at the gap: once for images, `plan.rounds`
/// times for timings (reversed every other round and gap), after a short
/// probe that sizes the frame count to `plan.seconds_per_point`.
fn measure(
    dir: &Path,
    gap: &Gap,
    size: Size,
    plan: &WhyPlan,
    order: &[Run],
    gap_index: usize,
    stop: &AtomicBool,
) -> Measured {
    let images = gap.measure == GapMeasure::Agreement;
    let base = RenderArgs {
        accel: gap.accel,
        path: gap.path,
        set: gap.set.iter().map(|s| s.to_string()).collect(),
        ..RenderArgs::headless(gap.scene, size)
    };
    let frames = if images {
        1
    } else {
        let probe = RenderArgs {
            frames: Some(2),
            ..base.clone()
        };
        match run_json(Api::Vulkan, &probe) {
            Ok(r) => r
                .frames
                .iter()
                .map(|f| f.wall_ms)
                .reduce(f64::min)
                .filter(|&ms| ms > 0.0)
                .map(|ms| {
                    ((plan.seconds_per_point * 1e3 / ms).floor() as u32)
                        .clamp(plan.frames.min(7), plan.frames)
                })
                .unwrap_or(plan.frames),
            Err(_) => plan.frames,
        }
    };
    let rounds = if images { 1 } else { plan.rounds };
    let mut measured = Measured::new();
    for round in 0..rounds {
        let mut runs = order.to_vec();
        if (gap_index + round as usize) % 2 == 1 {
            runs.reverse();
        }
        for run in runs {
            if stop.load(Ordering::SeqCst) {
                return measured;
            }
            let label = run_label(run);
            let result = match tool_needed(run) {
                Some(tool) if !on_path(tool, std::env::var_os("PATH").as_deref()) => {
                    Err(format!("not run: {tool} not on PATH"))
                }
                _ => {
                    let mut args = RenderArgs {
                        frames: Some(frames),
                        settle: (!images).then_some(plan.settle),
                        out: images.then(|| dir.join(format!("{}-{label}.png", gap.scene))),
                        experiment: run.1.to_vec(),
                        ..base.clone()
                    };
                    match run.2 {
                        Some(Hold::Workgroup(x, y)) => args.workgroup = Some(Workgroup { x, y }),
                        Some(Hold::Set(kv)) => args.set.push(kv.to_string()),
                        Some(Hold::Floor) => {
                            args.scene = dir.join(floor_file(gap.scene)).display().to_string()
                        }
                        Some(Hold::SecondFrame(workgroup)) => {
                            args.experiment.push(Experiment::BackToBack);
                            args.workgroup = workgroup.map(|(x, y)| Workgroup { x, y });
                        }
                        None => {}
                    }
                    run_json(run.0, &args).map_err(|e| refused_or_failed(run, &e))
                }
            };
            if stop.load(Ordering::SeqCst) && result.is_err() {
                // Stopped by the signal, not failed: not a measurement.
                return measured;
            }
            measured.entry(label).or_default().push(result);
        }
    }
    measured
}

/// Why a run gave no report: an experiment the app refuses on this device
/// (its one sentence, exit 2) was not run; anything else failed.
fn refused_or_failed(run: Run, e: &anyhow::Error) -> String {
    match e.downcast_ref::<Failure>() {
        Some(f) if f.kind == FailureKind::BadInput && !run.1.is_empty() => {
            format!("not run: {}", f.message)
        }
        _ => format!("failed: {e:#}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use twinray_common::report::RunReport;

    #[test]
    fn a_tool_is_found_only_as_an_executable_on_path() {
        let dir = std::env::temp_dir().join(format!("twinray-why-path-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let joined = std::env::join_paths([Path::new("/nonexistent"), &dir]).unwrap();
        assert!(!on_path("glslangValidator", Some(&joined)));
        let tool = dir.join("glslangValidator");
        std::fs::write(&tool, "#!/bin/sh\n").unwrap();
        assert!(
            !on_path("glslangValidator", Some(&joined)),
            "not executable"
        );
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&tool, std::fs::Permissions::from_mode(0o755)).unwrap();
        assert!(on_path("glslangValidator", Some(&joined)));
        assert!(!on_path("glslangValidator", None));
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn the_title_names_the_vulkan_device_and_else_the_opengl_one() {
        const VK: &str = "NVIDIA H100 80GB HBM3";
        const GL: &str = "NVIDIA H100 80GB HBM3/PCIe/SSE2";
        let report = |device: &str| {
            let mut r = crate::compare::runs::test_outcome(Api::Vulkan, RenderPath::Fragment, 1.0)
                .result
                .expect("a test outcome succeeds");
            r.device = device.into();
            Ok(r)
        };
        let gap = |vulkan: Result<RunReport, String>| -> Measured {
            [
                ("vulkan".to_string(), vec![vulkan]),
                ("opengl".to_string(), vec![report(GL)]),
                ("opengl-spirv".to_string(), vec![report(GL)]),
            ]
            .into()
        };
        let order: Vec<Run> = vec![
            (Api::Vulkan, &[], None),
            (Api::Opengl, &[], None),
            (Api::OpenglSpirv, &[], None),
        ];
        let title = |why: &Why| {
            crate::report::title(why.vulkan_device.as_deref(), why.opengl_device.as_deref())
        };
        let mut why = Why::default();
        note_devices(&mut why, &order, &gap(Err("failed: no device".into())));
        assert_eq!(title(&why), format!("# twinray compare — {GL}"));
        // A later gap's Vulkan run still wins over an earlier gap's OpenGL one.
        note_devices(&mut why, &order, &gap(report(VK)));
        assert_eq!(title(&why), format!("# twinray compare — {VK}"));
        let mut why = Why::default();
        note_devices(&mut why, &order, &gap(report(VK)));
        assert_eq!(title(&why), format!("# twinray compare — {VK}"));
        assert!(!why.software);
        assert_eq!(title(&Why::default()), "# twinray compare — no device");
    }

    #[test]
    fn each_gap_has_its_default_runs_and_a_glslang_case_needs_the_tool() {
        for case in CASES {
            let [vk, gl] = runs_of(case);
            assert_eq!(vk.0, Api::Vulkan);
            assert_ne!(gl.0, Api::Vulkan);
            assert!(
                !case.vulkan.is_empty()
                    || !case.opengl.is_empty()
                    || gl.0 == Api::OpenglSpirv
                    || case.hold.is_some(),
                "{} has a case that changes nothing",
                case.gap.name
            );
        }
        assert_eq!(
            tool_needed((Api::Vulkan, &[Experiment::Glslang], None)),
            Some("glslangValidator")
        );
        assert_eq!(
            tool_needed((Api::Vulkan, &[Experiment::NoLoopBounding], None)),
            None
        );
        assert_eq!(
            run_label((Api::Opengl, &[Experiment::NoContraction], None)),
            "opengl-no-contraction"
        );
    }
}
