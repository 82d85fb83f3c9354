//! One plan per run. `Planner::new` reads the options once — the laboratory's
//! check and changes, the workgroup, the outputs — and says what the run asks
//! of the device, before a device exists. Then
//! `prepare` gives everything the GPU receives: the scene, its BVH (built once,
//! timed as a step of its own), the typed shader variant, the buffers' bytes
//! (checked against the device's storage limit) and the compiled shaders of
//! the one path that runs. The headless run, the window's start, each of its
//! scene switches and the counting frame all come from here, so they cannot
//! disagree about what a run is.

pub mod launch;
pub mod requests;

use crate::cli::{RenderArgs, RenderPath, Workgroup};
use crate::explain;
use crate::gpu::layout::{Bvh, WIDE_NODE_TEXELS};
use crate::gpu::upload::{check_storage_limit, GpuScene};
use crate::lab::{self, Changes};
use crate::limits::StorageLimit;
use crate::reference::image_io::FloatImage;
use crate::report::{dump_statistics, DeviceInfo, FrameTime, RunReport, ShaderStats};
use crate::scene::camera::local_origin;
use crate::scene::Scene;
use crate::shader::build::PathShaders;
use crate::shader::variant::{Entry, Variant};
use requests::{Api, DeviceRequest};
use std::time::Instant;

/// The run's options, checked and turned into choices; makes the plans.
#[derive(Debug, Clone)]
pub struct Planner {
    args: RenderArgs,
    api: Api,
    changes: Changes,
    /// `--workgroup`, if given (`workgroup` gives the default otherwise).
    workgroup: Option<Workgroup>,
}

/// Everything one scene needs on the GPU, decided and prepared.
pub struct RunPlan {
    pub scene: Scene,
    /// The BVH the variant traces through, built over the primitives as the
    /// GPU holds them (relative to the local origin).
    pub bvh: Option<Bvh>,
    /// How long the build took.
    pub bvh_ms: Option<f64>,
    pub variant: Variant,
    /// The size the plan was prepared for (the window's may change since).
    pub size: (u32, u32),
    /// The shaders of the variant's path, compiled.
    pub shaders: PathShaders,
    /// A headless compute frame times its barrier with its dispatch
    /// (`--experiment timed-barrier`); by default each API times the dispatch alone.
    pub timed_barrier: bool,
    /// Dispatches of the tracer in a headless compute frame's timed span, with
    /// no barrier between them: 1, or 2 with `--experiment back-to-back`.
    pub frame_dispatches: u32,
    /// The compute path hands out the costliest tiles first (`launch`);
    /// in rows with `--experiment row-order`.
    pub launch_by_cost: bool,
}

/// What the untimed ray-counting frame renders (`--count-rays`), in either
/// app: the plan's scene at a size, with the counting variant of its shader.
pub struct CountingRun<'a> {
    pub gpu: &'a GpuScene<'a>,
    /// The counting variant, on the path that is drawing.
    pub variant: Variant,
    pub width: u32,
    pub height: u32,
}

impl Planner {
    /// How every run of either app begins: `--experiments` prints the
    /// laboratory's page (`None`: nothing more to do), `--explain` turns the
    /// printout on, and the options are checked once.
    pub fn start(args: &RenderArgs, api: Api) -> anyhow::Result<Option<Planner>> {
        if lab::print_page_if_asked(args) {
            return Ok(None);
        }
        if args.explain {
            explain::enable(api.program(), api.name());
        }
        Planner::new(args, api).map(Some)
    }

    /// Checks the options (one sentence and exit 2 for what this run cannot
    /// do) and decides everything that needs no scene.
    pub fn new(args: &RenderArgs, api: Api) -> anyhow::Result<Planner> {
        lab::check(args, api)?;
        let workgroup = args.compute_workgroup()?;
        args.check_outputs()?;
        let changes = lab::changes(args);
        Ok(Planner {
            args: args.clone(),
            api,
            changes,
            workgroup,
        })
    }

    pub fn args(&self) -> &RenderArgs {
        &self.args
    }

    /// What the device must offer.
    pub fn device(&self) -> DeviceRequest {
        DeviceRequest {
            count_rays: self.args.count_rays,
        }
    }

    /// The compute path's workgroup for a tracer that walks `bvh` or none:
    /// `--workgroup`, or the app's default for it (also kept while the
    /// fragment path draws).
    pub fn workgroup(&self, bvh: Option<&Bvh>) -> Workgroup {
        self.workgroup
            .unwrap_or(self.api.default_workgroup(bvh.is_some()))
    }

    /// The plan for `--scene` with every `--set`, at `width`×`height`.
    pub fn prepare(
        &self,
        limit: &StorageLimit,
        width: u32,
        height: u32,
    ) -> anyhow::Result<RunPlan> {
        let args = &self.args;
        self.prepare_scene(
            &args.scene,
            &args.overrides()?,
            args.path,
            limit,
            (width, height),
        )
    }

    /// A window's switch to the built-in scene `name`: every `--set` that
    /// applies to it is kept, and each one that cannot is dropped with the
    /// reason (which the window prints), instead of refusing the switch.
    pub fn prepare_switch(
        &self,
        name: &str,
        path: RenderPath,
        limit: &StorageLimit,
        width: u32,
        height: u32,
    ) -> anyhow::Result<(RunPlan, Vec<String>)> {
        let (kept, dropped) = Scene::applicable_overrides(name, &self.args.overrides()?);
        let plan = self.prepare_scene(name, &kept, path, limit, (width, height))?;
        Ok((plan, dropped))
    }

    fn prepare_scene(
        &self,
        name: &str,
        overrides: &[(String, String)],
        path: RenderPath,
        limit: &StorageLimit,
        (width, height): (u32, u32),
    ) -> anyhow::Result<RunPlan> {
        let scene = Scene::load_limited(name, overrides, limit)?;
        explain::numbered(0, "Scene (twinray-common)", || {
            format!(
                "{}: {} spheres, {} triangles, {} lights",
                scene.name,
                scene.spheres.len(),
                scene.triangles.len(),
                scene.lights.len()
            )
        });
        let (bvh, bvh_ms) = if self.args.accel.wants_bvh(&scene) {
            let t0 = Instant::now();
            let (binary, width) = (build_bvh(&scene), self.args.accel.width());
            let bvh = if self.changes.first_of_equals {
                binary.widen_first_of_equals(width)
            } else if self.changes.greedy_collapse {
                binary.widen_greedy(width)
            } else {
                binary.widen(width)
            };
            let ms = t0.elapsed().as_secs_f64() * 1e3;
            explain::numbered(0, "BVH (twinray-common)", || {
                format!(
                    "{} {}-wide nodes over {} primitives, {} deep, SAH cost {:.3}; built in {ms:.1} ms ({:.1} M primitives/s)",
                    bvh.node_count(),
                    bvh.width,
                    scene.primitive_count(),
                    bvh.depth,
                    bvh.sah_cost(),
                    scene.primitive_count() as f64 / ms.max(1e-3) / 1e3
                )
            });
            (Some(bvh), Some(ms))
        } else {
            (None, None)
        };
        let variant = self.variant(&scene, bvh.as_ref(), path, limit.texel_buffer);
        check_storage_limit(&GpuScene::new(&scene, bvh.as_ref(), width, height), limit)?;
        let shaders = PathShaders::build(&variant)?;
        let target = match self.api {
            Api::Vulkan => "SPIR-V",
            Api::OpenGl => "GLSL 450 core",
        };
        explain::numbered(
            0,
            &format!("Shaders: GLSL -> naga module -> {target} (twinray-common)"),
            || format!("variant {}, {} path", variant.label(), variant.entry.path()),
        );
        Ok(RunPlan {
            scene,
            bvh,
            bvh_ms,
            variant,
            size: (width, height),
            shaders,
            timed_barrier: self.changes.timed_barrier,
            frame_dispatches: if self.changes.back_to_back { 2 } else { 1 },
            launch_by_cost: !self.changes.row_order,
        })
    }

    /// A headless run's `--json` report, the same in both APIs: the device,
    /// the plan's scene, variant (as `variant_label` names it) and BVH, the
    /// size and path, the timed frames, the last frame's non-finite pixels
    /// and what the driver said of the shaders, which `--dump-shaders` also
    /// writes beside them.
    pub fn report(
        &self,
        plan: &RunPlan,
        (api, device, variant_label): (&str, DeviceInfo, String),
        (frames, setup_ms): (Vec<FrameTime>, f64),
        image: &FloatImage,
        shader_stats: Vec<ShaderStats>,
    ) -> anyhow::Result<RunReport> {
        let args = &self.args;
        if let Some(dir) = &args.dump_shaders {
            dump_statistics(dir, &shader_stats)?;
        }
        Ok(
            RunReport::builder(api, device, plan.scene.stats(), variant_label)
                .size(args.size.width, args.size.height)
                .path(args.path, self.workgroup(plan.bvh.as_ref()))
                .frames(frames, setup_ms)
                .nonfinite_pixels(image.nonfinite_pixels())
                .shader_stats(shader_stats)
                .bvh(plan.bvh.as_ref(), plan.bvh_ms)
                .build(),
        )
    }

    /// The variant the apps render for `scene` on `path`: `--generic`,
    /// `--specialize` or the scene's own, tracing through `bvh` where there is
    /// one, with the laboratory's changes. `texel_buffer` is the most texels
    /// the device's buffer textures hold (`StorageLimit::texel_buffer`).
    pub fn variant(
        &self,
        scene: &Scene,
        bvh: Option<&Bvh>,
        path: RenderPath,
        texel_buffer: u64,
    ) -> Variant {
        let mut v = if self.args.generic {
            Variant::generic(scene.numerics).with_scene_data(scene, bvh)
        } else if self.args.specialize {
            Variant::specialized(scene, bvh)
        } else {
            Variant::for_scene(scene, bvh)
        };
        let c = &self.changes;
        v.knobs = c.knobs;
        v.passes = c.passes;
        if let Some(counts) = c.counts {
            v.counts = counts;
        }
        v.tags = c.tags.clone();
        v.entry = Entry::new(path, self.workgroup(bvh));
        v.bvh_stack_pairs = !c.knobs.unpaired_bvh_stack
            && v.bvh_stack_declared()
                .is_some_and(|n| self.api.bvh_stack_pairs(n));
        v.light_before_walk = !c.knobs.walk_then_shade
            && self
                .api
                .light_before_walk(bvh.is_some(), path, scene.lights.len());
        // A wide tree whose GPU copy (a sentinel node first, upload.rs) fits
        // the device's buffer textures.
        let wide_fits = bvh.is_some_and(|b| {
            b.width > 2 && (b.wide.len() as u64 + 1) * u64::from(WIDE_NODE_TEXELS) <= texel_buffer
        });
        // The arithmetic probe (`--experiment ulp`) replaces the tracer and
        // reads no node: there is no read to rewrite as a texel fetch.
        v.node_texels = c.knobs.ulp.is_none()
            && !c.knobs.storage_nodes
            && !self.args.gl_spirv
            && self.api.node_texels(wide_fits);
        v
    }
}

/// The BVH a run traces `scene` through: built over the primitives as the GPU
/// holds them, relative to the local origin, so its boxes round in that frame.
pub fn build_bvh(scene: &Scene) -> Bvh {
    Bvh::build_at(scene, local_origin(scene))
}

impl RunPlan {
    /// The buffers' bytes at the size the plan was prepared for, made from
    /// the plan's scene and BVH as the upload reads them (`GpuScene`).
    pub fn gpu(&self) -> GpuScene<'_> {
        self.gpu_at(self.size.0, self.size.1)
    }

    /// The buffers at `width`×`height` without a launch order, so that
    /// compute frames take their tiles in rows (`launch`): a window's, whose
    /// moving camera and changing size would leave an order stale, and the
    /// untimed counting frame's, whose time no one reads.
    pub fn gpu_in_rows(&self, width: u32, height: u32) -> GpuScene<'_> {
        GpuScene::new(&self.scene, self.bvh.as_ref(), width, height)
    }

    /// The same at `width`×`height`. On the compute path, with the launch
    /// order for that size (`launch`),
    /// unless the frame is too small to need one or `--experiment row-order`
    /// keeps the dispatch's rows.
    pub fn gpu_at(&self, width: u32, height: u32) -> GpuScene<'_> {
        let gpu = GpuScene::new(&self.scene, self.bvh.as_ref(), width, height);
        let Entry::Compute(workgroup) = self.variant.entry else {
            return gpu;
        };
        if !(self.launch_by_cost && launch::worth_ordering((width, height), workgroup)) {
            return gpu;
        }
        let t0 = Instant::now();
        let order =
            launch::launch_order(&self.scene, self.bvh.as_ref(), (width, height), workgroup);
        explain::numbered(0, "Launch order (twinray-common)", || {
            format!(
                "{} tiles of {}x{}, costliest first by the rays of one pixel in {}, {} seeing nothing; ranked in {:.1} ms",
                order.tiles.len(),
                workgroup.x,
                workgroup.y,
                launch::sample_step((width, height)).pow(2),
                order.tiles.iter().filter(|&&t| t & launch::EMPTY_TILE != 0).count(),
                t0.elapsed().as_secs_f64() * 1e3
            )
        });
        gpu.with_launch_order(order.grid, order.tiles)
    }

    /// The counting frame of this plan on its own path, at `width`×`height`
    /// (the window's size may differ from the plan's), with `gpu` as its buffers.
    pub fn counting<'a>(&self, gpu: &'a GpuScene<'a>, width: u32, height: u32) -> CountingRun<'a> {
        CountingRun {
            gpu,
            variant: self.variant.counting(),
            width,
            height,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::Size;
    use crate::plan::requests::Api;

    /// OpenGL's node texels: only its walks over a wide tree that fits the
    /// device's buffer textures, on either path, and never under `--gl-spirv`
    /// (whose SPIR-V the pass never sees) or `--experiment storage-nodes`.
    #[test]
    fn only_opengls_walks_over_a_wide_tree_read_node_texels() {
        let scene = Scene::load("teapot", &[]).unwrap();
        let binary = build_bvh(&scene);
        let wide = build_bvh(&scene).widen(4);
        let texels = (wide.wide.len() as u64 + 1) * u64::from(WIDE_NODE_TEXELS);
        let args = RenderArgs::headless(
            "teapot",
            Size {
                width: 8,
                height: 8,
            },
        );
        let reads = |args: &RenderArgs, api, bvh: &Bvh, path, limit| {
            Planner::new(args, api)
                .unwrap()
                .variant(&scene, Some(bvh), path, limit)
                .node_texels
        };
        let (compute, fragment) = (RenderPath::Compute, RenderPath::Fragment);
        assert!(reads(&args, Api::OpenGl, &wide, compute, texels));
        assert!(
            !reads(&args, Api::OpenGl, &wide, compute, texels - 1),
            "too many texels"
        );
        assert!(!reads(&args, Api::Vulkan, &wide, compute, texels));
        assert!(reads(&args, Api::OpenGl, &wide, fragment, texels));
        assert!(!reads(&args, Api::Vulkan, &wide, fragment, texels));
        assert!(!reads(&args, Api::OpenGl, &binary, compute, u64::MAX));
        let spirv = RenderArgs {
            gl_spirv: true,
            ..args.clone()
        };
        assert!(!reads(&spirv, Api::OpenGl, &wide, compute, texels));
        let storage = RenderArgs {
            experiment: vec![crate::lab::experiment::Experiment::StorageNodes],
            ..args.clone()
        };
        assert!(!reads(&storage, Api::OpenGl, &wide, compute, texels));
    }
}
