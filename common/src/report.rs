//! The JSON object each app prints with `--json`: the contract between the apps
//! and the `twinray` orchestrator (which reads it back with the same struct).

use crate::cli::{RenderPath, Workgroup};
use crate::rays::{grays_per_s, RateClock, RayCounts, RayKinds};
use crate::scene::SceneStats;
use crate::shader::build::Stage;
use crate::stats::{study_warmup, summarize, summarize_all, FramePlan, Summary};
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct FrameTime {
    /// GPU time of the draw, from timestamps / timer queries (None where unreliable or unsupported).
    pub gpu_ms: Option<f64>,
    /// One loop iteration: submit + wait, as the 2018 study measured.
    pub wall_ms: f64,
    /// A warm-up frame: rendered and shown, left out of the statistics.
    /// Reports from before the mark use the study's rule (the last 30 of 60).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub warmup: bool,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RunReport {
    /// "vulkan" or "opengl".
    pub api: String,
    pub device: String,
    pub driver: String,
    pub api_version: String,
    pub os: String,
    pub scene: SceneStats,
    pub variant: String,
    pub width: u32,
    pub height: u32,
    /// Which entry point traced: fragment or compute (absent in reports from
    /// before the compute path: those were fragment runs).
    #[serde(default)]
    pub path: RenderPath,
    /// The compute workgroup as "8x4"; None for the fragment path.
    #[serde(default)]
    pub workgroup: Option<String>,
    pub frames: Vec<FrameTime>,
    pub gpu_ms: Option<Summary>,
    pub wall_ms: Option<Summary>,
    /// Pixels of the last frame with a NaN or infinite channel before quantisation.
    pub nonfinite_pixels: u64,
    /// Milliseconds from process start to the first frame (setup cost).
    pub setup_ms: f64,
    /// Messages from the validation layer / GL debug output (errors and warnings).
    pub validation_messages: u64,
    /// With `--dump-shaders`: what the driver reported of the compiled tracer
    /// (Vulkan's pipeline executable statistics, OpenGL's program binary).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub shader_stats: Vec<ShaderStats>,
    /// With `--count-rays`: the rays of one frame by kind, counted in a
    /// separate untimed frame by the counting variant of the shader.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rays: Option<RayCounts>,
    /// With `--count-rays`: `rays.total` / the median frame time, in billions
    /// of rays per second; `grays_clock` says which median (GPU, or wall
    /// where the run has no GPU timer).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grays_per_s: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grays_clock: Option<RateClock>,
    /// Where the run traced through a BVH: how long building it took, a step
    /// of the setup of its own (absent without a BVH).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bvh_ms: Option<f64>,
    /// The BVH's nodes and its SAH cost (the builder's own costs, relative to
    /// the root's area: lower traces faster), where the run built one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bvh_nodes: Option<usize>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bvh_sah_cost: Option<f64>,
    /// The BVH's children per node (2, 4 or 8: `--accel bvh`, `bvh4`, `bvh8`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bvh_width: Option<u32>,
}

/// One compiled stage and the figures its driver gives for it, as the driver
/// names them (registers, local memory, instructions...).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ShaderStats {
    /// "graphics", "compute" or "program".
    pub pipeline: String,
    /// The driver's name for the stage ("Fragment Shader", "NV assembly"...).
    pub stage: String,
    pub statistics: Vec<(String, String)>,
}

/// What an app says about its device, kept after the device is gone.
#[derive(Debug, Clone)]
pub struct DeviceInfo {
    pub device: String,
    pub driver: String,
    pub api_version: String,
}

/// Assembles a [`RunReport`]: who ran (api, device) and what (scene, variant)
/// up front, the rest by name; `build` fills the summaries. Every report is
/// made here, so the apps, the window and the reference cannot disagree on
/// what a field means.
#[must_use]
pub struct RunReportBuilder {
    report: RunReport,
}

impl RunReport {
    /// A report of a fragment-path run with no frames yet (see [`RunReportBuilder`]).
    pub fn builder(
        api: &str,
        info: DeviceInfo,
        scene: SceneStats,
        variant: String,
    ) -> RunReportBuilder {
        RunReportBuilder {
            report: RunReport {
                api: api.to_string(),
                device: info.device,
                driver: info.driver,
                api_version: info.api_version,
                os: os_description(),
                scene,
                variant,
                width: 0,
                height: 0,
                path: RenderPath::Fragment,
                workgroup: None,
                frames: Vec::new(),
                gpu_ms: None,
                wall_ms: None,
                nonfinite_pixels: 0,
                setup_ms: 0.0,
                validation_messages: 0,
                shader_stats: Vec::new(),
                rays: None,
                grays_per_s: None,
                grays_clock: None,
                bvh_ms: None,
                bvh_nodes: None,
                bvh_sah_cost: None,
                bvh_width: None,
            },
        }
    }

    /// The one JSON line on stdout that `--json` promises.
    pub fn print_json(&self) -> anyhow::Result<()> {
        let line = serde_json::to_string(self)
            .map_err(|e| anyhow::anyhow!("serialising the JSON report: {e}"))?;
        println!("{line}");
        Ok(())
    }

    /// Adds the counting frame's rays (`--count-rays`) and the rate they give.
    pub fn add_rays(&mut self, kinds: RayKinds) {
        self.set_rays(kinds.counts());
    }

    /// Sets the frame's rays (counted by another run of the same scene and
    /// size: both paths trace the same rays) and the rate they give.
    pub fn set_rays(&mut self, counts: RayCounts) {
        self.rays = Some(counts);
        self.summarise();
    }

    /// Fills the summaries from `frames`.
    pub fn summarise(&mut self) {
        // Frames marked as warm-up stay out; unmarked reports (older ones,
        // tests) keep the study's tail.
        let marked = self.frames.iter().any(|f| f.warmup);
        let stats = |v: &[f64]| {
            if marked {
                summarize_all(v)
            } else {
                summarize(v)
            }
        };
        let timed = || self.frames.iter().filter(|f| !marked || !f.warmup);
        let wall: Vec<f64> = timed().map(|f| f.wall_ms).collect();
        self.wall_ms = stats(&wall);
        let gpu: Option<Vec<f64>> = timed().map(|f| f.gpu_ms).collect();
        self.gpu_ms = gpu.and_then(|g| stats(&g));
        if let Some(rays) = &self.rays {
            let (clock, median) = match (&self.gpu_ms, &self.wall_ms) {
                (Some(g), _) => (RateClock::Gpu, g.median),
                (None, Some(w)) => (RateClock::Wall, w.median),
                (None, None) => return,
            };
            self.grays_per_s = Some(grays_per_s(rays.total, median));
            self.grays_clock = Some(clock);
        }
    }
}

impl RunReportBuilder {
    /// The image size.
    pub fn size(mut self, width: u32, height: u32) -> Self {
        self.report.width = width;
        self.report.height = height;
        self
    }

    /// The entry point that traced; the workgroup is reported for compute only.
    pub fn path(mut self, path: RenderPath, workgroup: Workgroup) -> Self {
        self.report.path = path;
        self.report.workgroup = (path == RenderPath::Compute).then(|| workgroup.to_string());
        self
    }

    /// The timed frames and the setup time before the first.
    pub fn frames(mut self, frames: Vec<FrameTime>, setup_ms: f64) -> Self {
        self.report.frames = frames;
        self.report.setup_ms = setup_ms;
        self
    }

    /// Pixels of the last frame with a NaN or infinite channel.
    pub fn nonfinite_pixels(mut self, count: u64) -> Self {
        self.report.nonfinite_pixels = count;
        self
    }

    /// Messages from the validation layer or GL debug output.
    pub fn validation_messages(mut self, count: u64) -> Self {
        self.report.validation_messages = count;
        self
    }

    /// What the driver reported of the compiled shaders (`--dump-shaders`).
    pub fn shader_stats(mut self, stats: Vec<ShaderStats>) -> Self {
        self.report.shader_stats = stats;
        self
    }

    /// The BVH's build time, node count and SAH cost, where the run built one.
    pub fn bvh(mut self, bvh: Option<&crate::gpu::layout::Bvh>, ms: Option<f64>) -> Self {
        self.report.bvh_ms = ms;
        self.report.bvh_nodes = bvh.map(|b| b.node_count());
        self.report.bvh_sah_cost = bvh.map(|b| b.sah_cost());
        self.report.bvh_width = bvh.map(|b| b.width.max(2));
        self
    }

    /// As `bvh`, from figures kept after the tree is gone (a window's first scene).
    pub fn bvh_figures(mut self, ms: Option<f64>, figures: Option<(usize, f64)>) -> Self {
        self.report.bvh_ms = ms;
        self.report.bvh_nodes = figures.map(|f| f.0);
        self.report.bvh_sah_cost = figures.map(|f| f.1);
        self
    }

    /// The report, with its summaries filled from the frames.
    pub fn build(mut self) -> RunReport {
        self.report.summarise();
        self.report
    }
}

/// Writes what `--dump-shaders DIR` promises of naga's output: the SPIR-V and
/// the GLSL of each stage this run compiled, named `<stage>.spv` and
/// `<stage>.glsl`, and the source of each as one file an external compiler
/// takes (`<stage>.source.glsl`: the variant's defines, then the tracer's parts
/// put together). The apps add what their driver reports.
pub fn dump_shaders(dir: &std::path::Path, stages: &[&Stage]) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| {
        crate::error::bad_input(format!(
            "--dump-shaders '{}': the folder cannot be created ({e})",
            dir.display()
        ))
    })?;
    for stage in stages {
        let name = stage.name;
        dump_file(
            dir,
            &format!("{name}.spv"),
            bytemuck::cast_slice(&stage.spirv),
        )?;
        dump_file(dir, &format!("{name}.glsl"), stage.glsl.as_bytes())?;
        dump_file(dir, &format!("{name}.source.glsl"), stage.source.as_bytes())?;
    }
    Ok(())
}

/// The timed loop both apps run, one iteration = submit + wait, as the 2018
/// study measured: `frame` submits and waits, the wall clock runs around it,
/// then `gpu_ms` reads the GPU's own time of that frame. `setup_ms` runs from
/// `started` (first thing in main) to the first frame. The first frame is an
/// `--explain` step titled `title`.
pub fn timed_frames(
    plan: FramePlan,
    started: std::time::Instant,
    title: &str,
    mut frame: impl FnMut() -> anyhow::Result<()>,
    mut gpu_ms: impl FnMut() -> anyhow::Result<Option<f64>>,
) -> anyhow::Result<(Vec<FrameTime>, f64)> {
    let mut frames: Vec<FrameTime> = Vec::with_capacity(plan.cap.min(4096) as usize);
    let mut setup_ms = 0.0;
    // A fixed count warms up as the study did; a settling run until
    // FramePlan::warmup_over says so.
    let fixed_warmup = study_warmup(plan.cap as usize);
    let mut warming = true;
    let mut first_start = None;
    // The clock the stopping rule reads: GPU time while every timed frame
    // has it, wall time otherwise (as the reports choose).
    let mut timed_gpu: Option<Vec<f64>> = Some(Vec::new());
    let mut timed_wall: Vec<f64> = Vec::new();
    for i in 0..plan.cap as usize {
        let t0 = std::time::Instant::now();
        if i == 0 {
            setup_ms = (t0 - started).as_secs_f64() * 1e3;
        }
        let first = *first_start.get_or_insert(t0);
        frame()?;
        let wall_ms = t0.elapsed().as_secs_f64() * 1e3;
        let gpu_ms = gpu_ms()?;
        let warmup = match plan.settle {
            None => i < fixed_warmup,
            Some(_) => warming,
        };
        frames.push(FrameTime {
            gpu_ms,
            wall_ms,
            warmup,
        });
        if i == 0 {
            // The frames are the walkthrough's step 11 in both APIs.
            crate::explain::numbered(11, title, || {
                let gpu = gpu_ms.map_or("no GPU time".into(), |g| format!("GPU {g:.3} ms"));
                format!("wall {wall_ms:.3} ms, {gpu}; later frames repeat the same work")
            });
        }
        if warmup {
            let elapsed = first.elapsed().as_secs_f64() * 1e3;
            warming = !plan.warmup_over(i + 1, elapsed);
            continue;
        }
        timed_wall.push(wall_ms);
        timed_gpu = timed_gpu.and_then(|mut v| {
            v.push(gpu_ms?);
            Some(v)
        });
        if plan.settled(timed_gpu.as_deref().unwrap_or(&timed_wall)) {
            break;
        }
    }
    Ok((frames, setup_ms))
}

/// Writes one file of `--dump-shaders DIR`. A failure (a full disk, a
/// read-only place) is bad input (exit 2) naming the folder: the user chose it.
pub fn dump_file(dir: &std::path::Path, name: &str, bytes: &[u8]) -> anyhow::Result<()> {
    std::fs::write(dir.join(name), bytes).map_err(|e| {
        crate::error::bad_input(format!(
            "--dump-shaders '{}': '{name}' cannot be written there ({e})",
            dir.display()
        ))
    })
}

/// Writes the driver's figures beside the dumped shaders as `statistics.json`.
pub fn dump_statistics(dir: &std::path::Path, stats: &[ShaderStats]) -> anyhow::Result<()> {
    use anyhow::Context;
    let text = serde_json::to_string_pretty(stats).context("serialising shader statistics")?;
    dump_file(dir, "statistics.json", text.as_bytes())
}

/// "Debian GNU/Linux 12 (bookworm), Linux 6.1" — for reports.
pub fn os_description() -> String {
    let pretty = std::fs::read_to_string("/etc/os-release")
        .ok()
        .and_then(|t| {
            t.lines().find_map(|l| {
                l.strip_prefix("PRETTY_NAME=")
                    .map(|v| v.trim_matches('"').to_string())
            })
        })
        .unwrap_or_else(|| std::env::consts::OS.to_string());
    let kernel = std::fs::read_to_string("/proc/sys/kernel/osrelease")
        .map(|s| s.trim().to_string())
        .unwrap_or_default();
    if kernel.is_empty() {
        pretty
    } else {
        format!("{pretty}, Linux {kernel}")
    }
}
