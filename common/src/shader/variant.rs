//! The one place a scene's shader variant is decided: `Variant::chosen`, from
//! the scene and the run's options, which both apps (headless and windowed) and
//! the comparison call. A variant is the map of defines (and, for
//! `--specialize`, specialization constants) that selects what trace.glsl
//! compiles: only the features the scene uses, its counts and BVH stack, its
//! numerical choices, and any `--experiment`.

use crate::cli::{Experiment, RenderArgs, RenderPath, Workgroup};
use crate::fragment_pass::QUAD_DEFINE;
use crate::gpu::upload::GpuScene;
use crate::limits::MAX_DEPTH;
use crate::scene::numerics::Numerics;
use crate::scene::{Features, Scene};
use crate::value_name::ValueName;
use std::collections::BTreeMap;

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

/// What the untimed ray-counting frame renders (`--count-rays`), in either
/// app: the run's scene at its size, on its path, with `variant.counting()`.
pub struct CountingRun<'a> {
    pub scene: &'a GpuScene,
    pub variant: &'a Variant,
    pub path: RenderPath,
    pub workgroup: Workgroup,
    pub width: u32,
    pub height: u32,
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

    /// This variant with the ray counters compiled in (COUNT_RAYS): the shader
    /// of the one untimed frame that counts rays. Every other define is the
    /// timed variant's, so both trace the same rays.
    pub fn counting(&self) -> Variant {
        let mut v = self.clone();
        v.defines.insert("COUNT_RAYS".into(), "1".into());
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
        if v.defines.contains_key("USE_BVH")
            && v.experiments.contains(&Experiment::UnpairedBvhStack)
        {
            v.defines.insert("BVH_STACK_UNPAIRED".into(), "1".into());
        }
        if v.defines.contains_key("USE_BVH") && v.experiments.contains(&Experiment::LocalBvhStack) {
            v.defines.insert("BVH_STACK_LOCAL".into(), "1".into());
        }
        if v.experiments.contains(&Experiment::SplitRayStack) {
            v.defines.insert("RAY_STACK_SPLIT".into(), "1".into());
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
        if v.experiments.contains(&Experiment::Quad) {
            v.defines.insert(QUAD_DEFINE.into(), "1".into());
        }
        if let Some(kib) = args.shared_pad {
            v.defines.insert("SHARED_PAD_KIB".into(), kib.to_string());
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
        Variant::from_features(all, MAX_DEPTH, numerics)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_changes_rebuild_only_when_the_variant_cannot_cover_them() {
        let scene = Scene::load("box", &[]).unwrap();
        let deep = Variant::for_scene(&scene);
        let mut shallow_scene = scene.clone();
        shallow_scene.max_depth = 2;
        let shallow = Variant::for_scene(&shallow_scene);
        assert!(
            deep.covers(&shallow),
            "a deeper stack draws shallower scenes"
        );
        assert!(!shallow.covers(&deep), "a stack too small for the depth");
        shallow_scene.max_depth = 1;
        let flat = Variant::for_scene(&shallow_scene);
        assert!(
            !flat.covers(&shallow),
            "depth 1 compiles mirror and glass out"
        );
        let mut generic = RenderArgs::headless(
            "box",
            crate::cli::Size {
                width: 8,
                height: 8,
            },
        );
        generic.generic = true;
        assert!(Variant::chosen(&scene, &generic).covers(&deep));
        let teapot = Scene::load("teapot", &[]).unwrap();
        assert!(
            !Variant::chosen(&teapot, &generic).covers(&deep),
            "the counts are baked in: another scene's shader cannot draw this one"
        );
    }
}
