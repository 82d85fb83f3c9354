//! What a run asks of the API outside the shader: of the device (the
//! atomics the counting frame needs), and which app is asking. Both apps
//! read these, so Vulkan and OpenGL ask alike.

use crate::cli::RenderPath;

/// What the device must offer beyond what every run needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct DeviceRequest {
    /// The atomics the counting frame needs (`--count-rays`).
    pub count_rays: bool,
}

/// Which app is running: the one place a run's rules differ by API.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Api {
    Vulkan,
    OpenGl,
}

/// The deepest BVH stack OpenGL keeps in pairs (`Api::bvh_stack_pairs`):
/// the default teapot's tree (31 entries), 256 B of local memory. In one
/// entry a `uvec2` that tree's tracer reports 496 B and its 1000² and
/// 1080p frames are 3-4 % shorter (docs/findings/bvh.md#the-trees-top-h200),
/// but no study scene's OpenGL tracer is to report more than 256 B.
pub const PAIRED_STACK_MOST: u32 = 32;

impl Api {
    pub fn name(&self) -> &'static str {
        match self {
            Api::Vulkan => "Vulkan",
            Api::OpenGl => "OpenGL",
        }
    }

    /// The compute path's workgroup where `--workgroup` does not set one, for
    /// a tracer that walks a BVH (`bvh`) or tests every primitive. One warp,
    /// 8x4, except for the BVH walks:
    /// - Vulkan's take 8x16: at 64 invocations or more its driver compiles
    ///   the teapot's walk to 64 registers and 36 bytes of shared memory per
    ///   invocation instead of 76 registers, and 8x16 took the 1080p teapot
    ///   from 0.219 to 0.196 ms
    ///   (docs/findings/opengl-compute.md#each-apis-workgroup).
    /// - OpenGL's take 4x8, still one warp (its driver is slower with more):
    ///   0.2-7 % faster than 8x4 at every teapot point, and 4.5 % slower on
    ///   the 10k sphere list's small frame
    ///   (docs/findings/opengl-compute.md#what-closed-the-gap; data:
    ///   f8d14ba:comparison/results/nvidia-h100/investigation/one-ray/).
    ///
    /// Brute force stays at 8x4 in both: 8x16 cost Vulkan's teapot up to 10 %.
    /// `--workgroup WxH` runs both apps at one shape.
    pub fn default_workgroup(&self, bvh: bool) -> crate::cli::Workgroup {
        match (self, bvh) {
            (Api::Vulkan, true) => crate::cli::Workgroup { x: 8, y: 16 },
            (Api::OpenGl, true) => crate::cli::Workgroup { x: 4, y: 8 },
            _ => crate::cli::Workgroup { x: 8, y: 4 },
        }
    }

    /// Whether the tracer shades a scene's one light before its shadow walk,
    /// with the hit's secondary rays pushed first (LIGHT_BEFORE_WALK in
    /// shaders/trace/loop.glsl): on OpenGL's BVH walks on the compute path.
    /// There NVIDIA's OpenGL holds 28 warps a multiprocessor on the sphere
    /// list instead of 24, and its 1080p frames are 6-7 % shorter. Vulkan's
    /// driver gains nothing from it (1-4 % slower), nor does brute force,
    /// where OpenGL's glass box lost 6 % on the fragment path
    /// (docs/findings/opengl-compute.md#the-one-lights-share-before-its-walk-h200).
    /// Like the workgroup, each API runs the form it runs best; the image is
    /// the same.
    pub fn light_before_walk(
        &self,
        bvh: bool,
        path: crate::cli::RenderPath,
        lights: usize,
    ) -> bool {
        *self == Api::OpenGl && bvh && path == RenderPath::Compute && lights == 1
    }

    /// Whether the tracer reads the wide tree's nodes through a buffer texture
    /// (`texelFetch` on a `samplerBuffer` over the node buffer) instead of
    /// its storage block: on OpenGL's BVH walks, on both paths, where the tree
    /// fits the device's largest buffer texture. NVIDIA's OpenGL guards each
    /// storage read with a bounds check that clears the registers before a
    /// predicated load; a texel fetch needs neither. On an H200 OpenGL's
    /// teapot frames were 2-5 % shorter on the compute path and 6-9 % on the
    /// fragment path, its 1080p sphere lists 1 % and 5 %, its 300² ones on
    /// the compute path up to 1.6 % longer; not one pixel moved
    /// (docs/findings/opengl-compute.md#the-nodes-through-a-buffer-texture-h200,
    /// docs/findings/fragment-gap.md#the-nodes-through-a-buffer-texture-h200).
    /// Vulkan keeps its storage reads: naga has no texel buffers, and through
    /// glslang's SPIR-V the same reads cost Vulkan 6-7 % at scale
    /// (f8d14ba:comparison/results/nvidia-h100/investigation/texel-nodes/vk/tv.txt).
    pub fn node_texels(&self, wide: bool) -> bool {
        *self == Api::OpenGl && wide
    }

    /// Whether a BVH stack of `entries` holds two entries to a `uvec4`
    /// (BVH_STACK_PAIRS in shaders/trace/bvh.glsl), not one to a `uvec2`:
    /// on OpenGL, for trees of at most `PAIRED_STACK_MOST` entries. Vulkan's
    /// driver gives an 8-byte entry 8 bytes, and without the test of which
    /// half an entry is in its teapot frames are 2-3 % shorter. NVIDIA's
    /// OpenGL compiler reports 16 bytes for each element of a local array, so
    /// one entry an element reads as twice the local memory (the teapot's
    /// tracer 256 to 496 B); yet it ran on as many multiprocessors as the
    /// pairs at every tree size, so its real footprint is the same, and it
    /// held 24 warps a multiprocessor to the pairs' 28. Up to the greedy
    /// collapse's teapot of 30 entries the pairs were as fast or faster at some points
    /// (4K, the 1080p sphere list); from the 307k-triangle teapot's 37 up the
    /// one-entry form was 4-6 % faster on the compute path and 3-6 % on the
    /// fragment path (docs/findings/bvh.md#the-stacks-form-in-opengl-h200).
    pub fn bvh_stack_pairs(&self, entries: u32) -> bool {
        *self == Api::OpenGl && entries <= PAIRED_STACK_MOST
    }

    /// The app's program name, as its messages begin.
    pub fn program(&self) -> &'static str {
        match self {
            Api::Vulkan => "twinray-vk",
            Api::OpenGl => "twinray-gl",
        }
    }
}

/// A device's compute limits, under the names its API gives them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ComputeLimits {
    pub group_size: [u32; 2],
    pub invocations: u32,
    pub group_count: [u32; 2],
    /// The API's names for the three limits, for the error.
    pub names: [&'static str; 3],
}

impl ComputeLimits {
    /// The workgroup against the limits (bad input: the user chose it), and
    /// the dispatch that covers `width`×`height`, which has limits of its own.
    /// Returns the group counts.
    pub fn dispatch(
        &self,
        wg: crate::cli::Workgroup,
        width: u32,
        height: u32,
    ) -> anyhow::Result<(u32, u32)> {
        let [size, invocations, count] = self.names;
        let l = self;
        if wg.x > l.group_size[0] || wg.y > l.group_size[1] || wg.x * wg.y > l.invocations {
            return Err(crate::error::bad_input(format!(
                "--workgroup {wg} exceeds this device's limits ({size} {}x{}, {invocations} {})",
                l.group_size[0], l.group_size[1], l.invocations
            )));
        }
        let groups = wg.tiles((width, height));
        if groups.0 > l.group_count[0] || groups.1 > l.group_count[1] {
            return Err(crate::error::bad_input(format!(
                "--size {width}x{height} with --workgroup {wg} needs {}x{} workgroups, more than this device's {count} {}x{}",
                groups.0, groups.1, l.group_count[0], l.group_count[1]
            )));
        }
        Ok(groups)
    }
}
