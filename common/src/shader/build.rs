//! The naga build: puts shaders/ together (naga has no #include), compiles a
//! `Variant` through its defines (or, for comparison, through specialization
//! constants that naga's process_overrides fixes), validates the naga module
//! once, and writes SPIR-V for Vulkan and GLSL 450 core for OpenGL from that
//! same module — then finishes both as the variant's `Passes` say (by default
//! taking out two costs naga adds on its own: `post::strip_local_array_zero_init_*`
//! and `spv::Options::force_loop_bounding`). Each entry point compiles only
//! what it runs.

use crate::cli::{RenderPath, Workgroup};
use crate::shader::post::{
    float_controls_spirv, no_contraction_spirv, precise_float_locals_glsl, restrict_resources_glsl,
    spirv_for_opengl, strip_local_array_zero_init_glsl, strip_local_array_zero_init_spirv,
    warp_probe_glsl,
};
use crate::shader::variant::{Entry, SpirvCompiler, Variant, SPEC_CONSTANTS};
use anyhow::{anyhow, Context};
use naga::back::{glsl, spv};
use naga::valid::{Capabilities, ModuleInfo, ValidationFlags, Validator};
use naga::{Module, ShaderStage};

/// The tracer's parts, in reading order (shaders/trace/loop.glsl lists what
/// each holds). naga has no `#include`, so the build puts them together here,
/// at compile time: editing a part and rebuilding changes what the apps run.
pub const TRACE_PARTS: [(&str, &str); 6] = [
    (
        "inputs.glsl",
        include_str!("../../../shaders/trace/inputs.glsl"),
    ),
    (
        "intersect.glsl",
        include_str!("../../../shaders/trace/intersect.glsl"),
    ),
    ("bvh.glsl", include_str!("../../../shaders/trace/bvh.glsl")),
    ("hit.glsl", include_str!("../../../shaders/trace/hit.glsl")),
    (
        "secondary.glsl",
        include_str!("../../../shaders/trace/secondary.glsl"),
    ),
    (
        "loop.glsl",
        include_str!("../../../shaders/trace/loop.glsl"),
    ),
];

/// The single tracer every variant, both APIs and both paths start from: the
/// parts of [`TRACE_PARTS`] concatenated by the compiler (`concat!` of the same
/// files), so there is no checked-in copy to fall out of step. `--dump-shaders`
/// writes it, with a run's defines and entry point, as one file an external
/// compiler takes (`shader_source`).
pub const TRACE_GLSL: &str = concat!(
    "// The one Whitted-style tracer, put together from shaders/trace/*.glsl by common/src/shader/build.rs.\n",
    include_str!("../../../shaders/trace/inputs.glsl"),
    include_str!("../../../shaders/trace/intersect.glsl"),
    include_str!("../../../shaders/trace/bvh.glsl"),
    include_str!("../../../shaders/trace/hit.glsl"),
    include_str!("../../../shaders/trace/secondary.glsl"),
    include_str!("../../../shaders/trace/loop.glsl"),
);
pub const TRACE_FRAG: &str = include_str!("../../../shaders/trace.frag");
pub const FULLSCREEN_VERT: &str = include_str!("../../../shaders/fullscreen.vert");
pub const TRACE_COMP: &str = include_str!("../../../shaders/trace.comp");
/// The laboratory's arithmetic probe (`--experiment ulp`): both entry points.
pub const ULP_GLSL: &str = include_str!("../../../shaders/lab/ulp.glsl");

/// The entry point's source for `variant`: the tracer's, or, with the
/// laboratory's arithmetic probe, the probe's main behind the same
/// declarations (so every binding is the tracer's).
fn entry_source(variant: &Variant, compute: bool) -> String {
    match (variant.knobs.ulp, compute) {
        (None, false) => fragment_source(),
        (None, true) => compute_source(),
        (Some(_), false) => format!("#version 450\n{TRACE_GLSL}\n{ULP_GLSL}"),
        (Some(_), true) => format!("#version 450\n#define ULP_COMPUTE 1\n{TRACE_GLSL}\n{ULP_GLSL}"),
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

/// One stage of `variant` as a single self-contained file that an external
/// compiler (glslangValidator) takes as it is: the version, the variant's
/// defines, then the source naga parses. `--dump-shaders` writes it.
pub fn standalone_source(source: &str, variant: &Variant) -> String {
    let body = source.strip_prefix("#version 450\n").unwrap_or(source);
    let mut s = String::from("#version 450\n");
    for (k, v) in variant.defines() {
        s.push_str(&format!("#define {k} {v}\n"));
    }
    s.push_str(body);
    s
}

/// Parses and validates one stage.
pub fn parse(
    source: &str,
    stage: ShaderStage,
    variant: &Variant,
) -> anyhow::Result<(Module, ModuleInfo)> {
    let mut options = naga::front::glsl::Options::from(stage);
    options.defines.extend(variant.defines());
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
    let values = variant.constants();
    for (name, id) in SPEC_CONSTANTS {
        if let Some(&on) = values.get(name) {
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

/// One compiled stage: what each API loads, and the source it came from.
#[derive(Debug, Clone)]
pub struct Stage {
    /// "vertex", "fragment" or "compute": the file names `--dump-shaders` writes.
    pub name: &'static str,
    pub spirv: Vec<u32>,
    pub glsl: String,
    /// The stage as one file an external compiler takes (`standalone_source`).
    pub source: String,
}

fn compile(
    name: &'static str,
    source: &str,
    stage: ShaderStage,
    variant: &Variant,
) -> anyhow::Result<Stage> {
    let (m, i) = parse(source, stage, variant)?;
    Ok(Stage {
        name,
        spirv: spirv_for_vulkan(source, (&m, &i), stage, variant)?,
        glsl: to_glsl(&m, &i, stage, variant)?,
        source: standalone_source(source, variant),
    })
}

/// The fragment path's pair, for both APIs.
#[derive(Debug, Clone)]
pub struct Shaders {
    pub variant: Variant,
    pub vertex: Stage,
    pub fragment: Stage,
}

/// The tracer as a compute shader, for both APIs.
#[derive(Debug, Clone)]
pub struct ComputeShader {
    pub variant: Variant,
    pub workgroup: Workgroup,
    pub stage: Stage,
}

impl Shaders {
    /// The fragment stage as `--gl-spirv` loads it, with the variant's
    /// `Restrict` decorations (`post::spirv_for_opengl`).
    pub fn fragment_spirv_for_opengl(&self) -> Vec<u32> {
        spirv_for_opengl(&self.fragment.spirv, self.variant.passes.restrict)
    }
}

impl ComputeShader {
    /// The stage as `--gl-spirv` loads it, likewise.
    pub fn spirv_for_opengl(&self) -> Vec<u32> {
        spirv_for_opengl(&self.stage.spirv, self.variant.passes.restrict)
    }
}

/// The shaders of one entry point: the fullscreen pair, or the compute
/// shader with its workgroup. Each path compiles only what it runs.
#[derive(Debug, Clone)]
pub enum PathShaders {
    Fragment(Shaders),
    Compute(ComputeShader),
}

impl PathShaders {
    /// Compiles `variant` for its entry point.
    pub fn build(variant: &Variant) -> anyhow::Result<PathShaders> {
        Ok(match variant.entry {
            Entry::Fragment => PathShaders::Fragment(build(variant)?),
            Entry::Compute(workgroup) => PathShaders::Compute(build_compute(variant, workgroup)?),
        })
    }

    /// Whether the tracer reads the wide tree's nodes through a buffer
    /// texture, which OpenGL must then bind (`Variant::node_texels`).
    pub fn reads_node_texels(&self) -> bool {
        match self {
            PathShaders::Fragment(s) => s.variant.node_texels,
            PathShaders::Compute(c) => c.variant.node_texels,
        }
    }

    pub fn path(&self) -> RenderPath {
        match self {
            PathShaders::Fragment(_) => RenderPath::Fragment,
            PathShaders::Compute(_) => RenderPath::Compute,
        }
    }

    pub fn variant(&self) -> &Variant {
        match self {
            PathShaders::Fragment(s) => &s.variant,
            PathShaders::Compute(c) => &c.variant,
        }
    }

    /// The stages, as `--dump-shaders` writes them.
    pub fn stages(&self) -> Vec<&Stage> {
        match self {
            PathShaders::Fragment(s) => vec![&s.vertex, &s.fragment],
            PathShaders::Compute(c) => vec![&c.stage],
        }
    }
}

/// The fullscreen pair of `variant` (whatever its entry point says).
pub fn build(variant: &Variant) -> anyhow::Result<Shaders> {
    let variant = variant.on(Entry::Fragment);
    Ok(Shaders {
        vertex: compile("vertex", FULLSCREEN_VERT, ShaderStage::Vertex, &variant)?,
        fragment: compile(
            "fragment",
            &entry_source(&variant, false),
            ShaderStage::Fragment,
            &variant,
        )?,
        variant,
    })
}

/// The compute shader of `variant` with `workgroup`.
pub fn build_compute(variant: &Variant, workgroup: Workgroup) -> anyhow::Result<ComputeShader> {
    let variant = variant.on(Entry::Compute(workgroup));
    Ok(ComputeShader {
        stage: compile(
            "compute",
            &entry_source(&variant, true),
            ShaderStage::Compute,
            &variant,
        )?,
        workgroup,
        variant,
    })
}

/// Whether naga bounds every loop of the SPIR-V with a 64-bit counter that
/// breaks out after 2^64 iterations, so that a driver cannot assume an
/// infinite loop away; the GLSL writer adds none, so it is a cost only Vulkan
/// pays. Every loop of the tracer ends (the stacks shrink, the primitive loops
/// count up to a constant), so it is never needed for correctness. It costs
/// the BVH variants time in Vulkan, but without it NVIDIA's Vulkan compiler,
/// given the constant trip count of the brute-force sphere loop, made the
/// 10,000-sphere list slower
/// (docs/findings/shader-compilers.md#loop-bounds-the-trap-and-the-choice).
/// So the BVH variants go without it and the brute-force ones keep it, unless
/// the laboratory says otherwise.
pub fn loop_bounding(variant: &Variant) -> bool {
    variant
        .passes
        .loop_bounding
        .unwrap_or(variant.bvh_stack.is_none())
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
    // Workgroup memory (the shared BVH stack and --shared-pad, both compute
    // experiments) is written before it is read, and the GLSL writer is told
    // not to zero it (`to_glsl`): naga's default polyfill would zero it at the
    // start of every workgroup in Vulkan alone, a cost only one API would pay.
    let options = spv::Options {
        flags: spv::WriterFlags::LABEL_VARYINGS,
        force_loop_bounding: loop_bounding(variant),
        zero_initialize_workgroup_memory: spv::ZeroInitializeWorkgroupMemoryMode::None,
        ..Default::default()
    };
    let pipeline = spv::PipelineOptions {
        shader_stage: stage,
        entry_point: "main".into(),
    };
    let words = spv::write_vec(module, info, &options, Some(&pipeline))
        .with_context(|| format!("writing {stage:?} SPIR-V"))?;
    Ok(if variant.passes.strip_zero_init {
        strip_local_array_zero_init_spirv(&words)
    } else {
        words
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
    for b in 0..=crate::gpu::layout::binding::LAST {
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
    let passes = variant.passes;
    if passes.strip_zero_init {
        out = strip_local_array_zero_init_glsl(&out);
    }
    if passes.restrict {
        out = restrict_resources_glsl(&out);
    }
    if stage == ShaderStage::Compute && passes.warp_probe {
        out = warp_probe_glsl(&out, crate::gpu::layout::binding::WARP_PROBE)?;
    }
    if stage != ShaderStage::Vertex && variant.node_texels {
        out = super::node_texels::node_texels_glsl(&out, stage)?;
    }
    if passes.no_contraction {
        out = precise_float_locals_glsl(&out);
    }
    Ok(out)
}

/// The SPIR-V that Vulkan runs: naga's, or glslangValidator's from the same
/// source and defines; finished as the variant's passes say.
fn spirv_for_vulkan(
    source: &str,
    (module, info): (&Module, &ModuleInfo),
    stage: ShaderStage,
    variant: &Variant,
) -> anyhow::Result<Vec<u32>> {
    let mut words = match variant.passes.compiler {
        SpirvCompiler::Glslang => glslang_spirv(source, stage, variant)?,
        SpirvCompiler::Naga => to_spirv(module, info, stage, variant)?,
    };
    if variant.passes.no_contraction {
        words = no_contraction_spirv(&words);
    }
    if variant.passes.float_controls {
        words = float_controls_spirv(&words);
    }
    Ok(words)
}

/// `--experiment glslang`: compiles `source` with glslangValidator, to measure
/// naga's SPIR-V against the reference compiler's for the very same GLSL. naga
/// stays the product's compiler; this is a measurement, run where the tool is
/// installed.
fn glslang_spirv(source: &str, stage: ShaderStage, variant: &Variant) -> anyhow::Result<Vec<u32>> {
    let extension = match stage {
        ShaderStage::Vertex => "vert",
        ShaderStage::Fragment => "frag",
        _ => "comp",
    };
    let dir = std::env::temp_dir().join(format!("twinray-glslang-{}", std::process::id()));
    std::fs::create_dir_all(&dir)
        .with_context(|| format!("--experiment glslang: creating {}", dir.display()))?;
    let input = dir.join(format!("trace.{extension}"));
    let output = dir.join(format!("trace-{extension}.spv"));
    std::fs::write(&input, source)
        .with_context(|| format!("--experiment glslang: writing {}", input.display()))?;
    let mut command = std::process::Command::new("glslangValidator");
    command.args(["-V", "--target-env", "vulkan1.1"]);
    command.args(variant.defines().iter().map(|(k, v)| format!("-D{k}={v}")));
    command.arg("-o").arg(&output).arg(&input);
    let result = command.output().map_err(|e| {
        anyhow!("--experiment glslang needs glslangValidator on PATH (Debian: glslang-tools): {e}")
    })?;
    if !result.status.success() {
        anyhow::bail!(
            "--experiment glslang: glslangValidator rejected the {stage:?} shader:\n{}",
            String::from_utf8_lossy(&result.stdout)
        );
    }
    let bytes = std::fs::read(&output)
        .with_context(|| format!("--experiment glslang: reading {}", output.display()))?;
    let _ = std::fs::remove_dir_all(&dir);
    if bytes.len() % 4 != 0 {
        anyhow::bail!("--experiment glslang: {} is not SPIR-V", output.display());
    }
    Ok(bytes
        .chunks_exact(4)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

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
        let v = Variant::specialized(&scene, None);
        assert_eq!(v.constants().get("SPEC_GLASS"), Some(&false));
        assert_eq!(v.constants().get("SPEC_MIRROR"), Some(&true));
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
        assert!(!s.fragment.spirv.is_empty() && s.fragment.glsl.contains("void main"));
    }

    #[test]
    fn compute_shader_builds_with_each_measured_workgroup() {
        for wg in Workgroup::MEASURED {
            let c = build_compute(&Variant::generic(Default::default()), wg).unwrap();
            let c = &c.stage;
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

    #[test]
    fn opengl_spirv_marks_every_resource_restrict() {
        let s = build(&Variant::generic(Default::default())).unwrap();
        let decorations = |w: &[u32], decoration: u32| {
            crate::shader::post::spirv_instructions(w)
                .filter(|i| i[0] & 0xffff == 71 && i.len() >= 3 && i[2] == decoration)
                .count()
        };
        // Each of the five set-0 resources, and nothing else, is decorated Restrict.
        let gl = spirv_for_opengl(&s.fragment.spirv, true);
        assert_eq!(
            decorations(&s.fragment.spirv, 19),
            0,
            "Vulkan's SPIR-V is naga's"
        );
        assert_eq!(decorations(&gl, 19), decorations(&s.fragment.spirv, 34));
        assert_eq!(decorations(&gl, 19), 5);
        let plain = spirv_for_opengl(&s.fragment.spirv, false);
        assert_eq!(decorations(&plain, 19), 0);
    }

    #[test]
    fn spirv_for_opengl_drops_sets_and_flips_origin_only() {
        let s = build(&Variant::generic(Default::default())).unwrap();
        let gl = spirv_for_opengl(&s.fragment.spirv, false);
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
            count(&s.fragment.spirv, 71, 34),
            5,
            "five resources in set 0"
        );
        assert_eq!(count(&gl, 71, 34), 0);
        assert_eq!(count(&s.fragment.spirv, 16, 7), 1);
        assert_eq!(count(&gl, 16, 8), 1);
        assert_eq!(
            gl.len(),
            s.fragment.spirv.len() - 5 * 4,
            "only the five 4-word decorations go"
        );
    }
}
