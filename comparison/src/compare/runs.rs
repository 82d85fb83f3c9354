//! What a comparison runs and what each run gave back: the plan of points,
//! every API's outcome at a point, the runs of "model only what a scene
//! needs", the image agreement, the gaps and the experiments that explain
//! them. The steps (compare.rs and its accel.rs, agreement.rs, why.rs) fill
//! these in and the report reads them, so neither imports the other.

use crate::apps::{api_name, Api};
use std::collections::BTreeMap;
use twinray_common::cli::{RenderPath, Size};
use twinray_common::lab::experiment::Experiment;
use twinray_common::reference::metrics::Metrics;
use twinray_common::report::RunReport;
use twinray_common::scene::accel::Accel;
use twinray_common::value_name::ValueName;

/// The study's three experiments, in the order every output lists them.
pub const EXPERIMENTS: [&str; 3] = ["teapot", "box", "spherelist"];

/// One point of a sweep: a scene at one size or one extra-sphere count.
#[derive(Debug, Clone)]
pub struct Point {
    pub experiment: &'static str,
    pub param_name: &'static str,
    pub param_value: String,
    pub scene: &'static str,
    pub size: Size,
    pub set: Vec<String>,
    /// Work relative to the sweep's first point (pixels or primitives), to predict frame time.
    pub work: f64,
}

/// The points of a comparison and how long each may run.
pub struct Plan {
    pub points: Vec<Point>,
    /// Frames per run, or with `settle` the cap.
    pub frames: u32,
    /// Each run stops once its median's 95 % interval is within ±this % (`--settle`).
    pub settle: Option<f64>,
    /// Fewer frames for a point predicted to take longer than this per app.
    pub seconds_per_point: f64,
    /// "quick" or "full".
    pub preset: &'static str,
}

impl Plan {
    /// How long each run went on, as the report's method paragraph says it.
    pub fn describe(&self) -> String {
        match self.settle {
            Some(p) => format!(
                "each run until its median's 95 % interval was within ±{p} % (after a warm-up of its first 0.2 s, \
                 at least 6 timed frames), at most {} frames (fewer for slow points, about {} s per app per point)",
                self.frames, self.seconds_per_point
            ),
            None => format!(
                "up to {} frames per point (fewer for slow points, about {} s per app per point), statistics over \
                 the last 30 (or the last half of shorter runs)",
                self.frames, self.seconds_per_point
            ),
        }
    }
}

/// One API at one point: its report, or why it failed.
#[derive(Debug, Clone)]
pub struct Outcome {
    pub point: Point,
    pub api: Api,
    pub path: RenderPath,
    pub result: Result<RunReport, String>,
}

/// Image agreement of one scene: both APIs against each other and the f64 reference.
#[derive(Debug, Clone)]
pub struct Agreement {
    pub scene: &'static str,
    pub size: Size,
    /// Vulkan vs OpenGL, Vulkan vs reference, OpenGL vs reference.
    pub result: Result<[Metrics; 3], String>,
    /// With the compute path measured: each API's compute image against its fragment image.
    pub paths: Option<Result<[Metrics; 2], String>>,
}

/// The all-features shader; the scene's own variant (defines); the one
/// all-features source specialised to the scene through specialization
/// constants (`--specialize`); the scene's variant with a BVH.
pub const ACCEL_CONFIGS: [&str; 4] = [
    "generic, brute force",
    "variant, brute force",
    "specialized, brute force",
    "variant, BVH",
];

/// One run of "model only what a scene needs": a scene in one configuration.
#[derive(Debug, Clone)]
pub struct AccelRun {
    pub scene: &'static str,
    pub size: Size,
    pub set: Vec<String>,
    /// One of ACCEL_CONFIGS.
    pub config: &'static str,
    pub api: Api,
    pub result: Result<RunReport, String>,
    /// The BVH, built here as the apps build it (BVH configurations only).
    pub bvh: Option<BvhStats>,
}

#[derive(Debug, Clone, Copy)]
pub struct BvhStats {
    pub nodes: usize,
    pub bytes: usize,
    pub build_ms: f64,
}

/// What a gap is a gap in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GapMeasure {
    /// Vulkan's median frame time over OpenGL's.
    Ratio,
    /// The share of pixels on which Vulkan's and OpenGL's images agree within 1/255.
    Agreement,
}

/// A point where the two APIs differ: one scene, accel and path, at the
/// preset's size for that scene.
#[derive(Debug, Clone, Copy)]
pub struct Gap {
    pub name: &'static str,
    pub scene: &'static str,
    /// Scene values (`--set KEY=VALUE`) the gap's point takes.
    pub set: &'static [&'static str],
    pub frame: GapFrame,
    pub accel: Accel,
    pub path: RenderPath,
    pub measure: GapMeasure,
}

/// The frame a gap is measured at (`WhyPlan` gives the sizes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GapFrame {
    /// A square of the preset's side for the scene.
    Square,
    /// The preset's large frame (1080p in the full preset).
    Large,
    /// The preset's largest frame (4K in the full preset), where a lone
    /// frame's start and end weigh least.
    Largest,
    /// The preset's small square (300² in the full preset): a frame of one
    /// wave of workgroups, which a fixed cost of each dispatch weighs on.
    Small,
}

/// One candidate cause of a gap: what each API runs instead of its default.
/// `opengl` names the OpenGL front door: `Api::OpenglSpirv` runs Vulkan's SPIR-V.
#[derive(Debug, Clone, Copy)]
pub struct Case {
    pub gap: &'static Gap,
    pub vulkan: &'static [Experiment],
    pub opengl: &'static [Experiment],
    pub opengl_api: Api,
    /// What both APIs' runs hold fixed instead of their defaults, if anything.
    pub hold: Option<Hold>,
}

/// A change a case makes to both APIs' runs that is no experiment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Hold {
    /// One compute workgroup for both, instead of each API's own.
    Workgroup(u32, u32),
    /// One more scene value (`--set KEY=VALUE`).
    Set(&'static str),
    /// Both also trace an empty frame of the same size, shader variant and
    /// workgroup (the sphere list behind its camera: every ray misses), and
    /// each API's time of it comes off its time at the gap: what is left is
    /// the tracing, without each API's fixed cost of a dispatch.
    Floor,
    /// Both run two frames back to back (`--experiment back-to-back`), at
    /// their own workgroups or at the one given, and one frame at the same
    /// workgroup comes off each: the second frame's cost, the frame's
    /// tracing without a lone dispatch's start and end (its last workgroups'
    /// latency, when the GPU has nothing else to run).
    SecondFrame(Option<(u32, u32)>),
}

impl Hold {
    /// As it appears in run labels and file names: `4x8`, `max_depth=1`.
    pub fn label(self) -> String {
        match self {
            Hold::Workgroup(x, y) => format!("{x}x{y}"),
            Hold::Set(kv) => kv.to_string(),
            Hold::Floor => "floor".to_string(),
            Hold::SecondFrame(None) => "back-to-back".to_string(),
            Hold::SecondFrame(Some((x, y))) => format!("back-to-back-{x}x{y}"),
        }
    }
}

/// A gap's figure (VK/GL ratio or % of pixels within 1/255) by default and
/// with the experiment, and the times behind a ratio.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WhyFigures {
    pub before: f64,
    pub after: f64,
    /// "GPU" or "wall" for a ratio (GPU where all four runs have a timer), "image" for agreement.
    pub clock: &'static str,
    /// Median ms: Vulkan and OpenGL by default, then with the experiment
    /// (ratios only; with `Hold::Floor`, of the empty frame, whose time the
    /// ratio with the experiment takes off each API's; with
    /// `Hold::SecondFrame`, of the second frame, whose ratio it is).
    pub ms: Option<[f64; 4]>,
}

/// One case as measured: at which size, and its figures or why there are none
/// ("not run: ..." or "failed: ...").
#[derive(Debug, Clone)]
pub struct WhyRow {
    pub case: Case,
    pub size: Size,
    pub result: Result<WhyFigures, String>,
}

/// The why step's rows, the devices they ran on, and whether it is a software
/// driver (whose ratios say nothing about GPUs).
#[derive(Debug, Clone, Default)]
pub struct Why {
    pub rows: Vec<WhyRow>,
    /// The device of the first Vulkan run that succeeded: the title's choice
    /// (report::title).
    pub vulkan_device: Option<String>,
    /// The device of the first OpenGL run that succeeded: the title's fallback.
    pub opengl_device: Option<String>,
    pub software: bool,
}

/// Everything one `twinray compare` measured: what its report is written from.
#[derive(Clone)]
pub struct Results<'a> {
    pub plan: &'a Plan,
    pub outcomes: &'a [Outcome],
    pub accel: &'a [AccelRun],
    pub agreement: &'a [Agreement],
    /// Every API × path each point was to run with, so that the report can
    /// name the runs an interruption left out.
    pub runs: &'a [(Api, RenderPath)],
    /// A signal stopped the run: the report says so in its title and summary.
    pub interrupted: Option<Interruption>,
    /// How many app runs the whole comparison made, every step included, how
    /// long it took, and each step's share: the report states them.
    pub cost: Option<(usize, f64, String)>,
}

/// What stopped a comparison early: the signal, and the step it stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Interruption {
    pub signal: &'static str,
    /// "the sweep", "the acceleration runs", ... as a sentence reads it.
    pub step: &'static str,
}

/// A successful outcome of `api` on `path` at the box's 8x8 point whose every
/// frame took `ms`, for the report's tests.
#[cfg(test)]
pub fn test_outcome(api: Api, path: RenderPath, ms: f64) -> Outcome {
    let json = format!(
        r#"{{"api":"x","device":"d","driver":"v","api_version":"1","os":"o","scene":{{"name":"box","triangles":30,"spheres":2,"lights":1,"materials":3,"max_depth":5}},
           "variant":"v","width":8,"height":8,{}"frames":[{{"gpu_ms":{ms},"wall_ms":{ms}}}],"gpu_ms":null,"wall_ms":null,
           "nonfinite_pixels":0,"setup_ms":1.0,"validation_messages":0}}"#,
        if path == RenderPath::Compute {
            r#""path":"compute","workgroup":"16x8","#
        } else {
            ""
        }
    );
    let mut r: RunReport =
        serde_json::from_str(&json).expect("a report without `path` still parses");
    r.summarise();
    let point = Point {
        experiment: "box",
        param_name: "resolution",
        param_value: "8x8".into(),
        scene: "box",
        size: Size {
            width: 8,
            height: 8,
        },
        set: vec![],
        work: 1.0,
    };
    Outcome {
        point,
        api,
        path,
        result: Ok(r),
    }
}

/// One process to run at a gap: an API with its experiments, and what else
/// it is held to (`Hold`; None: its defaults).
pub(crate) type Run = (Api, &'static [Experiment], Option<Hold>);

/// What `case` runs: its Vulkan run and its OpenGL run.
pub(crate) fn runs_of(case: &Case) -> [Run; 2] {
    [
        (Api::Vulkan, case.vulkan, case.hold),
        (case.opengl_api, case.opengl, case.hold),
    ]
}

/// The runs `case`'s own are read against besides the defaults: a second
/// frame held at one workgroup takes off one frame at that workgroup.
pub(crate) fn baselines(case: &Case) -> [Run; 2] {
    let hold = match case.hold {
        Some(Hold::SecondFrame(Some((x, y)))) => Some(Hold::Workgroup(x, y)),
        _ => None,
    };
    [(Api::Vulkan, &[], hold), (Api::Opengl, &[], hold)]
}

/// A run's label in file names and messages: `vulkan`, `opengl-glslang`...
pub(crate) fn run_label(run: Run) -> String {
    std::iter::once(api_name(run.0).to_string())
        .chain(run.1.iter().map(|e| e.name()))
        .chain(run.2.map(Hold::label))
        .collect::<Vec<_>>()
        .join("-")
}

/// A row whose runs all ran but whose figure this device cannot give: the
/// table's answer, not a failure.
pub const NOT_MEASURED: &str = "not measured: ";

/// Each run's reports at one gap, rounds in alternating order.
pub(crate) type Measured = BTreeMap<String, Vec<Result<RunReport, String>>>;
