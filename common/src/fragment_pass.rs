//! The fullscreen pass as the fragment-path experiments shape it (`quad`,
//! `load-clear`, `rgba8`, Vulkan's `dynamic-viewport`) and the runs that
//! refuse an experiment of the pass or of the queue (`compute-queue`): one
//! place, so that Vulkan and OpenGL draw, clear and read back alike and say
//! the same sentence when they refuse.

use crate::cli::{Experiment, RenderArgs, RenderPath};
use crate::error::bad_input;
use crate::value_name::ValueName;

/// The define under which shaders/fullscreen.vert emits two triangles.
pub const QUAD_DEFINE: &str = "FULLSCREEN_QUAD";

/// What the fragment path's draw looks like outside the shaders.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FragmentPass {
    /// Two triangles covering the viewport exactly, instead of one oversized
    /// triangle clipped to it.
    pub quad: bool,
    /// The colour target cleared at the start of every frame's pass, instead
    /// of its old contents left undefined (every pixel is written anyway).
    pub clear: bool,
    /// An RGBA8 UNORM target (the GPU rounds to 8 bits) instead of RGBA32F.
    pub rgba8: bool,
    /// Vulkan: the viewport and scissor set while recording instead of fixed
    /// in the pipeline (OpenGL has no other kind).
    pub dynamic_viewport: bool,
}

impl FragmentPass {
    pub fn of(experiments: &[Experiment]) -> FragmentPass {
        FragmentPass {
            quad: experiments.contains(&Experiment::Quad),
            clear: experiments.contains(&Experiment::LoadClear),
            rgba8: experiments.contains(&Experiment::Rgba8),
            dynamic_viewport: experiments.contains(&Experiment::DynamicViewport),
        }
    }

    /// The vertices of the draw, which the vertex shader makes from their index.
    pub fn vertices(&self) -> u32 {
        if self.quad {
            6
        } else {
            3
        }
    }

    /// The render target's bytes per pixel.
    pub fn texel_bytes(&self) -> u64 {
        if self.rgba8 {
            4
        } else {
            16
        }
    }

    /// The render target's format as `--explain` and errors name it.
    pub fn format_name(&self) -> &'static str {
        if self.rgba8 {
            "RGBA8"
        } else {
            "RGBA32F"
        }
    }
}

/// Refuses, in one sentence (exit 2), an experiment this run cannot honour:
/// the pass's experiments need the headless fragment path, `compute-queue` the
/// headless compute path; `dynamic-viewport` and `compute-queue` are Vulkan's
/// alone (`vulkan` false: OpenGL, which has neither queues nor a viewport
/// fixed in advance); `naga-aliasing` and `warp-probe` (headless compute)
/// are OpenGL's alone, and `robust-access` needs a headless run.
pub fn check_experiments(args: &RenderArgs, vulkan: bool) -> anyhow::Result<()> {
    for e in &args.experiment {
        let name = e.name();
        let (path, not_in_opengl) = match e {
            Experiment::Quad | Experiment::LoadClear | Experiment::Rgba8 => {
                (RenderPath::Fragment, None)
            }
            Experiment::DynamicViewport => (
                RenderPath::Fragment,
                Some("OpenGL's viewport is always state set before the draw"),
            ),
            Experiment::ComputeQueue => (
                RenderPath::Compute,
                Some("OpenGL has no queues to choose from"),
            ),
            Experiment::WarpProbe if vulkan => {
                return Err(bad_input(format!(
                    "--experiment {name} is OpenGL only: Vulkan reports the register count that fixes its occupancy (--dump-shaders)"
                )));
            }
            Experiment::WarpProbe => (RenderPath::Compute, None),
            Experiment::NagaAliasing if vulkan => {
                return Err(bad_input(format!(
                    "--experiment {name} is OpenGL only: Vulkan's SPIR-V lets the driver assume that no two resources alias anyway"
                )));
            }
            Experiment::RobustAccess if !args.headless => {
                return Err(bad_input(format!(
                    "--experiment {name} is a headless measurement; run it with --headless"
                )));
            }
            _ => continue,
        };
        if let (false, Some(why)) = (vulkan, not_in_opengl) {
            return Err(bad_input(format!(
                "--experiment {name} is Vulkan only: {why}"
            )));
        }
        if args.path != path {
            return Err(bad_input(format!(
                "--experiment {name} applies to --path {path} only"
            )));
        }
        if !args.headless {
            return Err(bad_input(format!(
                "--experiment {name} is a headless measurement; run it with --headless"
            )));
        }
    }
    Ok(())
}
