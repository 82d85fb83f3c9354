//! `twinray compare`'s why step: the Vulkan/OpenGL gaps the study leaves and
//! the experiments that each isolate one candidate cause (`CASES`, one line
//! per gap × experiment), run at each gap point in fresh processes with the
//! order alternating, like the sweeps. The report's "Why the gaps" section and
//! why.csv are written from what this returns (report/why_table.rs).

use crate::apps::api_name;
use crate::apps::{run_json, Api};
use crate::compare::gaps::{
    floor_file, write_floor_files, BOX_COMPUTE, BOX_FRAGMENT, BOX_IMAGES, SPHERELIST_BVH_COMPUTE,
    SPHERELIST_BVH_SMALL, TEAPOT_BVH_COMPUTE, TEAPOT_FRAGMENT,
};
use crate::compare::runs::{Case, Gap, GapFrame, GapMeasure, Hold, Why, WhyFigures, WhyRow};
use std::collections::BTreeMap;
use std::ffi::OsStr;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use twinray_common::cli::{RenderArgs, RenderPath, Size, Workgroup};
use twinray_common::error::{Failure, FailureKind};
use twinray_common::lab::experiment::Experiment;
use twinray_common::reference::image_io::load_png;
use twinray_common::reference::metrics;
use twinray_common::report::RunReport;
use twinray_common::scene::accel::Accel;
use twinray_common::value_name::ValueName;

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

/// Every gap × experiment the step measures, in the report's order.
pub const CASES: &[Case] = &[
    vulkan(&BOX_FRAGMENT, &[Experiment::Glslang]),
    vulkan(&BOX_FRAGMENT, &[Experiment::NoLoopBounding]),
    gl_spirv(&BOX_FRAGMENT),
    gl_spirv(&BOX_COMPUTE),
    both(&BOX_COMPUTE, &[Experiment::SplitRayStack]),
    vulkan(&TEAPOT_FRAGMENT, &[Experiment::Glslang]),
    vulkan(&TEAPOT_FRAGMENT, &[Experiment::NoLoopBounding]),
    gl_spirv(&TEAPOT_FRAGMENT),
    both(&TEAPOT_BVH_COMPUTE, &[Experiment::SharedBvhStack]),
    both(&TEAPOT_BVH_COMPUTE, &[Experiment::LocalBvhStack]),
    opengl(&TEAPOT_BVH_COMPUTE, &[Experiment::NagaAliasing]),
    gl_spirv(&TEAPOT_BVH_COMPUTE),
    one_workgroup(&TEAPOT_BVH_COMPUTE),
    floor(&TEAPOT_BVH_COMPUTE),
    both(&SPHERELIST_BVH_COMPUTE, &[Experiment::FirstOfEquals]),
    both(&SPHERELIST_BVH_COMPUTE, &[Experiment::WalkThenShade]),
    both(&SPHERELIST_BVH_COMPUTE, &[Experiment::LocalBvhStack]),
    gl_spirv(&SPHERELIST_BVH_COMPUTE),
    one_workgroup(&SPHERELIST_BVH_COMPUTE),
    no_ray_loop(&SPHERELIST_BVH_COMPUTE),
    both(&SPHERELIST_BVH_SMALL, &[Experiment::TimedBarrier]),
    floor(&SPHERELIST_BVH_SMALL),
    one_workgroup(&SPHERELIST_BVH_SMALL),
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
    /// The side of the gaps measured in a frame of one wave.
    pub small_side: u32,
    /// Frames per run at most; each stops once settled (`settle`, per cent).
    pub frames: u32,
    pub settle: f64,
    pub seconds_per_point: f64,
    pub rounds: u32,
}

/// One process to run at a gap: an API with its experiments, and what else
/// it is held to (`Hold`; None: its defaults).
type Run = (Api, &'static [Experiment], Option<Hold>);

/// What `case` runs: its Vulkan run and its OpenGL run.
fn runs_of(case: &Case) -> [Run; 2] {
    [
        (Api::Vulkan, case.vulkan, case.hold),
        (case.opengl_api, case.opengl, case.hold),
    ]
}

/// A run's label in file names and messages: `vulkan`, `opengl-glslang`...
pub fn run_label(run: Run) -> String {
    std::iter::once(api_name(run.0).to_string())
        .chain(run.1.iter().map(|e| e.name()))
        .chain(run.2.map(Hold::label))
        .collect::<Vec<_>>()
        .join("-")
}

/// A row whose runs all ran but whose figure this device cannot give: the
/// table's answer, not a failure.
pub const NOT_MEASURED: &str = "not measured: ";

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
    for case in CASES.iter().filter(|c| paths.contains(&c.gap.path)) {
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
        for run in cases.iter().flat_map(runs_of) {
            if !order.contains(&run) {
                order.push(run);
            }
        }
        let measured = measure(&dir, gap, size, plan, &order, i, stop);
        note_devices(&mut why, &order, &measured);
        for case in cases {
            let result = figures(gap, &case, &measured, &dir);
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

/// Each run's reports at one gap, rounds in alternating order.
type Measured = BTreeMap<String, Vec<Result<RunReport, String>>>;

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

/// The median over rounds of each round's median: GPU ms with `gpu`, else wall ms.
fn median_ms(reports: &[Result<RunReport, String>], gpu: bool) -> Result<f64, String> {
    let mut v = Vec::new();
    for r in reports {
        let r = r.as_ref().map_err(Clone::clone)?;
        let s = if gpu { r.gpu_ms } else { r.wall_ms };
        v.push(s.map(|s| s.median).ok_or("failed: no frame times")?);
    }
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2)
        .copied()
        .ok_or_else(|| "failed: not run (stopped)".to_string())
}

/// The case's figures from the runs at its gap.
fn figures(gap: &Gap, case: &Case, measured: &Measured, dir: &Path) -> Result<WhyFigures, String> {
    let [vk, gl] = runs_of(case);
    let default = [(Api::Vulkan, &[][..], None), (Api::Opengl, &[][..], None)];
    let four = [default[0], default[1], vk, gl];
    let reports = |run: Run| -> Result<&Vec<Result<RunReport, String>>, String> {
        measured
            .get(&run_label(run))
            .ok_or_else(|| "failed: not run (stopped)".to_string())
    };
    match gap.measure {
        GapMeasure::Agreement => {
            let within = |a: Run, b: Run| -> Result<f64, String> {
                for run in [a, b] {
                    reports(run)?
                        .iter()
                        .try_for_each(|r| r.as_ref().map(|_| ()).map_err(Clone::clone))?;
                }
                let png = |run| dir.join(format!("{}-{}.png", gap.scene, run_label(run)));
                let (a, b) = (load_png(&png(a)), load_png(&png(b)));
                let m = metrics::compare(
                    &a.map_err(|e| format!("failed: {e:#}"))?,
                    &b.map_err(|e| format!("failed: {e:#}"))?,
                )
                .map_err(|e| format!("failed: {e:#}"))?;
                Ok(100.0 * m.within_1())
            };
            Ok(WhyFigures {
                before: within(default[0], default[1])?,
                after: within(vk, gl)?,
                clock: "image",
                ms: None,
            })
        }
        GapMeasure::Ratio => {
            let all: Vec<_> = four.iter().map(|&r| reports(r)).collect::<Result<_, _>>()?;
            let gpu = all.iter().all(|rs| {
                rs.iter()
                    .all(|r| r.as_ref().is_ok_and(|r| r.gpu_ms.is_some()))
            });
            let ms: Vec<f64> = all
                .iter()
                .map(|rs| median_ms(rs, gpu))
                .collect::<Result<_, _>>()?;
            let after = if case.hold == Some(Hold::Floor) {
                // A wall-clock frame holds the host's share of the loop too,
                // which an empty frame does not measure apart from the GPU's.
                if !gpu {
                    return Err(format!("{NOT_MEASURED}each API's empty frame comes off GPU time only, and this driver's runs have wall time"));
                }
                let (vk, gl) = (ms[0] - ms[2], ms[1] - ms[3]);
                if vk <= 0.0 || gl <= 0.0 {
                    return Err(format!(
                        "failed: the empty frame ({:.4} / {:.4} ms) took as long as the gap's ({:.4} / {:.4} ms)",
                        ms[2], ms[3], ms[0], ms[1]
                    ));
                }
                vk / gl
            } else {
                ms[2] / ms[3]
            };
            Ok(WhyFigures {
                before: ms[0] / ms[1],
                after,
                clock: if gpu { "GPU" } else { "wall" },
                ms: Some([ms[0], ms[1], ms[2], ms[3]]),
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    /// The empty frame's row: each API's time less its empty frame's, on GPU
    /// time only; an empty frame as long as the gap's frame is a failure.
    #[test]
    fn a_floor_row_takes_each_empty_frame_off_gpu_time_only() {
        let case = floor(&SPHERELIST_BVH_SMALL);
        let measured = |times: [f64; 4], gpu: bool| -> Measured {
            let labels = ["vulkan", "opengl", "vulkan-floor", "opengl-floor"];
            labels
                .iter()
                .zip(times)
                .map(|(label, ms)| {
                    let mut r =
                        crate::compare::runs::test_outcome(Api::Vulkan, RenderPath::Compute, ms)
                            .result
                            .expect("a test outcome succeeds");
                    if !gpu {
                        r.gpu_ms = None;
                    }
                    (label.to_string(), vec![Ok(r)])
                })
                .collect()
        };
        let dir = Path::new("/nonexistent");
        let f = figures(
            case.gap,
            &case,
            &measured([18.0, 20.0, 6.0, 8.0], true),
            dir,
        )
        .unwrap();
        assert_eq!((f.before, f.after, f.clock), (0.9, 1.0, "GPU"));
        assert_eq!(f.ms, Some([18.0, 20.0, 6.0, 8.0]));
        let wall = figures(
            case.gap,
            &case,
            &measured([18.0, 20.0, 6.0, 8.0], false),
            dir,
        );
        assert!(wall.unwrap_err().starts_with(NOT_MEASURED));
        let longer = figures(case.gap, &case, &measured([18.0, 7.0, 6.0, 8.0], true), dir);
        assert!(longer.unwrap_err().starts_with("failed: the empty frame"));
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
