//! What one compiled tracer is: a typed `Variant` that holds every choice the
//! shader's bytes depend on — the scene's features, the ray stack, the counts,
//! the BVH stack, the numerical choices, the form (the scene's own, generic or
//! specialised), the entry point with its workgroup, and the laboratory's
//! shader knobs and passes over naga's output. It renders its defines only at
//! the end (`defines`), for naga. The run plan (`plan`) decides a variant; the
//! build (`build`) compiles it; nothing parses a decision back out of a define.

use crate::cli::{RenderPath, Workgroup};
use crate::gpu::layout::Bvh;
use crate::lab::experiment::UlpOp;
use crate::limits::MAX_DEPTH;
use crate::scene::numerics::Numerics;
use crate::scene::{Features, Scene};
use std::collections::BTreeMap;

/// One tracer, fully decided. Same variant → same module → same code in both APIs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Variant {
    /// The primitives and materials compiled in.
    pub features: Features,
    pub form: Form,
    /// Pending rays the depth-first ray stack holds.
    pub ray_stack: u32,
    /// Where the shader's loops find the primitive and light counts.
    pub counts: Counts,
    /// The BVH traversal stack's entries, where the variant traces through a BVH.
    pub bvh_stack: Option<u32>,
    /// The BVH's children per node: 2, 4 or 8 (trace/bvh.glsl walks each).
    pub bvh_width: u32,
    /// Offset, triangle and sphere tests; the reference can take the same.
    pub numerics: Numerics,
    /// The entry point: the fullscreen pair, or compute with its workgroup.
    pub entry: Entry,
    /// COUNT_RAYS: the untimed frame that counts rays by kind.
    pub count_rays: bool,
    /// What the laboratory changed in the shader source (all off in the product).
    pub knobs: ShaderKnobs,
    /// How naga's output is finished (the product's passes unless the laboratory says otherwise).
    pub passes: Passes,
    /// The one light shaded before its shadow walk, the hit's secondary rays
    /// pushed before it (LIGHT_BEFORE_WALK; `Api::light_before_walk` decides).
    pub light_before_walk: bool,
    /// The BVH stack as two entries to a `uvec4` (BVH_STACK_PAIRS;
    /// `Api::bvh_stack_pairs` decides), not one to a `uvec2`.
    pub bvh_stack_pairs: bool,
    /// OpenGL's GLSL reads the wide tree's nodes through a buffer texture
    /// over the same buffer instead of its storage block (`Api::node_texels`
    /// decides; `shader::node_texels::node_texels_glsl` rewrites naga's reads).
    pub node_texels: bool,
    /// The experiments' names, in registry order, for the label.
    pub tags: Vec<String>,
}

/// The most entries `--experiment capped-bvh-stack` leaves a BVH stack: the
/// default teapot's (a test holds the two together), whose stack NVIDIA's
/// OpenGL runs on every multiprocessor.
pub const CAPPED_BVH_STACK: u32 = 31;

/// Which source the variant compiles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Form {
    /// Only the scene's features, as defines (the default).
    Scene,
    /// Every feature and the deepest stack (`--generic`).
    Generic,
    /// One source for every scene whose feature switches are specialization
    /// constants fixed by naga's process_overrides (`--specialize`).
    Specialized,
}

/// The loops' bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Counts {
    /// Baked in as constants (a bound read at run time made lavapipe compile
    /// and keep a new shader at every draw).
    Baked {
        spheres: u32,
        triangles: u32,
        lights: u32,
    },
    /// Read from the `Frame` uniform.
    Uniform,
}

/// The tracer's entry point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Entry {
    /// shaders/fullscreen.vert + shaders/trace.frag.
    Fragment,
    /// shaders/trace.comp with this workgroup.
    Compute(Workgroup),
}

impl Entry {
    pub fn new(path: RenderPath, workgroup: Workgroup) -> Entry {
        match path {
            RenderPath::Fragment => Entry::Fragment,
            RenderPath::Compute => Entry::Compute(workgroup),
        }
    }

    pub fn path(&self) -> RenderPath {
        match self {
            Entry::Fragment => RenderPath::Fragment,
            Entry::Compute(_) => RenderPath::Compute,
        }
    }
}

/// Changes to the shader source that only the laboratory asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ShaderKnobs {
    /// A BVH stack per walk instead of one at module scope.
    pub local_bvh_stack: bool,
    /// Compute: the BVH stack in shared memory where it fits.
    pub shared_bvh_stack: bool,
    /// The ray stack as four arrays instead of two of vec4 pairs.
    pub split_ray_stack: bool,
    /// No LIGHT_BEFORE_WALK where the plan would choose it.
    pub walk_then_shade: bool,
    /// No BVH_STACK_PAIRS where the plan would choose it.
    pub unpaired_bvh_stack: bool,
    /// The BVH stack at most `CAPPED_BVH_STACK` entries, pushes past it dropped.
    pub capped_bvh_stack: bool,
    /// No node texels where the plan would choose them: OpenGL reads the
    /// wide tree's nodes from their storage block, as Vulkan does.
    pub storage_nodes: bool,
    /// Compute: KiB of workgroup memory the tracer does not need.
    pub shared_pad_kib: Option<u32>,
    /// The arithmetic probe (shaders/lab/ulp.glsl) in place of the tracer's
    /// entry point, measuring this operation.
    pub ulp: Option<UlpOp>,
}

/// The SPIR-V compiler Vulkan's shader comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SpirvCompiler {
    #[default]
    Naga,
    /// Khronos' glslangValidator, from the same source and defines.
    Glslang,
}

/// How naga's output is finished before a driver sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Passes {
    pub compiler: SpirvCompiler,
    /// naga's zero initialisers on function-local arrays are taken out.
    pub strip_zero_init: bool,
    /// naga's loop bounding, where the laboratory forces it on or off
    /// (`None`: the build decides, see `build::loop_bounding`).
    pub loop_bounding: Option<bool>,
    /// `NoContraction` / `precise` on every float operation.
    pub no_contraction: bool,
    /// SPV_KHR_float_controls' strict IEEE modes.
    pub float_controls: bool,
    /// OpenGL's resources declared `restrict` / `Restrict`, as Vulkan's SPIR-V implies.
    pub restrict: bool,
    /// OpenGL compute: record each multiprocessor's highest warp slot.
    pub warp_probe: bool,
}

impl Default for Passes {
    /// The product's passes.
    fn default() -> Passes {
        Passes {
            compiler: SpirvCompiler::Naga,
            strip_zero_init: true,
            loop_bounding: None,
            no_contraction: false,
            float_controls: false,
            restrict: true,
            warp_probe: false,
        }
    }
}

/// The feature switches the tracer declares with `layout(constant_id = N)`
/// under SPECIALIZE: name and id (naga's process_overrides wants the id).
/// A test checks this table against the parsed module.
pub const SPEC_CONSTANTS: [(&str, u16); 4] = [
    ("SPEC_SPHERES", 0),
    ("SPEC_TRIANGLES", 1),
    ("SPEC_MIRROR", 2),
    ("SPEC_GLASS", 3),
];

/// The most shared memory the compute path's BVH stack may take: OpenGL
/// guarantees a workgroup 32 KiB (Vulkan only 16 KiB, but lavapipe, llvmpipe
/// and NVIDIA offer 32 KiB or more).
pub const SHARED_BVH_STACK_BUDGET: usize = 32 * 1024;

const ALL_FEATURES: Features = Features {
    spheres: true,
    triangles: true,
    mirror: true,
    glass: true,
};

impl Variant {
    /// Only what the features need: no triangle loop without triangles, no
    /// refraction code without glass, a ray stack sized to the depth. The
    /// counts are read from the uniform until `with_scene_data` bakes them.
    pub fn from_features(features: Features, max_depth: u32, numerics: Numerics) -> Variant {
        let ray_stack = features.ray_stack_entries(max_depth);
        Variant {
            features,
            form: Form::Scene,
            ray_stack,
            counts: Counts::Uniform,
            bvh_stack: None,
            bvh_width: 2,
            numerics,
            entry: Entry::Fragment,
            count_rays: false,
            knobs: ShaderKnobs::default(),
            passes: Passes::default(),
            light_before_walk: false,
            bvh_stack_pairs: false,
            node_texels: false,
            tags: Vec::new(),
        }
    }

    /// The scene's own variant, tracing through `bvh` where it has one.
    pub fn for_scene(scene: &Scene, bvh: Option<&Bvh>) -> Variant {
        Variant::from_features(scene.features(), scene.max_depth, scene.numerics)
            .with_scene_data(scene, bvh)
    }

    /// Every feature on, the deepest stack, the counts read from the `Frame`
    /// uniform: renders any scene (with the given numerics).
    pub fn generic(numerics: Numerics) -> Variant {
        let mut v = Variant::from_features(ALL_FEATURES, MAX_DEPTH, numerics);
        v.form = Form::Generic;
        v
    }

    /// The generic source with the scene's features as specialization
    /// constants. An array size cannot be an override, so the ray stack stays
    /// the deepest.
    pub fn specialized(scene: &Scene, bvh: Option<&Bvh>) -> Variant {
        let mut v = Variant::generic(scene.numerics).with_scene_data(scene, bvh);
        v.form = Form::Specialized;
        v.features = scene.features();
        v
    }

    /// What every variant built for one scene bakes in: the primitive and light
    /// counts that bound the shader's loops, and, with a BVH, a traversal stack
    /// exactly as deep as the built tree needs.
    pub fn with_scene_data(mut self, scene: &Scene, bvh: Option<&Bvh>) -> Variant {
        self.counts = Counts::Baked {
            spheres: scene.spheres.len() as u32,
            triangles: scene.triangles.len() as u32,
            lights: scene.lights.len() as u32,
        };
        self.bvh_stack = bvh.map(Bvh::stack_entries);
        self.bvh_width = bvh.map_or(2, |b| b.width.max(2));
        self
    }

    /// The ray stack's entries as the shader declares them (STACK_SIZE):
    /// `ray_stack` where the tracer walks a BVH, one more by brute force.
    /// Beside a BVH stack the spare entry's 32 bytes of local memory took
    /// NVIDIA's OpenGL box tracer from 240 to 272 B, past the 254 B where
    /// that driver idles multiprocessors (124 of 132 ran it; its 1080p and
    /// 4K frames 4-5 % longer). By brute force it is what keeps Vulkan's
    /// fragment compiler from holding the whole stack in registers: given
    /// five entries it took 113 registers instead of 95 and the box's frame
    /// took 7 % longer (docs/findings/bvh.md#the-boxs-tree-and-its-ray-stack-h200).
    /// A stack of one entry (no glass) has nothing to spare.
    pub fn ray_stack_declared(&self) -> u32 {
        if self.ray_stack > 1 && self.bvh_stack.is_none() {
            self.ray_stack + 1
        } else {
            self.ray_stack
        }
    }

    /// The BVH stack's entries as the shader declares them: the tree's, or
    /// with `--experiment capped-bvh-stack` at most `CAPPED_BVH_STACK`.
    pub fn bvh_stack_declared(&self) -> Option<u32> {
        let cap = if self.knobs.capped_bvh_stack {
            CAPPED_BVH_STACK
        } else {
            u32::MAX
        };
        self.bvh_stack.map(|n| n.min(cap))
    }

    /// This variant with the ray counters compiled in: the shader of the one
    /// untimed frame that counts rays. Everything else is the timed variant's,
    /// so both trace the same rays.
    pub fn counting(&self) -> Variant {
        Variant {
            count_rays: true,
            ..self.clone()
        }
    }

    /// This variant on another entry point.
    pub fn on(&self, entry: Entry) -> Variant {
        Variant {
            entry,
            ..self.clone()
        }
    }

    /// Whether the compute tracer keeps its BVH stack in shared memory: only
    /// with the laboratory's shared stack, and only where it fits the budget.
    pub fn bvh_stack_in_shared_memory(&self) -> bool {
        let (Some(entries), Entry::Compute(wg)) = (self.bvh_stack_declared(), self.entry) else {
            return false;
        };
        let bytes = entries as usize * (wg.x * wg.y) as usize * 8;
        self.knobs.shared_bvh_stack && bytes <= SHARED_BVH_STACK_BUDGET
    }

    /// The specialization constants (`Form::Specialized` only).
    pub fn constants(&self) -> BTreeMap<String, bool> {
        if self.form != Form::Specialized {
            return BTreeMap::new();
        }
        let f = self.features;
        SPEC_CONSTANTS
            .iter()
            .zip([f.spheres, f.triangles, f.mirror, f.glass])
            .map(|((name, _), on)| (name.to_string(), on))
            .collect()
    }

    /// The defines naga compiles the variant with: rendered here, at the end,
    /// from the typed choices.
    pub fn defines(&self) -> BTreeMap<String, String> {
        let mut d = BTreeMap::new();
        let mut flag = |on: bool, name: &str| {
            if on {
                d.insert(name.to_string(), "1".to_string());
            }
        };
        // The generic form compiles every feature; the specialised one's
        // switches are constants (the tracer defines every HAS_* under SPECIALIZE).
        let f = match self.form {
            Form::Scene => self.features,
            Form::Generic => ALL_FEATURES,
            Form::Specialized => Features {
                spheres: false,
                triangles: false,
                mirror: false,
                glass: false,
            },
        };
        flag(f.spheres, "HAS_SPHERES");
        flag(f.triangles, "HAS_TRIANGLES");
        flag(f.mirror, "HAS_MIRROR");
        flag(f.glass, "HAS_GLASS");
        flag(self.form == Form::Specialized, "SPECIALIZE");
        let k = self.knobs;
        let bvh = self.bvh_stack.is_some();
        flag(bvh, "USE_BVH");
        flag(bvh && self.bvh_width > 2, "USE_BVH_WIDE");
        flag(bvh && k.local_bvh_stack, "BVH_STACK_LOCAL");
        flag(k.split_ray_stack, "RAY_STACK_SPLIT");
        flag(self.light_before_walk, "LIGHT_BEFORE_WALK");
        flag(bvh && self.bvh_stack_pairs, "BVH_STACK_PAIRS");
        flag(self.count_rays, "COUNT_RAYS");
        flag(self.bvh_stack_in_shared_memory(), "BVH_STACK_SHARED");
        for n in self.numerics.defines() {
            flag(true, n);
        }
        d.insert("STACK_SIZE".into(), self.ray_stack_declared().to_string());
        if let (Some(n), Some(declared)) = (self.bvh_stack, self.bvh_stack_declared()) {
            d.insert("BVH_STACK".into(), declared.to_string());
            if declared < n {
                // trace/bvh.glsl then drops a push that finds the stack full.
                d.insert("BVH_STACK_FIXED".into(), "1".into());
            }
            if self.bvh_width > 2 {
                let quads = crate::scene::accel::wide::quads(self.bvh_width);
                d.insert("BVH_WIDE_QUADS".into(), quads.to_string());
            }
        }
        if let Counts::Baked {
            spheres,
            triangles,
            lights,
        } = self.counts
        {
            d.insert("SPHERE_COUNT".into(), format!("{spheres}u"));
            d.insert("TRIANGLE_COUNT".into(), format!("{triangles}u"));
            d.insert("LIGHT_COUNT".into(), format!("{lights}u"));
        }
        if let Some(kib) = k.shared_pad_kib {
            d.insert("SHARED_PAD_KIB".into(), kib.to_string());
        }
        if let Some(op) = k.ulp {
            d.insert(op.define(), "1".into());
        }
        // `local_size` must be a constant; a define keeps it out of the
        // specialisation-constant path naga's writers handle poorly.
        if let Entry::Compute(wg) = self.entry {
            d.insert("WG_X".into(), wg.x.to_string());
            d.insert("WG_Y".into(), wg.y.to_string());
        }
        d
    }

    /// Whether this variant can draw everything `needed` can: every feature of
    /// `needed` compiled in, and a ray stack at least as deep, with every other
    /// choice the same. A windowed app keeps its pipeline when `+`/`-` change
    /// the depth to one the current variant covers.
    pub fn covers(&self, needed: &Variant) -> bool {
        let compiled = |v: &Variant| match v.form {
            Form::Generic => ALL_FEATURES,
            _ => v.features,
        };
        let (a, b) = (compiled(self), compiled(needed));
        let features = if self.form == Form::Specialized || needed.form == Form::Specialized {
            self.form == needed.form && a == b
        } else {
            (a.spheres || !b.spheres)
                && (a.triangles || !b.triangles)
                && (a.mirror || !b.mirror)
                && (a.glass || !b.glass)
        };
        features
            && self.ray_stack >= needed.ray_stack
            && Variant {
                features: needed.features,
                form: needed.form,
                ray_stack: needed.ray_stack,
                ..self.clone()
            } == *needed
    }

    /// A short label such as `spheres+triangles+mirror+glass/stack6/normal-scaled/watertight/stable`
    /// (with `/bvhN` when the variant traces through a BVH with an N-entry
    /// stack, preceded by `/wide4` or `/wide8` for a wide one, `/spec` when
    /// specialised, `/light-first` with LIGHT_BEFORE_WALK, then any
    /// experiment's name).
    pub fn label(&self) -> String {
        let f = match self.form {
            Form::Generic => ALL_FEATURES,
            _ => self.features,
        };
        let mut parts: Vec<&str> = [
            (f.spheres, "spheres"),
            (f.triangles, "triangles"),
            (f.mirror, "mirror"),
            (f.glass, "glass"),
        ]
        .iter()
        .filter(|(on, _)| *on)
        .map(|(_, n)| *n)
        .collect();
        if parts.is_empty() {
            parts.push("background");
        }
        let bvh = match (self.bvh_stack_declared(), self.bvh_width) {
            (None, _) => String::new(),
            (Some(n), 2) => format!("/bvh{n}"),
            (Some(n), w) => format!("/wide{w}/bvh{n}"),
        };
        let spec = if self.form == Form::Specialized {
            "/spec"
        } else {
            ""
        };
        let light = if self.light_before_walk {
            "/light-first"
        } else {
            ""
        };
        let texels = if self.node_texels { "/node-texels" } else { "" };
        let tags: String = self.tags.iter().map(|t| format!("/{t}")).collect();
        format!(
            "{}/stack{}/{}{bvh}{spec}{light}{texels}{tags}",
            parts.join("+"),
            self.ray_stack_declared(),
            self.numerics.label()
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_changes_rebuild_only_when_the_variant_cannot_cover_them() {
        let scene = Scene::load("box", &[]).unwrap();
        let deep = Variant::for_scene(&scene, None);
        let mut shallow_scene = scene.clone();
        shallow_scene.max_depth = 2;
        let shallow = Variant::for_scene(&shallow_scene, None);
        assert!(
            deep.covers(&shallow),
            "a deeper stack draws shallower scenes"
        );
        assert!(!shallow.covers(&deep), "a stack too small for the depth");
        shallow_scene.max_depth = 1;
        let flat = Variant::for_scene(&shallow_scene, None);
        assert!(
            !flat.covers(&shallow),
            "depth 1 compiles mirror and glass out"
        );
        let generic = Variant::generic(scene.numerics).with_scene_data(&scene, None);
        assert!(generic.covers(&deep));
        let teapot = Scene::load("teapot", &[]).unwrap();
        let generic_teapot = Variant::generic(teapot.numerics).with_scene_data(&teapot, None);
        assert!(
            !generic_teapot.covers(&deep),
            "the counts are baked in: another scene's shader cannot draw this one"
        );
    }

    #[test]
    fn defines_render_the_typed_choices() {
        let scene = Scene::load("box", &[]).unwrap();
        let v = Variant::for_scene(&scene, None);
        let d = v.defines();
        assert_eq!(d.get("SPHERE_COUNT").map(String::as_str), Some("2u"));
        assert!(d.contains_key("HAS_GLASS") && !d.contains_key("USE_BVH"));
        let c = v.on(Entry::Compute(Workgroup { x: 8, y: 4 })).defines();
        assert_eq!(c.get("WG_X").map(String::as_str), Some("8"));
        let s = Variant::specialized(&scene, None);
        assert!(s.defines().contains_key("SPECIALIZE") && !s.defines().contains_key("HAS_GLASS"));
        assert_eq!(s.constants().get("SPEC_GLASS"), Some(&true));
    }
}
