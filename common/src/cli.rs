//! The apps' whole configuration surface: the options both apps accept, parsed
//! by one clap struct so that `twinray-vk` and `twinray-gl` can never drift
//! apart (docs/architecture.md, the command-line contract), and each app's own knobs, which are options too and are also read
//! from `TWINRAY_*` environment variables (so that a script or the orchestrator
//! can set them for every run). Everything is parsed once, in `main`.

use crate::error::bad_input;
use crate::lab::experiment::{Experiment, UlpOp};
use crate::scene::accel::Accel;
use crate::value_name::ValueName;
use clap::builder::{PossibleValue, TypedValueParser};
use clap::parser::ValueSource;
use clap::{Parser, ValueEnum};
use std::path::PathBuf;

pub mod files;
mod values;

use values::parse_settle;
pub use values::{parse_frames, parse_seconds, parse_size, parse_workgroup};

// A hidden option (`hide = true`) is the laboratory's: its doc comment is its
// row of the laboratory's page (`lab::measurement_options`, docs/experiments.md).
#[derive(Parser, Debug, Clone, PartialEq)]
pub struct RenderArgs {
    /// Built-in scene (teapot, box, spherelist) or a path to a scene file (.toml).
    // The path hint makes it an input of `files`'s check of outputs against inputs.
    #[arg(long, default_value = "box", value_hint = clap::ValueHint::FilePath)]
    pub scene: String,
    /// Image size as WxH.
    // Hyphen values reach parse_size, so `-64x48` is refused as a size, not as an unknown option.
    #[arg(long, default_value = "800x600", value_parser = parse_size, allow_hyphen_values = true)]
    pub size: Size,
    /// Render offscreen, without a window.
    #[arg(long)]
    pub headless: bool,
    /// Frames to render, then exit (headless default: 1).
    // Hyphen values reach parse_frames, so `-1` is refused as a count, not as an unknown option.
    #[arg(long, value_parser = parse_frames, allow_hyphen_values = true)]
    pub frames: Option<u32>,
    /// Headless: stop once the median frame time's 95 % confidence interval
    /// lies within ±PCT % of it (after a warm-up, at least 6 timed frames);
    /// --frames is then the cap [default cap: 60].
    #[arg(long, value_name = "PCT", value_parser = parse_settle, allow_hyphen_values = true, requires = "headless")]
    pub settle: Option<f64>,
    /// Save the last frame as PNG (top row first, same orientation in both APIs).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print one JSON object describing the run on stdout.
    #[arg(long)]
    pub json: bool,
    /// Count the rays of one frame by kind, in an extra untimed frame of the
    /// shader's counting variant: adds `rays` and `grays_per_s` to `--json`.
    #[arg(long)]
    pub count_rays: bool,
    /// Scene parameter override KEY=VALUE (repeatable), e.g. extra_spheres=2500, max_depth=3.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Vulkan: require validation layers and fail on any message. OpenGL: debug context, fail on any error.
    #[arg(long)]
    pub validate: bool,
    /// Render with the all-features shader instead of the scene's own variant.
    #[arg(long, hide = true)]
    pub generic: bool,
    /// Render with one shader for every scene whose feature switches are
    /// specialization constants set to this scene's features (fixed by naga's
    /// process_overrides), instead of the scene's own variant of defines.
    #[arg(long, conflicts_with = "generic", hide = true)]
    pub specialize: bool,
    /// Acceleration structure: auto (for scenes with many primitives a BVH, 4-wide: the
    /// faster tree on the H100 in both APIs), none (test every
    /// primitive, as the 2018 study did), bvh (two children a node), bvh4 or bvh8 (the same
    /// tree collapsed to four or eight children a node).
    #[arg(long, value_enum, default_value_t = Accel::Auto)]
    pub accel: Accel,
    /// OpenGL, headless: load naga's SPIR-V through GL_ARB_gl_spirv instead of naga's GLSL,
    /// so that both APIs run the very same shader binary (isolates the compiler path).
    #[arg(long, hide = true)]
    pub gl_spirv: bool,
    /// Windowed: wait for the display's refresh (Vulkan FIFO, OpenGL swap interval 1).
    /// Without it the frame rate is uncapped (MAILBOX or IMMEDIATE, swap interval 0).
    #[arg(long)]
    pub vsync: bool,
    /// Print every API object on stderr as it is created, in order, with the
    /// parameters that matter and the time each step took.
    #[arg(long)]
    pub explain: bool,
    /// Which entry point runs the tracer: a fullscreen fragment shader, or the same
    /// tracer as a compute shader writing a storage image.
    #[arg(long, value_enum, default_value_t = RenderPath::Fragment)]
    pub path: RenderPath,
    /// Compute path only: the workgroup size WxH (e.g. 8x4, 4x8, 8x16) [default: 8x4; for BVH walks 8x16 in Vulkan, 4x8 in OpenGL].
    #[arg(long, value_name = "WxH", value_parser = parse_workgroup)]
    pub workgroup: Option<Workgroup>,
    /// Compute path: declare 1-32 KiB of workgroup memory that the tracer does
    /// not need (each invocation writes and reads one word of it), to see how
    /// the driver's split of each multiprocessor's memory between shared memory
    /// and L1 cache, and its occupancy, move the time.
    #[arg(long, value_name = "KIB", value_parser = clap::value_parser!(u32).range(1..=32), hide = true)]
    pub shared_pad: Option<u32>,
    /// Repeatable: one of the experiments (`--experiments` lists them), each of
    /// which puts back a cost the build removes (or moves one) to measure its effect.
    #[arg(long, value_enum, value_name = "NAME", hide = true)]
    pub experiment: Vec<Experiment>,
    /// With `--experiment ulp`: the f32 operation the arithmetic probe
    /// measures (`twinray ulp --help` lists them).
    #[arg(long, value_enum, value_name = "OP", hide = true)]
    pub ulp_op: Option<UlpOp>,
    /// Print the laboratory's page (its experiments and measurement options,
    /// docs/experiments.md) and exit.
    #[arg(long)]
    pub experiments: bool,
    /// Write the shaders this run compiles (naga's SPIR-V and GLSL) and what
    /// the driver reports of them (OpenGL's program binary, Vulkan's pipeline
    /// executable statistics where offered) into this folder.
    #[arg(long, value_name = "DIR")]
    pub dump_shaders: Option<PathBuf>,
}
/// The tracer's entry point: the two ways one GLSL tracer reaches the GPU.
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    Eq,
    Hash,
    Default,
    clap::ValueEnum,
    serde::Serialize,
    serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum RenderPath {
    /// One fullscreen triangle; the fragment shader traces (shaders/trace.frag).
    #[default]
    Fragment,
    /// A compute dispatch over the image; each invocation traces (shaders/trace.comp).
    Compute,
}

impl std::fmt::Display for RenderPath {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.name())
    }
}

/// A compute workgroup size (local_size_x x local_size_y; z is 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Workgroup {
    pub x: u32,
    pub y: u32,
}

impl Workgroup {
    /// The sizes the comparison measures.
    pub const MEASURED: [Workgroup; 6] = [
        Workgroup { x: 8, y: 4 },
        Workgroup { x: 4, y: 8 },
        Workgroup { x: 8, y: 8 },
        Workgroup { x: 8, y: 16 },
        Workgroup { x: 16, y: 8 },
        Workgroup { x: 16, y: 16 },
    ];

    /// The tiles across and down of a `width`×`height` image in workgroups
    /// of this size: the dispatch, whose edge tiles overhang the image.
    pub fn tiles(self, (width, height): (u32, u32)) -> (u32, u32) {
        (width.div_ceil(self.x), height.div_ceil(self.y))
    }
}

impl std::fmt::Display for Workgroup {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}x{}", self.x, self.y)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Size {
    pub width: u32,
    pub height: u32,
}

impl std::fmt::Display for Size {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}x{}", self.width, self.height)
    }
}

impl RenderArgs {
    /// A headless run of `scene` at `size` with every other option at its default.
    pub fn headless(scene: &str, size: Size) -> RenderArgs {
        RenderArgs {
            scene: scene.to_string(),
            size,
            headless: true,
            frames: None,
            settle: None,
            out: None,
            json: false,
            count_rays: false,
            set: Vec::new(),
            validate: false,
            generic: false,
            specialize: false,
            accel: Accel::Auto,
            gl_spirv: false,
            vsync: false,
            explain: false,
            path: RenderPath::Fragment,
            workgroup: None,
            shared_pad: None,
            experiment: Vec::new(),
            ulp_op: None,
            experiments: false,
            dump_shaders: None,
        }
    }

    /// The `--workgroup` of a compute run, None for the app's default
    /// (`Api::default_workgroup`). A `--workgroup` with the fragment path is a
    /// mistake worth saying, not ignoring.
    pub fn compute_workgroup(&self) -> anyhow::Result<Option<Workgroup>> {
        if self.path == RenderPath::Fragment && self.workgroup.is_some() {
            return Err(bad_input("--workgroup applies to --path compute only"));
        }
        if self.path == RenderPath::Fragment && self.shared_pad.is_some() {
            return Err(bad_input("--shared-pad applies to --path compute only"));
        }
        Ok(self.workgroup)
    }

    pub fn frame_count(&self) -> u32 {
        self.frames.unwrap_or(1)
    }

    /// The headless loop's frames: `--frames` alone, or with `--settle` a cap
    /// (60, the study's count, unless `--frames` gives one).
    pub fn frame_plan(&self) -> crate::stats::FramePlan {
        match self.settle {
            Some(pct) => crate::stats::FramePlan {
                cap: self.frames.unwrap_or(60),
                settle: Some(pct / 100.0),
            },
            None => crate::stats::FramePlan::fixed(self.frame_count()),
        }
    }

    /// The `--set` pairs split into (key, value).
    pub fn overrides(&self) -> anyhow::Result<Vec<(String, String)>> {
        self.set
            .iter()
            .map(|kv| {
                kv.split_once('=')
                    .map(|(k, v)| (k.trim().to_string(), v.trim().to_string()))
                    .ok_or_else(|| bad_input(format!("--set '{kv}' is not KEY=VALUE")))
            })
            .collect()
    }

    /// Checks every output path (`--out`) before any work: a typo must not cost a render.
    pub fn check_outputs(&self) -> anyhow::Result<()> {
        if let Some(out) = &self.out {
            crate::reference::image_io::check_output_file("--out", out)?;
            files::check_output("--out", out, &self.scene)?;
        }
        Ok(())
    }
}

/// Parses argv (and the knobs' environment variables), mapping clap's usage
/// errors to exit code 2 (clap already prints one clear line naming the
/// option), then refuses an output that names an input (`files`), before any work.
pub fn parse_or_exit<T: Parser>() -> T {
    // The binary's own name (twinray-vk, twinray-gl), as its other errors say it.
    let program = std::env::current_exe()
        .ok()
        .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .unwrap_or_else(|| "twinray".to_string());
    let cmd = T::command();
    let matches = cmd.clone().try_get_matches();
    let parsed = matches.and_then(|m| {
        if let Err(e) = files::check_command(&cmd, &m) {
            crate::error::exit_with(&program, e);
        }
        T::from_arg_matches(&m)
    });
    match parsed {
        Ok(a) => a,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            std::process::exit(code);
        }
    }
}

/// An app's command line: the shared options and that app's knobs.
#[derive(Parser, Debug, Clone)]
pub struct AppCli<K: clap::Args> {
    #[command(flatten)]
    pub render: RenderArgs,
    #[command(flatten)]
    pub knobs: K,
}

/// `twinray-vk`'s command line.
pub type VulkanCli = AppCli<VulkanKnobs>;
/// `twinray-gl`'s command line.
pub type OpenGlCli = AppCli<OpenGlKnobs>;

// The knobs are each app's own: the other app never reads them, so a Vulkan
// knob set for a whole comparison cannot stop the OpenGL runs, as before.

/// Vulkan-only choices, for picking a device and for reproducing the naive
/// choices the comparison measures.
#[derive(clap::Args, Debug, Clone, Default, PartialEq)]
#[command(next_help_heading = "Vulkan knobs (also read from the environment)")]
pub struct VulkanKnobs {
    /// The Vulkan device: an index or part of its name [default: the most
    /// capable kind present: discrete, integrated, virtual, then CPU].
    #[arg(
        long = "vk-device",
        env = "TWINRAY_VK_DEVICE",
        value_name = "INDEX|NAME",
        value_parser = named_in_env(clap::builder::StringValueParser::new())
    )]
    pub device: Option<String>,
    /// Where the scene's buffers live: device-local memory filled through a
    /// staging buffer (the careful choice), or host-visible memory the GPU
    /// reads across the bus (the naive one, to measure what it costs).
    #[arg(
        long = "vk-memory",
        env = "TWINRAY_VK_MEMORY",
        value_enum,
        value_parser = named_in_env(clap::builder::EnumValueParser::<SceneMemory>::new()),
        default_value_t = SceneMemory::Device,
        hide = true
    )]
    pub memory: SceneMemory,
    /// Turn the validation layer on without failing on its messages (with a
    /// note, not an error, where it is not installed); --validate requires it.
    #[arg(
        long = "vk-validation",
        env = "TWINRAY_VK_VALIDATION",
        value_parser = named_in_env(clap::builder::BoolishValueParser::new())
    )]
    pub validation: bool,
    /// How each headless frame is waited for: its fence, or vkQueueWaitIdle +
    /// vkDeviceWaitIdle as the 2018 study did.
    #[arg(
        long = "vk-wait",
        env = "TWINRAY_VK_WAIT",
        value_enum,
        value_parser = named_in_env(clap::builder::EnumValueParser::<FrameWait>::new()),
        default_value_t = FrameWait::Fence,
        hide = true
    )]
    pub wait: FrameWait,
    /// Record the barriers with Vulkan 1.3's synchronization2
    /// (vkCmdPipelineBarrier2, vkQueueSubmit2) instead of Vulkan 1.0's calls:
    /// the same named accesses, each barrier with its own, finer stages.
    #[arg(
        long = "vk-sync2",
        env = "TWINRAY_VK_SYNC2",
        value_parser = named_in_env(clap::builder::BoolishValueParser::new())
    )]
    pub sync2: bool,
}

impl VulkanKnobs {
    /// The device asked for; empty counts as none, so that a script can pass
    /// an unset variable through.
    pub fn device(&self) -> Option<&str> {
        self.device
            .as_deref()
            .map(str::trim)
            .filter(|d| !d.is_empty())
    }
}

/// Where the Vulkan app places the scene's buffers (`--vk-memory`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum SceneMemory {
    /// Device-local, filled once through a staging buffer.
    #[default]
    Device,
    /// Host-visible: every GPU access crosses the bus.
    Host,
}

/// How the Vulkan app waits for a headless frame (`--vk-wait`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum FrameWait {
    /// The frame's fence: waits for this frame's work only.
    #[default]
    Fence,
    /// vkQueueWaitIdle + vkDeviceWaitIdle, as the 2018 study did.
    Idle,
}

/// OpenGL-only choices.
#[derive(clap::Args, Debug, Clone, Default, PartialEq)]
#[command(next_help_heading = "OpenGL knobs (also read from the environment)")]
pub struct OpenGlKnobs {
    /// The EGL device index, headless [default: hardware devices first, then
    /// Mesa's software one].
    #[arg(
        long = "gl-device",
        env = "TWINRAY_GL_DEVICE",
        value_name = "INDEX",
        value_parser = named_in_env(parse_index)
    )]
    pub device: Option<usize>,
}

fn parse_index(s: &str) -> Result<usize, String> {
    s.trim()
        .parse()
        .map_err(|_| "not a device index (0, 1, ...)".to_string())
}

/// Wraps a knob's value parser so that a bad value read from the environment
/// is named by its variable: clap's own message names the option, which the
/// user never typed.
pub fn named_in_env<P: TypedValueParser>(parser: P) -> NamedInEnv<P> {
    NamedInEnv(parser)
}

/// See [`named_in_env`].
#[derive(Clone)]
pub struct NamedInEnv<P>(P);

impl<P: TypedValueParser> TypedValueParser for NamedInEnv<P> {
    type Value = P::Value;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<Self::Value, clap::Error> {
        self.0.parse_ref(cmd, arg, value)
    }

    fn parse_ref_(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
        source: ValueSource,
    ) -> Result<Self::Value, clap::Error> {
        use clap::error::{ContextKind, ContextValue};
        self.0.parse_ref_(cmd, arg, value, source).map_err(|mut e| {
            let variable = arg.and_then(clap::Arg::get_env);
            if let (Some(variable), ValueSource::EnvVariable) = (variable, source) {
                // The clap message stays ("invalid value 'x' for '...'", the
                // possible values); only the culprit's name changes.
                let name = ContextValue::String(variable.to_string_lossy().into_owned());
                e.insert(ContextKind::InvalidArg, name);
            }
            e
        })
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        self.0.possible_values()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lab::experiment::Experiment;
    use crate::scene::numerics::{Offset, SphereTest, TriangleTest};
    use crate::scene::OriginMode;

    #[test]
    fn no_output_of_either_app_may_name_one_of_its_inputs() {
        use clap::CommandFactory;
        let dir = std::env::temp_dir().join(format!("twinray-cli-pairs-{}", std::process::id()));
        for cmd in [VulkanCli::command(), OpenGlCli::command()] {
            let failures = files::every_pair_refused(&cmd, &dir);
            assert!(failures.is_empty(), "{}", failures.join("\n"));
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    fn names<T: ValueEnum>() -> Vec<String> {
        T::value_variants().iter().map(ValueName::name).collect()
    }

    /// The names are in reports, CSV columns, variant labels and scripts:
    /// deriving them must keep every spelling.
    #[test]
    fn value_names_keep_their_spelling() {
        assert_eq!(names::<Accel>(), ["auto", "none", "bvh", "bvh4", "bvh8"]);
        assert_eq!(names::<RenderPath>(), ["fragment", "compute"]);
        assert_eq!(
            names::<Experiment>(),
            [
                "naga-zero-init",
                "naga-loop-bounding",
                "no-loop-bounding",
                "shared-bvh-stack",
                "local-bvh-stack",
                "split-ray-stack",
                "unpaired-bvh-stack",
                "capped-bvh-stack",
                "first-of-equals",
                "greedy-collapse",
                "walk-then-shade",
                "storage-nodes",
                "uniform-counts",
                "no-contraction",
                "float-controls",
                "glslang",
                "naga-aliasing",
                "warp-probe",
                "timed-barrier",
                "back-to-back",
                "row-order",
                "ulp"
            ]
        );
        assert_eq!(
            names::<crate::lab::experiment::UlpOp>(),
            [
                "bits",
                "add",
                "mul",
                "div",
                "sqrt",
                "inversesqrt",
                "pow",
                "fma",
                "min",
                "max",
                "clamp",
                "dot",
                "length",
                "normalize",
                "cross",
                "reflect",
                "refract"
            ]
        );
        assert_eq!(
            names::<Offset>(),
            ["ray", "normal", "normal-scaled", "ulp", "scale-aware"]
        );
        assert_eq!(names::<TriangleTest>(), ["moller-trumbore", "watertight"]);
        assert_eq!(names::<SphereTest>(), ["quadratic", "stable"]);
        assert_eq!(names::<OriginMode>(), ["local", "world"]);
        assert_eq!(names::<SceneMemory>(), ["device", "host"]);
        assert_eq!(names::<FrameWait>(), ["fence", "idle"]);
    }
}
