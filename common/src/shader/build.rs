//! The naga build: concatenates shaders/ (naga has no #include), compiles a
//! `Variant` through defines (or, for comparison, through specialization
//! constants that naga's process_overrides fixes), validates the naga module
//! once, and writes SPIR-V for Vulkan and GLSL 450 core for OpenGL from that
//! same module — then takes out two costs naga adds on its own (see
//! `post::strip_local_array_zero_init_*` and `spv::Options::force_loop_bounding`).

use crate::cli::{Experiment, Workgroup};
use crate::shader::post::{
    float_controls_spirv, no_contraction_spirv, precise_float_locals_glsl, restrict_resources_glsl,
    strip_local_array_zero_init_glsl, strip_local_array_zero_init_spirv, warp_probe_glsl,
};
use crate::shader::variant::{Variant, SPEC_CONSTANTS};
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

impl Shaders {
    /// Both stages as `--dump-shaders` writes them: (name, SPIR-V, GLSL).
    pub fn stages(&self) -> [(&str, &[u32], &str); 2] {
        [
            ("vertex", &self.vertex_spirv, &self.vertex_glsl),
            ("fragment", &self.fragment_spirv, &self.fragment_glsl),
        ]
    }
}

pub fn build(variant: &Variant) -> anyhow::Result<Shaders> {
    let (vm, vi) = parse(FULLSCREEN_VERT, ShaderStage::Vertex, variant)?;
    let (fm, fi) = parse(&fragment_source(), ShaderStage::Fragment, variant)?;
    Ok(Shaders {
        variant: variant.clone(),
        vertex_spirv: spirv_for_vulkan(FULLSCREEN_VERT, (&vm, &vi), ShaderStage::Vertex, variant)?,
        fragment_spirv: spirv_for_vulkan(
            &fragment_source(),
            (&fm, &fi),
            ShaderStage::Fragment,
            variant,
        )?,
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
        spirv: spirv_for_vulkan(&compute_source(), (&m, &i), ShaderStage::Compute, &v)?,
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
    // Workgroup memory (the shared BVH stack and --shared-pad, both compute
    // experiments) is written before it is read, and the GLSL writer is told
    // not to zero it (`to_glsl`): naga's default polyfill would zero it at the
    // start of every workgroup in Vulkan alone, a cost only one API would pay.
    let options = spv::Options {
        flags: spv::WriterFlags::LABEL_VARYINGS,
        force_loop_bounding: loop_bounding,
        zero_initialize_workgroup_memory: spv::ZeroInitializeWorkgroupMemoryMode::None,
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
    let out = if variant.experiments.contains(&Experiment::NagaZeroInit) {
        out
    } else {
        strip_local_array_zero_init_glsl(&out)
    };
    let out = if restricts_resources(variant) {
        restrict_resources_glsl(&out)
    } else {
        out
    };
    let out =
        if stage == ShaderStage::Compute && variant.experiments.contains(&Experiment::WarpProbe) {
            warp_probe_glsl(&out, crate::gpu::layout::binding::WARP_PROBE)?
        } else {
            out
        };
    Ok(
        if variant.experiments.contains(&Experiment::NoContraction) {
            precise_float_locals_glsl(&out)
        } else {
            out
        },
    )
}

/// Whether OpenGL's shader declares its buffers and image `restrict` (GLSL) or
/// `Restrict` (SPIR-V), as Vulkan's SPIR-V implies: always, except with
/// `--experiment naga-aliasing` (see `post::restrict_resources_glsl`).
pub fn restricts_resources(variant: &Variant) -> bool {
    !variant.experiments.contains(&Experiment::NagaAliasing)
}

/// The SPIR-V that Vulkan runs: naga's, or with `--experiment glslang` Khronos'
/// glslangValidator's from the same source and defines; with `--experiment
/// no-contraction`, decorated so that the driver may not fuse float arithmetic.
fn spirv_for_vulkan(
    source: &str,
    (module, info): (&Module, &ModuleInfo),
    stage: ShaderStage,
    variant: &Variant,
) -> anyhow::Result<Vec<u32>> {
    let words = if variant.experiments.contains(&Experiment::Glslang) {
        glslang_spirv(source, stage, variant)?
    } else {
        to_spirv(module, info, stage, variant)?
    };
    let words = if variant.experiments.contains(&Experiment::NoContraction) {
        no_contraction_spirv(&words)
    } else {
        words
    };
    Ok(
        if variant.experiments.contains(&Experiment::FloatControls) {
            float_controls_spirv(&words)
        } else {
            words
        },
    )
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
    command.args(variant.defines.iter().map(|(k, v)| format!("-D{k}={v}")));
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
    use crate::shader::post::spirv_for_opengl;

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

    #[test]
    fn opengl_spirv_marks_every_resource_restrict() {
        let s = build(&Variant::generic(Default::default())).unwrap();
        let decorations = |w: &[u32], decoration: u32| {
            crate::shader::post::spirv_instructions(w)
                .filter(|i| i[0] & 0xffff == 71 && i.len() >= 3 && i[2] == decoration)
                .count()
        };
        // Each of the five set-0 resources, and nothing else, is decorated Restrict.
        let gl = spirv_for_opengl(&s.fragment_spirv, true);
        assert_eq!(
            decorations(&s.fragment_spirv, 19),
            0,
            "Vulkan's SPIR-V is naga's"
        );
        assert_eq!(decorations(&gl, 19), decorations(&s.fragment_spirv, 34));
        assert_eq!(decorations(&gl, 19), 5);
        let plain = spirv_for_opengl(&s.fragment_spirv, false);
        assert_eq!(decorations(&plain, 19), 0);
    }

    #[test]
    fn spirv_for_opengl_drops_sets_and_flips_origin_only() {
        let s = build(&Variant::generic(Default::default())).unwrap();
        let gl = spirv_for_opengl(&s.fragment_spirv, false);
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
}
