//! The shader build: concatenates shaders/ (naga has no #include), picks the
//! scene's variant through defines, validates the naga module once, and writes
//! SPIR-V for Vulkan and GLSL 450 core for OpenGL from that same module.

use crate::cli::Workgroup;
use crate::numerics::Numerics;
use crate::scene::{Features, Scene, MAX_DEPTH_LIMIT};
use anyhow::{anyhow, Context};
use naga::back::{glsl, spv};
use naga::valid::{Capabilities, ModuleInfo, ValidationFlags, Validator};
use naga::{Module, ShaderStage};
use std::collections::BTreeMap;

pub const TRACE_GLSL: &str = include_str!("../../shaders/trace.glsl");
pub const TRACE_FRAG: &str = include_str!("../../shaders/trace.frag");
pub const FULLSCREEN_VERT: &str = include_str!("../../shaders/fullscreen.vert");
pub const TRACE_COMP: &str = include_str!("../../shaders/trace.comp");

/// The defines that select a shader variant. Same map → same module → same code
/// in both APIs. `numerics` is what its numerical defines encode, kept so that
/// the reference can be asked to take the same choices.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Variant {
    pub defines: BTreeMap<String, String>,
    pub numerics: Numerics,
}

impl Variant {
    /// Only what the scene needs: no triangle loop without triangles, no
    /// refraction code without glass, a ray stack sized to the scene's depth;
    /// and the scene's numerical choices (offset, triangle and sphere tests).
    pub fn for_scene(scene: &Scene) -> Variant {
        let mut v = Variant::from_features(scene.features(), scene.max_depth, scene.numerics);
        if scene.bvh {
            v.defines.insert("USE_BVH".into(), "1".into());
        }
        v
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
        // Without mirrors or glass no ray ever spawns another: the stack holds
        // the primary ray alone, and every max depth compiles to one shader.
        let stack = if f.mirror || f.glass {
            max_depth.max(1) + 1
        } else {
            1
        };
        defines.insert("STACK_SIZE".into(), stack.to_string());
        for d in numerics.defines() {
            defines.insert(d.to_string(), "1".to_string());
        }
        Variant { defines, numerics }
    }

    /// Every feature on, the deepest stack: renders any scene (with the given numerics).
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
    }

    /// A short label such as `spheres+triangles+mirror+glass/stack6/normal-scaled/watertight/stable`
    /// (with `/bvh` at the end when the variant traces through a BVH).
    pub fn label(&self) -> String {
        let mut parts: Vec<String> = ["HAS_SPHERES", "HAS_TRIANGLES", "HAS_MIRROR", "HAS_GLASS"]
            .iter()
            .filter(|d| self.defines.contains_key(**d))
            .map(|d| d.trim_start_matches("HAS_").to_lowercase())
            .collect();
        if parts.is_empty() {
            parts.push("background".into());
        }
        let bvh = if self.defines.contains_key("USE_BVH") {
            "/bvh"
        } else {
            ""
        };
        format!(
            "{}/stack{}/{}{bvh}",
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
    Ok((module, info))
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
        vertex_spirv: to_spirv(&vm, &vi, ShaderStage::Vertex)?,
        fragment_spirv: to_spirv(&fm, &fi, ShaderStage::Fragment)?,
        vertex_glsl: to_glsl(&vm, &vi, ShaderStage::Vertex)?,
        fragment_glsl: to_glsl(&fm, &fi, ShaderStage::Fragment)?,
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
    let (m, i) = parse(&compute_source(), ShaderStage::Compute, &v)?;
    Ok(ComputeShader {
        variant: variant.clone(),
        workgroup,
        spirv: to_spirv(&m, &i, ShaderStage::Compute)?,
        glsl: to_glsl(&m, &i, ShaderStage::Compute)?,
    })
}

pub fn to_spirv(
    module: &Module,
    info: &ModuleInfo,
    stage: ShaderStage,
) -> anyhow::Result<Vec<u32>> {
    // No ADJUST_COORDINATE_SPACE (y stays as written, see trace.frag) and no DEBUG,
    // so debug and release builds emit identical SPIR-V.
    let options = spv::Options {
        flags: spv::WriterFlags::LABEL_VARYINGS,
        ..Default::default()
    };
    let pipeline = spv::PipelineOptions {
        shader_stage: stage,
        entry_point: "main".into(),
    };
    spv::write_vec(module, info, &options, Some(&pipeline))
        .with_context(|| format!("writing {stage:?} SPIR-V"))
}

pub fn to_glsl(module: &Module, info: &ModuleInfo, stage: ShaderStage) -> anyhow::Result<String> {
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
    let options = glsl::Options {
        version: glsl::Version::Desktop(450),
        writer_flags: glsl::WriterFlags::empty(),
        binding_map,
        zero_initialize_workgroup_memory: true,
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
    Ok(out)
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
