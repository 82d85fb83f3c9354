//! The shader build: concatenates shaders/ (naga has no #include), picks the
//! scene's variant through defines (or, for comparison, through specialization
//! constants that naga's process_overrides fixes), validates the naga module
//! once, and writes SPIR-V for Vulkan and GLSL 450 core for OpenGL from that
//! same module — then takes out two costs naga adds on its own (see
//! `strip_local_array_zero_init` and `spv::Options::force_loop_bounding`).

use crate::cli::{Experiment, RenderArgs, ValueName, Workgroup};
use crate::numerics::Numerics;
use crate::scene::{Features, Scene, MAX_DEPTH_LIMIT};
use anyhow::{anyhow, Context};
use naga::back::{glsl, spv};
use naga::valid::{Capabilities, ModuleInfo, ValidationFlags, Validator};
use naga::{Module, ShaderStage};
use std::collections::BTreeMap;

/// The tracer as one source. naga has no `#include`, so this is the one place
/// that puts the parts of shaders/trace/ together, in the reading order that
/// trace.glsl's header lists; every variant, both APIs and both paths start
/// from it.
pub const TRACE_GLSL: &str = concat!(
    include_str!("../../shaders/trace/inputs.glsl"),
    include_str!("../../shaders/trace/intersect.glsl"),
    include_str!("../../shaders/trace/bvh.glsl"),
    include_str!("../../shaders/trace/hit.glsl"),
    include_str!("../../shaders/trace/secondary.glsl"),
    include_str!("../../shaders/trace.glsl"),
);
pub const TRACE_FRAG: &str = include_str!("../../shaders/trace.frag");
pub const FULLSCREEN_VERT: &str = include_str!("../../shaders/fullscreen.vert");
pub const TRACE_COMP: &str = include_str!("../../shaders/trace.comp");

/// The defines that select a shader variant. Same map → same module → same code
/// in both APIs. `numerics` is what its numerical defines encode, kept so that
/// the reference can be asked to take the same choices. `constants` are the
/// specialization constants of `Variant::specialized` (empty otherwise).
/// `experiments` undo the build's own optimisations, to measure them.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Variant {
    pub defines: BTreeMap<String, String>,
    pub numerics: Numerics,
    pub constants: BTreeMap<String, bool>,
    pub experiments: Vec<Experiment>,
}

/// The feature switches trace.glsl declares with `layout(constant_id = N)`
/// under SPECIALIZE: name and id (naga's process_overrides wants the id).
/// A test checks this table against the parsed module.
pub const SPEC_CONSTANTS: [(&str, u16); 4] = [
    ("SPEC_SPHERES", 0),
    ("SPEC_TRIANGLES", 1),
    ("SPEC_MIRROR", 2),
    ("SPEC_GLASS", 3),
];

impl Variant {
    /// Only what the scene needs: no triangle loop without triangles, no
    /// refraction code without glass, a ray stack sized to the scene's depth;
    /// and the scene's numerical choices (offset, triangle and sphere tests).
    pub fn for_scene(scene: &Scene) -> Variant {
        let mut v = Variant::from_features(scene.features(), scene.max_depth, scene.numerics);
        v.add_scene_data(scene);
        v
    }

    /// What every variant built for one scene bakes in: the primitive and light
    /// counts that bound the shader's loops (a bound read from a uniform made
    /// lavapipe compile and keep a new shader at every draw), and, with a BVH,
    /// a traversal stack exactly as deep as the built tree needs.
    fn add_scene_data(&mut self, scene: &Scene) {
        let mut set = |k: &str, v: String| self.defines.insert(k.to_string(), v);
        set("SPHERE_COUNT", format!("{}u", scene.spheres.len()));
        set("TRIANGLE_COUNT", format!("{}u", scene.triangles.len()));
        set("LIGHT_COUNT", format!("{}u", scene.lights.len()));
        if let Some(bvh) = scene.bvh_tree() {
            set("USE_BVH", "1".into());
            set("BVH_STACK", bvh.stack_entries().to_string());
        }
    }

    pub fn from_features(f: Features, max_depth: u32, numerics: Numerics) -> Variant {
        let mut defines = BTreeMap::new();
        let mut flag = |on: bool, name: &str| {
            if on {
                defines.insert(name.to_string(), "1".to_string());
            }
        };
        flag(f.spheres, "HAS_SPHERES");
        flag(f.triangles, "HAS_TRIANGLES");
        flag(f.mirror, "HAS_MIRROR");
        flag(f.glass, "HAS_GLASS");
        // Only glass makes the ray tree branch (reflected and refracted rays):
        // then the depth-first stack holds one pending ray per level. Without
        // glass a hit pushes at most one ray after popping one, so one slot
        // serves every max depth, and every max depth compiles to one shader.
        let stack = if f.glass { max_depth.max(1) + 1 } else { 1 };
        defines.insert("STACK_SIZE".into(), stack.to_string());
        for d in numerics.defines() {
            defines.insert(d.to_string(), "1".to_string());
        }
        Variant {
            defines,
            numerics,
            constants: BTreeMap::new(),
            experiments: Vec::new(),
        }
    }

    /// The specialization-constant alternative to `for_scene`, for comparison
    /// (`--specialize`): one source for every scene, with every feature and the
    /// deepest stack compiled in, whose feature switches are `constant_id`
    /// overrides set to the scene's features. naga's SPIR-V and GLSL writers
    /// take no overrides, so `parse` fixes them with process_overrides: the
    /// driver then sees constant branches where `for_scene` leaves no code. An
    /// array size cannot be an override, so the ray stack stays the deepest.
    pub fn specialized(scene: &Scene) -> Variant {
        let mut v = Variant::generic(scene.numerics);
        // trace.glsl defines every HAS_* itself under SPECIALIZE.
        v.defines.retain(|k, _| !k.starts_with("HAS_"));
        v.defines.insert("SPECIALIZE".into(), "1".into());
        v.add_scene_data(scene);
        let f = scene.features();
        for ((name, _), on) in
            SPEC_CONSTANTS
                .iter()
                .zip([f.spheres, f.triangles, f.mirror, f.glass])
        {
            v.constants.insert(name.to_string(), on);
        }
        v
    }

    /// The variant the apps render: `--generic`, `--specialize` or the scene's
    /// own; each traces through the BVH when the scene has one. The one place
    /// both apps (and the windowed ones) choose what to compile.
    pub fn chosen(scene: &Scene, args: &RenderArgs) -> Variant {
        let mut v = if args.generic {
            let mut v = Variant::generic(scene.numerics);
            v.add_scene_data(scene);
            v
        } else if args.specialize {
            Variant::specialized(scene)
        } else {
            Variant::for_scene(scene)
        };
        v.experiments = args.experiment.clone();
        v.experiments.sort();
        v.experiments.dedup();
        if v.defines.contains_key("USE_BVH") {
            if v.experiments.contains(&Experiment::StacklessBvh) {
                v.defines.insert("BVH_STACKLESS".into(), "1".into());
            }
            if v.experiments.contains(&Experiment::UnpairedBvhStack) {
                v.defines.insert("BVH_STACK_UNPAIRED".into(), "1".into());
            }
        }
        if v.experiments.contains(&Experiment::UniformCounts)
            || v.experiments.contains(&Experiment::StorageCounts)
        {
            for k in ["SPHERE_COUNT", "TRIANGLE_COUNT", "LIGHT_COUNT"] {
                v.defines.remove(k);
            }
        }
        if v.experiments.contains(&Experiment::StorageCounts) {
            v.defines.insert("COUNTS_FROM_STORAGE".into(), "1".into());
        }
        v
    }

    /// Every feature on, the deepest stack, the counts read from the `Frame`
    /// uniform: renders any scene (with the given numerics). The apps never run
    /// it as it is: `chosen` bakes the scene's counts into every variant.
    pub fn generic(numerics: Numerics) -> Variant {
        let all = Features {
            spheres: true,
            triangles: true,
            mirror: true,
            glass: true,
        };
        Variant::from_features(all, MAX_DEPTH_LIMIT, numerics)
    }

    /// Whether this variant can draw everything `needed` can: every feature of
    /// `needed` compiled in, and a ray stack at least as deep. A windowed app keeps
    /// its pipeline when `+`/`-` change the depth to one the current variant covers.
    pub fn covers(&self, needed: &Variant) -> bool {
        let stack = |v: &Variant| {
            v.defines
                .get("STACK_SIZE")
                .and_then(|s| s.parse::<u32>().ok())
                .unwrap_or(0)
        };
        needed
            .defines
            .keys()
            .filter(|k| k.starts_with("HAS_"))
            .all(|k| self.defines.contains_key(k))
            && stack(self) >= stack(needed)
            && self.constants == needed.constants
            && self.experiments == needed.experiments
            && [
                "SPHERE_COUNT",
                "TRIANGLE_COUNT",
                "LIGHT_COUNT",
                "USE_BVH",
                "BVH_STACK",
            ]
            .iter()
            .all(|k| self.defines.get(*k) == needed.defines.get(*k))
    }

    /// A short label such as `spheres+triangles+mirror+glass/stack6/normal-scaled/watertight/stable`
    /// (with `/bvhN` at the end when the variant traces through a BVH with an
    /// N-entry stack, then any `--experiment`).
    pub fn label(&self) -> String {
        let mut parts: Vec<String> = ["SPHERES", "TRIANGLES", "MIRROR", "GLASS"]
            .iter()
            .filter(|d| {
                self.defines.contains_key(&format!("HAS_{d}"))
                    || self.constants.get(&format!("SPEC_{d}")) == Some(&true)
            })
            .map(|d| d.to_lowercase())
            .collect();
        if parts.is_empty() {
            parts.push("background".into());
        }
        let bvh = match self.defines.get("BVH_STACK") {
            Some(n) => format!("/bvh{n}"),
            None => String::new(),
        };
        let spec = if self.constants.is_empty() {
            ""
        } else {
            "/spec"
        };
        let experiments: String = self
            .experiments
            .iter()
            .map(|e| format!("/{}", e.name()))
            .collect();
        format!(
            "{}/stack{}/{}{bvh}{spec}{experiments}",
            parts.join("+"),
            self.defines
                .get("STACK_SIZE")
                .map(String::as_str)
                .unwrap_or("?"),
            self.numerics.label()
        )
    }
}

/// The fragment source as naga sees it (also used by the layout test).
pub fn fragment_source() -> String {
    format!("#version 450\n{TRACE_GLSL}\n{TRACE_FRAG}")
}

/// The compute source as naga sees it: the same tracer, the compute entry point.
pub fn compute_source() -> String {
    format!("#version 450\n{TRACE_GLSL}\n{TRACE_COMP}")
}

/// Parses and validates one stage.
pub fn parse(
    source: &str,
    stage: ShaderStage,
    variant: &Variant,
) -> anyhow::Result<(Module, ModuleInfo)> {
    let mut options = naga::front::glsl::Options::from(stage);
    for (k, v) in &variant.defines {
        options.defines.insert(k.clone(), v.clone());
    }
    let module = naga::front::glsl::Frontend::default()
        .parse(&options, source)
        .map_err(|e| {
            anyhow!(
                "naga could not parse the {stage:?} shader:\n{}",
                e.emit_to_string(source)
            )
        })?;
    let info = Validator::new(ValidationFlags::all(), Capabilities::default())
        .validate(&module)
        .map_err(|e| {
            anyhow!(
                "naga rejected the {stage:?} shader:\n{}",
                e.emit_to_string(source)
            )
        })?;
    if module.overrides.is_empty() {
        return Ok((module, info));
    }
    // Neither writer takes overrides: fix them now, as a Vulkan driver would
    // at pipeline creation (ids as decimal keys, booleans as 0 or 1).
    let mut constants = naga::back::PipelineConstants::default();
    for (name, id) in SPEC_CONSTANTS {
        if let Some(&on) = variant.constants.get(name) {
            constants.insert(id.to_string(), if on { 1.0 } else { 0.0 });
        }
    }
    let (m, i) = naga::back::pipeline_constants::process_overrides(
        &module,
        &info,
        Some((stage, "main")),
        &constants,
    )
    .map_err(|e| {
        anyhow!("naga could not apply the {stage:?} shader's specialization constants: {e}")
    })?;
    Ok((m.into_owned(), i.into_owned()))
}

/// One variant, compiled for both APIs.
#[derive(Debug, Clone)]
pub struct Shaders {
    pub variant: Variant,
    pub vertex_spirv: Vec<u32>,
    pub fragment_spirv: Vec<u32>,
    pub vertex_glsl: String,
    pub fragment_glsl: String,
}

pub fn build(variant: &Variant) -> anyhow::Result<Shaders> {
    let (vm, vi) = parse(FULLSCREEN_VERT, ShaderStage::Vertex, variant)?;
    let (fm, fi) = parse(&fragment_source(), ShaderStage::Fragment, variant)?;
    Ok(Shaders {
        variant: variant.clone(),
        vertex_spirv: to_spirv(&vm, &vi, ShaderStage::Vertex, variant)?,
        fragment_spirv: to_spirv(&fm, &fi, ShaderStage::Fragment, variant)?,
        vertex_glsl: to_glsl(&vm, &vi, ShaderStage::Vertex, variant)?,
        fragment_glsl: to_glsl(&fm, &fi, ShaderStage::Fragment, variant)?,
    })
}

/// The tracer as a compute shader, for both APIs.
#[derive(Debug, Clone)]
pub struct ComputeShader {
    pub variant: Variant,
    pub workgroup: Workgroup,
    pub spirv: Vec<u32>,
    pub glsl: String,
}

/// The scene's variant plus the workgroup size, which reaches the shader as the
/// WG_X/WG_Y defines: `local_size` must be a constant, and a define keeps it out
/// of the specialisation-constant path naga's writers handle poorly.
pub fn build_compute(variant: &Variant, workgroup: Workgroup) -> anyhow::Result<ComputeShader> {
    let mut v = variant.clone();
    v.defines.insert("WG_X".into(), workgroup.x.to_string());
    v.defines.insert("WG_Y".into(), workgroup.y.to_string());
    if bvh_stack_in_shared_memory(variant, workgroup) {
        v.defines.insert("BVH_STACK_SHARED".into(), "1".into());
    }
    let (m, i) = parse(&compute_source(), ShaderStage::Compute, &v)?;
    Ok(ComputeShader {
        variant: v.clone(),
        workgroup,
        spirv: to_spirv(&m, &i, ShaderStage::Compute, &v)?,
        glsl: to_glsl(&m, &i, ShaderStage::Compute, &v)?,
    })
}

/// The most shared memory the compute path's BVH stack may take: OpenGL
/// guarantees a workgroup 32 KiB (Vulkan only 16 KiB, but lavapipe, llvmpipe
/// and NVIDIA offer 32 KiB or more). Only `--experiment shared-bvh-stack` uses it.
pub const SHARED_BVH_STACK_BUDGET: usize = 32 * 1024;

/// Whether the compute tracer keeps its BVH stack in shared memory: only with
/// `--experiment shared-bvh-stack`, and only where the stack fits in the budget.
pub fn bvh_stack_in_shared_memory(variant: &Variant, workgroup: Workgroup) -> bool {
    let Some(entries) = variant
        .defines
        .get("BVH_STACK")
        .and_then(|n| n.parse::<usize>().ok())
    else {
        return false;
    };
    let bytes = entries * (workgroup.x * workgroup.y) as usize * 8;
    variant.experiments.contains(&Experiment::SharedBvhStack) && bytes <= SHARED_BVH_STACK_BUDGET
}

pub fn to_spirv(
    module: &Module,
    info: &ModuleInfo,
    stage: ShaderStage,
    variant: &Variant,
) -> anyhow::Result<Vec<u32>> {
    // No ADJUST_COORDINATE_SPACE (y stays as written, see trace.frag) and no DEBUG,
    // so debug and release builds emit identical SPIR-V.
    //
    // naga's loop bounding gives every loop a 64-bit counter that breaks out
    // after 2^64 iterations, so that a driver cannot assume an infinite loop
    // away; the GLSL writer adds none, so it is a cost only Vulkan pays. Every
    // loop of trace.glsl ends (the stacks shrink, the primitive loops count up
    // to a constant), so it is never needed for correctness. Measured on an
    // H100 (comparison/results/nvidia-h100/FINDINGS.md), it costs the BVH
    // variants 4-17 % in Vulkan and the box 7 %, but without it NVIDIA's
    // Vulkan compiler, given the constant trip count of the brute-force sphere
    // loop, made the 10,000-sphere list 1.7x slower (227 ms against 135). So the
    // BVH variants go without it and the brute-force ones keep it, until the
    // counts reach the shader in a way no driver specialises on.
    let loop_bounding = if variant.experiments.contains(&Experiment::NagaLoopBounding) {
        true
    } else if variant.experiments.contains(&Experiment::NoLoopBounding) {
        false
    } else {
        !variant.defines.contains_key("USE_BVH")
    };
    let options = spv::Options {
        flags: spv::WriterFlags::LABEL_VARYINGS,
        force_loop_bounding: loop_bounding,
        ..Default::default()
    };
    let pipeline = spv::PipelineOptions {
        shader_stage: stage,
        entry_point: "main".into(),
    };
    let words = spv::write_vec(module, info, &options, Some(&pipeline))
        .with_context(|| format!("writing {stage:?} SPIR-V"))?;
    Ok(if variant.experiments.contains(&Experiment::NagaZeroInit) {
        words
    } else {
        strip_local_array_zero_init_spirv(&words)
    })
}

pub fn to_glsl(
    module: &Module,
    info: &ModuleInfo,
    stage: ShaderStage,
    variant: &Variant,
) -> anyhow::Result<String> {
    // naga renames blocks and members, so OpenGL binds by number: give every
    // resource its (set 0) binding explicitly. UBOs and SSBOs have separate
    // binding spaces in GL, so the numbers carry over unchanged.
    let mut binding_map = glsl::BindingMap::default();
    // The storage image (compute only) is bound to image unit 5, yet another
    // binding space in GL; 6 and 7 are the BVH's storage buffers.
    for b in 0..=crate::gpu::binding::LAST {
        binding_map.insert(
            naga::ResourceBinding {
                group: 0,
                binding: b,
            },
            b as u8,
        );
    }
    // The only workgroup memory is the BVH stack, written before it is read.
    let options = glsl::Options {
        version: glsl::Version::Desktop(450),
        writer_flags: glsl::WriterFlags::empty(),
        binding_map,
        zero_initialize_workgroup_memory: false,
    };
    let pipeline = glsl::PipelineOptions {
        shader_stage: stage,
        entry_point: "main".into(),
        multiview: None,
    };
    let mut out = String::new();
    let mut writer = glsl::Writer::new(
        &mut out,
        module,
        info,
        &options,
        &pipeline,
        Default::default(),
    )
    .with_context(|| format!("setting up the {stage:?} GLSL writer"))?;
    writer
        .write()
        .with_context(|| format!("writing {stage:?} GLSL"))?;
    Ok(if variant.experiments.contains(&Experiment::NagaZeroInit) {
        out
    } else {
        strip_local_array_zero_init_glsl(&out)
    })
}

// naga zero-initialises every function-local variable it writes, in both back
// ends: an `OpConstantNull` initialiser in SPIR-V, `T a[N] = T[N](0, ...)` in
// GLSL. For a scalar the driver drops the dead store; for an array it cannot
// prove every element is written before it is read, so it stores N zeros at
// every call: the tracer's ray stack at every pixel and the BVH stack at every
// traversal (128 stores into NVIDIA's local memory per traversal, 1.2-1.85x the
// BVH time on an H100). trace.glsl only reads stack entries below the stack
// pointer, each written by a push first, so the zeros are never read: both
// passes remove the initialisers of function-local arrays, and only those.
// trace.glsl gives no array an explicit initialiser (a test holds it to that),
// so every initialiser removed here is naga's.

/// Removes the `OpConstantNull` initialiser of every `Function`-storage
/// `OpVariable` whose type is an array.
pub fn strip_local_array_zero_init_spirv(words: &[u32]) -> Vec<u32> {
    const OP_TYPE_ARRAY: u32 = 28;
    const OP_TYPE_POINTER: u32 = 32;
    const OP_CONSTANT_NULL: u32 = 46;
    const OP_VARIABLE: u32 = 59;
    const STORAGE_FUNCTION: u32 = 7;
    let instructions = || spirv_instructions(words);
    let arrays: std::collections::HashSet<u32> = instructions()
        .filter(|i| i[0] & 0xffff == OP_TYPE_ARRAY && i.len() >= 2)
        .map(|i| i[1])
        .collect();
    let nulls: std::collections::HashSet<u32> = instructions()
        .filter(|i| i[0] & 0xffff == OP_CONSTANT_NULL && i.len() >= 3)
        .map(|i| i[2])
        .collect();
    let array_pointers: std::collections::HashSet<u32> = instructions()
        .filter(|i| {
            i[0] & 0xffff == OP_TYPE_POINTER
                && i.len() >= 4
                && i[2] == STORAGE_FUNCTION
                && arrays.contains(&i[3])
        })
        .map(|i| i[1])
        .collect();
    let mut out = words[..5.min(words.len())].to_vec();
    for i in instructions() {
        let strip = i[0] & 0xffff == OP_VARIABLE
            && i.len() == 5
            && i[3] == STORAGE_FUNCTION
            && array_pointers.contains(&i[1])
            && nulls.contains(&i[4]);
        if strip {
            out.push((4 << 16) | OP_VARIABLE);
            out.extend_from_slice(&i[1..4]);
        } else {
            out.extend_from_slice(i);
        }
    }
    out
}

/// The instructions of a SPIR-V module after its 5-word header; a malformed
/// tail is returned as one last slice so nothing is lost.
fn spirv_instructions(words: &[u32]) -> impl Iterator<Item = &[u32]> {
    let mut i = 5.min(words.len());
    std::iter::from_fn(move || {
        if i >= words.len() {
            return None;
        }
        let count = (words[i] >> 16) as usize;
        let end = if count == 0 || i + count > words.len() {
            words.len()
        } else {
            i + count
        };
        let inst = &words[i..end];
        i = end;
        Some(inst)
    })
}

/// Removes naga's zero initialiser from every function-local array declaration
/// (`    T name[N] = T[N](zeros);` becomes `    T name[N];`). Only initialisers
/// made of zero literals and constructors are touched.
pub fn strip_local_array_zero_init_glsl(glsl: &str) -> String {
    let mut out = String::with_capacity(glsl.len());
    for line in glsl.split_inclusive('\n') {
        match local_array_zero_init(line) {
            Some(decl) => {
                out.push_str(decl);
                out.push_str(";\n");
            }
            None => out.push_str(line),
        }
    }
    out
}

/// For an indented `T name[N] = T[N](...);` line whose initialiser holds only
/// zeros, the declaration part `    T name[N]`.
fn local_array_zero_init(line: &str) -> Option<&str> {
    let body = line.trim_end();
    if !line.starts_with(' ') || !body.ends_with(");") {
        return None;
    }
    let (decl, init) = body.split_once(" = ")?;
    let ty = decl.split_whitespace().next()?;
    let size = &decl[decl.find('[')?..];
    if !decl.ends_with(']') {
        return None;
    }
    let args = init
        .strip_prefix(&format!("{ty}{size}("))?
        .strip_suffix(");")?;
    let zeros_only = args
        .split(|c: char| "(), ".contains(c))
        .filter(|t| !t.is_empty())
        .all(|t| t == ty || t == "false" || is_glsl_type(t) || is_zero_literal(t));
    zeros_only.then_some(decl)
}

fn is_zero_literal(t: &str) -> bool {
    let digits = t.trim_end_matches(['u', 'f']);
    !digits.is_empty() && digits.chars().all(|c| c == '0' || c == '.') && digits.contains('0')
}

fn is_glsl_type(t: &str) -> bool {
    matches!(t, "float" | "int" | "uint" | "bool")
        || ["vec", "ivec", "uvec", "bvec", "mat"].iter().any(|p| {
            t.strip_prefix(p)
                .is_some_and(|n| n.chars().all(|c| c.is_ascii_digit() || c == 'x'))
        })
}

/// naga's Vulkan SPIR-V made loadable by OpenGL (GL_ARB_gl_spirv), so both APIs
/// can run the very same binary: GL has no descriptor sets, so the
/// `DescriptorSet` decorations go, and GL's window origin is the lower left, so
/// `OriginUpperLeft` becomes `OriginLowerLeft` (with glReadPixels' bottom-up rows
/// this gives the same upright image as the GLSL path). Nothing else changes.
pub fn spirv_for_opengl(words: &[u32]) -> Vec<u32> {
    const OP_EXECUTION_MODE: u32 = 16;
    const OP_DECORATE: u32 = 71;
    const DECORATION_DESCRIPTOR_SET: u32 = 34;
    const ORIGIN_UPPER_LEFT: u32 = 7;
    const ORIGIN_LOWER_LEFT: u32 = 8;
    let mut out = words[..5.min(words.len())].to_vec();
    let mut i = 5;
    while i < words.len() {
        let count = (words[i] >> 16) as usize;
        let op = words[i] & 0xffff;
        if count == 0 || i + count > words.len() {
            // Malformed; keep the rest untouched and let the driver report it.
            out.extend_from_slice(&words[i..]);
            break;
        }
        let inst = &words[i..i + count];
        if op == OP_DECORATE && count >= 3 && inst[2] == DECORATION_DESCRIPTOR_SET {
            // dropped
        } else if op == OP_EXECUTION_MODE && count >= 3 && inst[2] == ORIGIN_UPPER_LEFT {
            out.extend_from_slice(&[inst[0], inst[1], ORIGIN_LOWER_LEFT]);
            out.extend_from_slice(&inst[3..]);
        } else {
            out.extend_from_slice(inst);
        }
        i += count;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spec_constant_table_matches_the_shader() {
        let mut options = naga::front::glsl::Options::from(ShaderStage::Fragment);
        options.defines.insert("SPECIALIZE".into(), "1".into());
        let module = naga::front::glsl::Frontend::default()
            .parse(&options, &fragment_source())
            .unwrap();
        let declared: Vec<(String, u16)> = module
            .overrides
            .iter()
            .map(|(_, o)| (o.name.clone().unwrap_or_default(), o.id.unwrap_or(u16::MAX)))
            .collect();
        let table: Vec<(String, u16)> = SPEC_CONSTANTS
            .iter()
            .map(|(n, id)| (n.to_string(), *id))
            .collect();
        assert_eq!(declared, table);
    }

    #[test]
    fn specialized_variant_leaves_no_override_for_the_writers() {
        let scene = Scene::load("spherelist", &[]).unwrap();
        let v = Variant::specialized(&scene);
        assert_eq!(v.constants.get("SPEC_GLASS"), Some(&false));
        assert_eq!(v.constants.get("SPEC_MIRROR"), Some(&true));
        let (m, _) = parse(&fragment_source(), ShaderStage::Fragment, &v).unwrap();
        // process_overrides keeps the arena but replaces every use by a constant.
        let uses = m
            .functions
            .iter()
            .map(|(_, f)| f)
            .chain(m.entry_points.iter().map(|e| &e.function))
            .flat_map(|f| f.expressions.iter())
            .chain(m.global_expressions.iter())
            .filter(|(_, e)| matches!(e, naga::Expression::Override(_)))
            .count();
        assert!(!m.overrides.is_empty(), "the shader declares the switches");
        assert_eq!(uses, 0, "no override left for the writers");
        let s = build(&v).unwrap();
        assert!(!s.fragment_spirv.is_empty() && s.fragment_glsl.contains("void main"));
    }

    #[test]
    fn spirv_for_opengl_drops_sets_and_flips_origin_only() {
        let s = build(&Variant::generic(Default::default())).unwrap();
        let gl = spirv_for_opengl(&s.fragment_spirv);
        let count = |w: &[u32], op: u32, arg2: u32| {
            let mut i = 5;
            let mut n = 0;
            while i < w.len() {
                let c = (w[i] >> 16) as usize;
                if w[i] & 0xffff == op && c >= 3 && w[i + 2] == arg2 {
                    n += 1;
                }
                i += c;
            }
            n
        };
        assert_eq!(
            count(&s.fragment_spirv, 71, 34),
            5,
            "five resources in set 0"
        );
        assert_eq!(count(&gl, 71, 34), 0);
        assert_eq!(count(&s.fragment_spirv, 16, 7), 1);
        assert_eq!(count(&gl, 16, 8), 1);
        assert_eq!(
            gl.len(),
            s.fragment_spirv.len() - 5 * 4,
            "only the five 4-word decorations go"
        );
    }

    #[test]
    fn compute_shader_builds_with_each_measured_workgroup() {
        for wg in Workgroup::MEASURED {
            let c = build_compute(&Variant::generic(Default::default()), wg).unwrap();
            assert_eq!(c.spirv[0], 0x0723_0203, "SPIR-V magic");
            let local = format!(
                "layout(local_size_x = {}, local_size_y = {}, local_size_z = 1) in;",
                wg.x, wg.y
            );
            assert!(c.glsl.contains(&local), "{wg}: {}", &c.glsl[..200]);
            assert!(
                c.glsl.contains("binding = 5"),
                "the storage image is bound by number"
            );
            assert!(c.glsl.contains("imageStore"));
        }
    }
}
