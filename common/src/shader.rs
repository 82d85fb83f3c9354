//! The shader build: concatenates shaders/ (naga has no #include), picks the
//! scene's variant through defines (or, for comparison, through specialization
//! constants that naga's process_overrides fixes), validates the naga module
//! once, and writes SPIR-V for Vulkan and GLSL 450 core for OpenGL from that
//! same module.

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
/// the reference can be asked to take the same choices. `constants` are the
/// specialization constants of `Variant::specialized` (empty otherwise).
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Variant {
    pub defines: BTreeMap<String, String>,
    pub numerics: Numerics,
    pub constants: BTreeMap<String, bool>,
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
        if scene.bvh {
            v.defines.insert("USE_BVH".into(), "1".into());
        }
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
    /// own; each traces through the BVH when the scene has one.
    pub fn chosen(scene: &Scene, generic: bool, specialize: bool) -> Variant {
        if generic {
            let mut v = Variant::generic(scene.numerics);
            if scene.bvh {
                v.defines.insert("USE_BVH".into(), "1".into());
            }
            v
        } else if specialize {
            Variant::specialized(scene)
        } else {
            Variant::for_scene(scene)
        }
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
            && self.constants == needed.constants
    }

    /// A short label such as `spheres+triangles+mirror+glass/stack6/normal-scaled/watertight/stable`
    /// (with `/bvh` at the end when the variant traces through a BVH).
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
        let bvh = if self.defines.contains_key("USE_BVH") {
            "/bvh"
        } else {
            ""
        };
        let spec = if self.constants.is_empty() {
            ""
        } else {
            "/spec"
        };
        format!(
            "{}/stack{}/{}{bvh}{spec}",
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
