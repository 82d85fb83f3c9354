//! The ray-counting frame (`--count-rays`), as in the Vulkan twin: the run's
//! own shader variant with COUNT_RAYS, drawn or dispatched once on the run's
//! path, untimed and after the timed frames, with buffers of its own. Each
//! pixel writes its rays by kind into its slot of a storage buffer (binding
//! 10), which is read back and added up. The timed program never sees it.

use crate::buffers::{ReadbackBuffer, SceneBuffers};
use crate::compute::Compute;
use crate::program::{EmptyVertexArray, Program};
use crate::target::Target;
use glow::HasContext;
use twinray_common::explain;
use twinray_common::gpu::layout::{binding, GpuRayCount};
use twinray_common::limits::pixel_count;
use twinray_common::plan::CountingRun;
use twinray_common::rays::RayKinds;
use twinray_common::shader::build::PathShaders;

/// Renders the counting frame of `run` and returns its rays by kind. Always
/// naga's GLSL (also under `--gl-spirv`): the rays do not depend on how the
/// driver was handed the shader.
pub fn count_rays(gl: &glow::Context, run: &CountingRun) -> anyhow::Result<RayKinds> {
    let (width, height) = (run.width, run.height);
    // Declared first, so deleted last: after the programs that use them.
    let _scene = SceneBuffers::new(gl, run.gpu, run.variant.node_texels)?;
    let counts = ReadbackBuffer::new(
        gl,
        binding::RAY_COUNTS,
        pixel_count(width, height) * size_of::<GpuRayCount>(),
        "ray counts",
    )?;
    match PathShaders::build(&run.variant)? {
        PathShaders::Fragment(shaders) => {
            let program = Program::new(gl, &shaders.vertex.glsl, &shaders.fragment.glsl)?;
            let _target = Target::new(gl, width, height)?;
            let vao = EmptyVertexArray::new(gl)?;
            program.bind(&vao);
            // SAFETY: program, VAO, buffers and FBO are bound and alive.
            unsafe { gl.draw_arrays(glow::TRIANGLES, 0, 3) };
        }
        PathShaders::Compute(shader) => {
            let compute = Compute::new(gl, &shader, None, width, height)?;
            compute.dispatch();
        }
    }
    let slots: Vec<GpuRayCount> = bytemuck::pod_collect_to_vec(&counts.read());
    let kinds = RayKinds::from_pixels(&slots);
    explain::numbered(
        11,
        "Ray count: one untimed frame of the COUNT_RAYS variant",
        || kinds.to_string(),
    );
    Ok(kinds)
}
