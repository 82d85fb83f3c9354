//! The laboratory: every experiment as one entry of one registry — its name,
//! the API, path and mode it applies to, and what it does to the run plan
//! (shader knobs, passes over naga's output, the loops' counts) — plus the measurement options that only the laboratory
//! uses. One check (`check`) refuses what a run cannot do; one function
//! (`changes`) says what the chosen experiments change; `page` writes
//! docs/experiments.md from the registry. The apps never read the list of
//! experiments: they consume the plan these changes shaped.

pub mod experiment;

use crate::cli::{OpenGlKnobs, RenderArgs, RenderPath, VulkanKnobs};
use crate::error::bad_input;
use crate::plan::requests::Api;
use crate::shader::variant::{Counts, Passes, ShaderKnobs, SpirvCompiler};
use crate::value_name::ValueName;
use experiment::Experiment;

/// What a run's experiments change, gathered from the registry.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Changes {
    pub knobs: ShaderKnobs,
    pub passes: Passes,
    /// Where the loops' counts come from, if not baked in.
    pub counts: Option<Counts>,
    /// The wide collapse opens the first of equal-area boxes.
    pub first_of_equals: bool,
    /// The wide collapse opens the largest box until a node is full.
    pub greedy_collapse: bool,
    /// The frame's barrier inside the timed span.
    pub timed_barrier: bool,
    /// Each timed frame dispatches the tracer twice.
    pub back_to_back: bool,
    /// The compute path hands out its tiles in rows, not costliest first.
    pub row_order: bool,
    /// The experiments' names in registry order, for the variant's label.
    pub tags: Vec<String>,
}

/// One experiment: where it applies and what it does.
pub struct Entry {
    pub experiment: Experiment,
    /// The API it is confined to, with the reason the other cannot take it.
    pub only: Option<(Api, &'static str)>,
    /// The path it is confined to.
    pub path: Option<RenderPath>,
    /// Headless runs only (a measurement, not a way to look at the scene).
    pub headless: bool,
    /// What it does, for the page.
    pub what: &'static str,
    pub apply: fn(&mut Changes),
}

const fn entry(experiment: Experiment, what: &'static str, apply: fn(&mut Changes)) -> Entry {
    Entry {
        experiment,
        only: None,
        path: None,
        headless: false,
        what,
        apply,
    }
}

const VULKAN_OCCUPANCY: &str =
    "Vulkan reports the register count that fixes its occupancy (--dump-shaders)";
const VULKAN_ALIASING: &str =
    "Vulkan's SPIR-V lets the driver assume that no two resources alias anyway";

/// Every experiment, in the order of `Experiment` (which is the order of the
/// label's tags). A test holds the two to the same list.
pub const REGISTRY: &[Entry] = &[
    entry(Experiment::NagaZeroInit, "Keep naga's zero initialisers on function-local arrays.", |c| {
        c.passes.strip_zero_init = false
    }),
    entry(Experiment::NagaLoopBounding, "Keep naga's loop bounding (a 64-bit counter in every SPIR-V loop) on the BVH variants too.", |c| {
        c.passes.loop_bounding = Some(true)
    }),
    entry(Experiment::NoLoopBounding, "Drop naga's loop bounding from the brute-force variants too (naga-loop-bounding wins if both are given).", |c| {
        c.passes.loop_bounding.get_or_insert(false);
    }),
    entry(Experiment::SharedBvhStack, "Compute path: put the BVH stack in shared memory wherever it fits in 32 KiB per workgroup (the default keeps it local).", |c| {
        c.knobs.shared_bvh_stack = true
    }),
    entry(Experiment::LocalBvhStack, "A BVH stack local to each walk (closest hit, any hit) instead of one at module scope that both share.", |c| {
        c.knobs.local_bvh_stack = true
    }),
    entry(Experiment::SplitRayStack, "The ray stack as four arrays (origin, direction, weight, depth) instead of two of vec4 pairs.", |c| {
        c.knobs.split_ray_stack = true
    }),
    entry(Experiment::UnpairedBvhStack, "OpenGL's BVH stack one entry to a uvec2 on every tree, as Vulkan's is, instead of two entries to a uvec4 on trees of up to 32 entries (the default scenes'; deeper trees take the uvec2 form already): NVIDIA's OpenGL compiler reports 16 bytes for each element, twice the local memory (the teapot's tracer 496 B instead of 256 B), yet runs it on as many multiprocessors, with 24 warps each instead of 28. Vulkan's stack is that way already.", |c| {
        c.knobs.unpaired_bvh_stack = true
    }),
    entry(Experiment::CappedBvhStack, "The BVH stack at most 31 entries, the default teapot's, on deeper trees (the 307k-, 1.2M- and 4.9M-triangle teapots' need 40, 42 and 46), in each API's form for 31; a push that finds it full is dropped. A bet, not a bound: a walk that needs more loses a subtree, though those teapots' 1000² frames came out byte-identical on an H200. What the deep trees' stacks cost NVIDIA's OpenGL, whose driver runs a tracer on fewer multiprocessors as its local memory grows.", |c| {
        c.knobs.capped_bvh_stack = true
    }),
    entry(Experiment::FirstOfEquals, "The wide tree's collapse opens the first of equal-area boxes, as it did until the shallowest was preferred: the sphere list's identical spheres then give a 4-wide tree of 16 levels at 100k spheres instead of 10, and a BVH stack of 368 B instead of 224 B, past what lets NVIDIA's OpenGL use every multiprocessor.", |c| {
        c.first_of_equals = true
    }),
    entry(Experiment::GreedyCollapse, "The wide tree's collapse opens the largest box until a node is full, the greedy rule it had until the one of least SAH cost over the same leaves replaced it: with the builder's finer top the teapot's frames up to 5 % longer (the 1.2M- and 4.9M-triangle ones; the default teapot's 1 %) on an H200, and the default teapot's BVH stack 30 entries instead of 31.", |c| {
        c.greedy_collapse = true
    }),
    entry(Experiment::WalkThenShade, "OpenGL's BVH walks on the compute path shade a scene's one light after its shadow walk, through the lights' loop, as every scene did, instead of before it with the hit's secondary rays pushed first: the hit's normals, view direction and material then stay live across the walk, and NVIDIA's OpenGL holds 24 warps a multiprocessor on the sphere list instead of 28. Vulkan and brute force shade that way already.", |c| {
        c.knobs.walk_then_shade = true
    }),
    entry(Experiment::StorageNodes, "OpenGL's BVH walks over a wide tree read its nodes from their storage block, as Vulkan does and as every walk did, instead of through a buffer texture over the same buffer: NVIDIA's OpenGL then guards each read with a bounds check and clears its registers before the load. Vulkan, brute force, the binary tree and --gl-spirv read them that way already.", |c| {
        c.knobs.storage_nodes = true
    }),
    entry(Experiment::UniformCounts, "Read the primitive and light counts from the Frame uniform instead of baking them into the shader (what made lavapipe grow per frame).", |c| {
        c.counts = Some(Counts::Uniform)
    }),
    entry(Experiment::NoContraction, "Forbid the driver to fuse or reassociate float arithmetic: a NoContraction decoration on every float operation of the SPIR-V and `precise` on every float local of the GLSL.", |c| {
        c.passes.no_contraction = true
    }),
    entry(Experiment::FloatControls, "SPIR-V only: ask for the IEEE behaviour the driver may otherwise relax (SPV_KHR_float_controls: denormals preserved, signed zero, Inf and NaN preserved).", |c| {
        c.passes.float_controls = true
    }),
    entry(Experiment::Glslang, "The SPIR-V (what Vulkan runs) from Khronos' reference compiler, glslangValidator (on PATH; Debian's glslang-tools), given the same GLSL and defines, instead of from naga.", |c| {
        c.passes.compiler = SpirvCompiler::Glslang
    }),
    Entry {
        only: Some((Api::OpenGl, VULKAN_ALIASING)),
        ..entry(Experiment::NagaAliasing, "naga's buffer and image declarations as naga writes them, without the `restrict` (GLSL) or `Restrict` (SPIR-V) that tells the driver no two of them alias, which Vulkan's SPIR-V assumes anyway.", |c| {
            c.passes.restrict = false
        })
    },
    Entry {
        only: Some((Api::OpenGl, VULKAN_OCCUPANCY)),
        path: Some(RenderPath::Compute),
        headless: true,
        ..entry(Experiment::WarpProbe, "NVIDIA only: record the highest warp slot in use on each multiprocessor (GL_NV_shader_thread_group's gl_WarpIDNV), the occupancy that OpenGL's driver does not report.", |c| {
            c.passes.warp_probe = true
        })
    },
    Entry {
        path: Some(RenderPath::Compute),
        headless: true,
        ..entry(Experiment::TimedBarrier, "The barrier that orders a headless frame's image stores after the last frame's, inside the timed span in both APIs: Vulkan records its first timestamp before the barrier instead of after it, and OpenGL issues a glMemoryBarrier after its timer starts, where it otherwise issues none between headless frames (the glFinish that ends each frame has completed the last one).", |c| {
            c.timed_barrier = true
        })
    },
    Entry {
        path: Some(RenderPath::Compute),
        headless: true,
        ..entry(Experiment::BackToBack, "Each headless frame dispatches the tracer twice inside its timed span, with no barrier between the two (both write the same values). The second dispatch's workgroups start as the first one's finish, so the frame's time less the default frame's is one frame's tracing without what a lone dispatch adds: its start, and its end, where the GPU waits on the last workgroups' latency. The why step takes that difference (`twinray compare --only why`).", |c| {
            c.back_to_back = true
        })
    },
    Entry {
        path: Some(RenderPath::Compute),
        ..entry(Experiment::RowOrder, "The compute path's workgroups take the image's tiles in rows, top-down, as the dispatch numbers them, and read no launch order, instead of the costliest tiles first (a frame of 4096 tiles or more: each tile ranked by the rays that the reference traces for a sparse grid of its pixels, through the run's tree, before the first frame). A lone frame ends when its last workgroups do; in rows the box's mirror and glass spheres and the teapot's lower half launch last and run on an otherwise idle GPU. Every image is the same in either order.", |c| {
            c.row_order = true
        })
    },
    Entry {
        headless: true,
        // The operation comes from --ulp-op (`changes`), which `check` requires.
        ..entry(Experiment::Ulp, "The arithmetic probe (shaders/lab/ulp.glsl) in place of the tracer: each pair of pixels holds the 32 bits of one f32 result of the operation `--ulp-op OP` names, on inputs derived from the pixel's index by an integer hash; `twinray ulp` recomputes the inputs and compares each result with the f64 one (docs/architecture.md#the-gpus-arithmetic).", |_| {})
    },
];

/// Experiments that cannot be combined, each pair with why: the shader has
/// no variant for both (naga would refuse it, naming a macro the user never
/// wrote), or the tree has no collapse for both. A pair where one wins
/// (`naga-loop-bounding` over `no-loop-bounding`) is not here: its entry
/// says which.
pub const EXCLUSIVE: &[(Experiment, Experiment, &str)] = &[
    (
        Experiment::SharedBvhStack,
        Experiment::LocalBvhStack,
        "the BVH stack lives either in shared memory or in each walk",
    ),
    (
        Experiment::FirstOfEquals,
        Experiment::GreedyCollapse,
        "first-of-equals is already a greedy collapse, with its own rule for equal boxes",
    ),
];

/// The registry's entry for `e`.
pub fn entry_of(e: Experiment) -> &'static Entry {
    REGISTRY
        .iter()
        .find(|r| r.experiment == e)
        .expect("every experiment has an entry (a test checks)")
}

/// Refuses, in one sentence (exit 2), what this run cannot do: an experiment
/// outside its API, path or mode, and the measurement options where they do
/// not apply.
pub fn check(args: &RenderArgs, api: Api) -> anyhow::Result<()> {
    if args.gl_spirv && api == Api::Vulkan {
        return Err(bad_input(
            "--gl-spirv is an OpenGL option: Vulkan always runs naga's SPIR-V",
        ));
    }
    for (a, b, why) in EXCLUSIVE {
        if args.experiment.contains(a) && args.experiment.contains(b) {
            return Err(bad_input(format!(
                "--experiment {} with --experiment {}: {why}; drop one of them",
                a.name(),
                b.name()
            )));
        }
    }
    for e in &args.experiment {
        let (r, name) = (entry_of(*e), e.name());
        if let Some((only, why)) = r.only {
            if only != api {
                return Err(bad_input(format!(
                    "--experiment {name} is {} only: {why}",
                    only.name()
                )));
            }
        }
        if let Some(path) = r.path {
            if args.path != path {
                return Err(bad_input(format!(
                    "--experiment {name} applies to --path {path} only"
                )));
            }
        }
        if r.headless && !args.headless {
            return Err(bad_input(format!(
                "--experiment {name} is a headless measurement; run it with --headless"
            )));
        }
    }
    if api == Api::OpenGl && args.gl_spirv {
        if !args.headless {
            return Err(bad_input(
                "--gl-spirv is a headless measurement option; run it with --headless",
            ));
        }
        if args.experiment.contains(&Experiment::WarpProbe) {
            return Err(bad_input(
                "--gl-spirv with --experiment warp-probe: the probe is added to naga's GLSL, which --gl-spirv does not load; drop one of them",
            ));
        }
        if args.experiment.contains(&Experiment::Glslang) {
            return Err(bad_input(
                "--gl-spirv with --experiment glslang: glslang's SPIR-V is 1.3 for Vulkan 1.1, and OpenGL loads SPIR-V 1.0 only; drop one of them",
            ));
        }
    }
    check_ulp(args)?;
    if args.path == RenderPath::Fragment && args.shared_pad.is_some() {
        return Err(bad_input("--shared-pad applies to --path compute only"));
    }
    Ok(())
}

/// `--experiment ulp` and `--ulp-op` go together, and the probe's image must
/// reach the PNG as the shader wrote it: no counting frame (the probe writes
/// no ray counts), an even width (two pixels per result).
fn check_ulp(args: &RenderArgs) -> anyhow::Result<()> {
    let probe = args.experiment.contains(&Experiment::Ulp);
    match (probe, args.ulp_op) {
        (false, None) => return Ok(()),
        (false, Some(_)) => return Err(bad_input("--ulp-op applies to --experiment ulp only")),
        (true, None) => {
            return Err(bad_input(
                "--experiment ulp needs --ulp-op OP, the operation to measure",
            ))
        }
        (true, Some(_)) => {}
    }
    if args.count_rays {
        return Err(bad_input(
            "--experiment ulp with --count-rays: the probe traces no rays; drop --count-rays",
        ));
    }
    if args.size.width % 2 != 0 {
        return Err(bad_input(format!(
            "--size {}: --experiment ulp needs an even width (two pixels per result)",
            args.size
        )));
    }
    Ok(())
}

/// What the run's experiments and measurement options change, each applied
/// once, in registry order.
pub fn changes(args: &RenderArgs) -> Changes {
    let mut c = Changes::default();
    for r in REGISTRY {
        if args.experiment.contains(&r.experiment) {
            (r.apply)(&mut c);
            c.tags.push(r.experiment.name());
        }
    }
    c.knobs.shared_pad_kib = args.shared_pad;
    if args.experiment.contains(&Experiment::Ulp) {
        c.knobs.ulp = args.ulp_op;
    }
    c
}

/// The measurement options: laboratory switches that are options of their
/// own, hidden from the default `--help`. clap's definitions (common/src/cli.rs)
/// are the one source of their names and texts: (the option as typed, what it does).
pub fn measurement_options() -> Vec<(String, String)> {
    use clap::{Args, CommandFactory};
    let sets = [
        (None, RenderArgs::command()),
        (
            Some(Api::Vulkan),
            VulkanKnobs::augment_args(clap::Command::new("twinray-vk")),
        ),
        (
            Some(Api::OpenGl),
            OpenGlKnobs::augment_args(clap::Command::new("twinray-gl")),
        ),
    ];
    let mut options = Vec::new();
    for (api, command) in sets {
        for arg in command.get_arguments().filter(|a| a.is_hide_set()) {
            let Some(long) = arg.get_long() else {
                continue;
            };
            let mut what = arg
                .get_long_help()
                .or(arg.get_help())
                .map(|h| h.to_string())
                .unwrap_or_default();
            // clap drops a one-sentence doc comment's full stop; the page is prose.
            if !what.ends_with('.') {
                what.push('.');
            }
            if let Some(api) = api {
                let env = arg
                    .get_env()
                    .map(|v| format!(" (also {})", v.to_string_lossy()))
                    .unwrap_or_default();
                let (first, rest) = what.split_at(what.chars().next().map_or(0, char::len_utf8));
                what = format!("{}{env}: {}{rest}", api.name(), first.to_lowercase());
            }
            options.push((format!("--{long}{}", typed_value(arg)), what));
        }
    }
    options
}

/// What follows the option as a measurement types it: for a choice with a
/// default, the choices that change something; else its value's name.
fn typed_value(arg: &clap::Arg) -> String {
    if !arg.get_action().takes_values() {
        return String::new();
    }
    let default = arg.get_default_values();
    if !default.is_empty() {
        let others: Vec<String> = arg
            .get_possible_values()
            .iter()
            .map(|v| v.get_name().to_string())
            .filter(|v| !default.iter().any(|d| d.to_str() == Some(v.as_str())))
            .collect();
        if !others.is_empty() {
            return format!(" {}", others.join("|"));
        }
    }
    arg.get_value_names()
        .and_then(|names| names.first())
        .map(|n| format!(" {n}"))
        .unwrap_or_default()
}

/// `--experiments`: prints the laboratory's page; true when it did (the app then exits).
pub fn print_page_if_asked(args: &RenderArgs) -> bool {
    if args.experiments {
        print!("{}", page());
    }
    args.experiments
}

/// docs/experiments.md, generated from the registry (a test keeps the file equal).
pub fn page() -> String {
    let mut s = String::from(
        "# The laboratory: experiments and measurement options\n\n\
         <!-- Generated from common/src/lab/mod.rs; TWINRAY_UPDATE_DOCS=1 cargo test -p twinray-common lab rewrites it. -->\n\n\
         twinray's product is the tracer and its two apps. Each gap the comparison found between Vulkan and OpenGL \
         has an experiment that puts a cost back, or takes one away, so that its effect can be measured in both APIs. \
         None is needed to render correctly, and none appears in `--help`; `twinray-vk --experiments` prints this page. \
         The comparison's why step (`twinray compare`) runs them, and the findings pages \
         ([findings/](findings/README.md)) report what each one measured.\n\n\
         ## Measurement options\n\n| option | what it does |\n|---|---|\n",
    );
    for (name, what) in measurement_options() {
        s.push_str(&format!("| `{name}` | {what} |\n"));
    }
    s.push_str("\n## Experiments (`--experiment NAME`)\n\n| name | applies to | what it does |\n|---|---|---|\n");
    for r in REGISTRY {
        let mut scope = Vec::new();
        scope.push(match r.only {
            Some((api, _)) => format!("{} only", api.name()),
            None => "both APIs".to_string(),
        });
        if let Some(p) = r.path {
            scope.push(format!("{p} path"));
        }
        if r.headless {
            scope.push("headless".to_string());
        }
        s.push_str(&format!(
            "| `{}` | {} | {} |\n",
            r.experiment.name(),
            scope.join(", "),
            r.what
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::ValueEnum;

    #[test]
    fn the_registry_has_every_experiment_once_in_order() {
        let listed: Vec<Experiment> = REGISTRY.iter().map(|r| r.experiment).collect();
        assert_eq!(listed, Experiment::value_variants());
    }

    /// Every hidden option is on the page, typed as a measurement types it,
    /// with the text clap holds for it.
    #[test]
    fn the_measurement_options_are_the_hidden_options() {
        let options = measurement_options();
        let names: Vec<&str> = options.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(
            names,
            [
                "--generic",
                "--specialize",
                "--gl-spirv",
                "--shared-pad KIB",
                "--experiment NAME",
                "--ulp-op OP",
                "--vk-memory host",
                "--vk-wait idle",
            ]
        );
        for (name, what) in &options {
            assert!(what.len() > 40, "{name} has no text: {what:?}");
        }
        let vk_memory = &options[6].1;
        assert!(
            vk_memory.starts_with("Vulkan (also TWINRAY_VK_MEMORY): where"),
            "{vk_memory}"
        );
    }

    /// docs/experiments.md is the registry's page; TWINRAY_UPDATE_DOCS=1 rewrites it.
    #[test]
    fn the_experiments_page_is_the_registry() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/experiments.md");
        let expected = page();
        if std::env::var("TWINRAY_UPDATE_DOCS").is_ok_and(|v| v == "1") {
            std::fs::write(&path, &expected).unwrap();
        }
        let found = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(
            found == expected,
            "docs/experiments.md is not the registry's page; run\n  TWINRAY_UPDATE_DOCS=1 cargo test --release -p twinray-common lab"
        );
        for e in Experiment::value_variants() {
            assert!(found.contains(&format!("| `{}` |", e.name())), "{e:?}");
        }
    }
}
