//! The shader build: concatenates shaders/ (naga has no #include), picks the
//! scene's variant through defines, validates the naga module once, and writes
//! SPIR-V for Vulkan and GLSL 450 core for OpenGL from that same module.

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
        Variant::from_features(scene.features(), scene.max_depth, scene.numerics)
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
        defines.insert("STACK_SIZE".into(), (max_depth.max(1) + 1).to_string());
        for d in numerics.defines() {
            defines.insert(d.to_string(), "1".to_string());
        }
        Variant { defines, numerics }
    }

    /// Every feature on, the deepest stack: renders any scene (with the given numerics).
    pub fn generic(numerics: Numerics) -> Variant {
        let all = Features { spheres: true, triangles: true, mirror: true, glass: true };
        Variant::from_features(all, MAX_DEPTH_LIMIT, numerics)
    }

    /// A short label such as `spheres+triangles+mirror+glass/stack6/normal-scaled/watertight/stable`.
    pub fn label(&self) -> String {
        let mut parts: Vec<String> = ["HAS_SPHERES", "HAS_TRIANGLES", "HAS_MIRROR", "HAS_GLASS"]
            .iter()
            .filter(|d| self.defines.contains_key(**d))
            .map(|d| d.trim_start_matches("HAS_").to_lowercase())
            .collect();
        if parts.is_empty() {
            parts.push("background".into());
        }
        format!(
            "{}/stack{}/{}",
            parts.join("+"),
            self.defines.get("STACK_SIZE").map(String::as_str).unwrap_or("?"),
            self.numerics.label()
        )
    }
}

/// The fragment source as naga sees it (also used by the layout test).
pub fn fragment_source() -> String {
    format!("#version 450\n{TRACE_GLSL}\n{TRACE_FRAG}")
}

/// Parses and validates one stage.
pub fn parse(source: &str, stage: ShaderStage, variant: &Variant) -> anyhow::Result<(Module, ModuleInfo)> {
    let mut options = naga::front::glsl::Options::from(stage);
    for (k, v) in &variant.defines {
        options.defines.insert(k.clone(), v.clone());
    }
    let module = naga::front::glsl::Frontend::default()
        .parse(&options, source)
        .map_err(|e| anyhow!("naga could not parse the {stage:?} shader:\n{}", e.emit_to_string(source)))?;
    let info = Validator::new(ValidationFlags::all(), Capabilities::default())
        .validate(&module)
        .map_err(|e| anyhow!("naga rejected the {stage:?} shader:\n{}", e.emit_to_string(source)))?;
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

pub fn to_spirv(module: &Module, info: &ModuleInfo, stage: ShaderStage) -> anyhow::Result<Vec<u32>> {
    // No ADJUST_COORDINATE_SPACE (y stays as written, see trace.frag) and no DEBUG,
    // so debug and release builds emit identical SPIR-V.
    let options = spv::Options { flags: spv::WriterFlags::LABEL_VARYINGS, ..Default::default() };
    let pipeline = spv::PipelineOptions { shader_stage: stage, entry_point: "main".into() };
    spv::write_vec(module, info, &options, Some(&pipeline)).with_context(|| format!("writing {stage:?} SPIR-V"))
}

pub fn to_glsl(module: &Module, info: &ModuleInfo, stage: ShaderStage) -> anyhow::Result<String> {
    // naga renames blocks and members, so OpenGL binds by number: give every
    // resource its (set 0) binding explicitly. UBOs and SSBOs have separate
    // binding spaces in GL, so the numbers carry over unchanged.
    let mut binding_map = glsl::BindingMap::default();
    for b in 0..=crate::gpu::binding::LIGHTS {
        binding_map.insert(naga::ResourceBinding { group: 0, binding: b }, b as u8);
    }
    let options = glsl::Options {
        version: glsl::Version::Desktop(450),
        writer_flags: glsl::WriterFlags::empty(),
        binding_map,
        zero_initialize_workgroup_memory: true,
    };
    let pipeline = glsl::PipelineOptions { shader_stage: stage, entry_point: "main".into(), multiview: None };
    let mut out = String::new();
    let mut writer = glsl::Writer::new(&mut out, module, info, &options, &pipeline, Default::default())
        .with_context(|| format!("setting up the {stage:?} GLSL writer"))?;
    writer.write().with_context(|| format!("writing {stage:?} GLSL"))?;
    Ok(out)
}
