//! The ray-counting frame (`--count-rays`), as in the Vulkan twin: the run's
//! own shader variant with COUNT_RAYS, drawn or dispatched once on the run's
//! path, untimed and after the timed frames, with buffers of its own. Each
//! pixel writes its rays by kind into its slot of a storage buffer (binding
//! 10), which is read back and added up. The timed program never sees it.

use crate::buffers::SceneBuffers;
use crate::compute::Compute;
use crate::program::{EmptyVertexArray, Program};
use crate::target::Target;
use anyhow::{anyhow, Context as _};
use glow::HasContext;
use twinray_common::cli::RenderPath;
use twinray_common::explain;
use twinray_common::fragment_pass::FragmentPass;
use twinray_common::gpu::layout::{binding, GpuRayCount};
use twinray_common::limits::pixel_count;
use twinray_common::rays::RayKinds;
use twinray_common::shader::build::{build, build_compute};
use twinray_common::shader::variant::CountingRun;

/// Renders the counting frame of `run` and returns its rays by kind. Always
/// naga's GLSL (also under `--gl-spirv`): the rays do not depend on how the
/// driver was handed the shader.
pub fn count_rays(gl: &glow::Context, run: &CountingRun) -> anyhow::Result<RayKinds> {
    let (width, height) = (run.width, run.height);
    let counting = run.variant.counting();
    // Declared first, so deleted last: after the programs that use them.
    let _scene = SceneBuffers::new(gl, run.scene)?;
    let counts = CountBuffer::new(gl, pixel_count(width, height))?;
    match run.path {
        RenderPath::Fragment => {
            let shaders = build(&counting)?;
            let program = Program::new(gl, &shaders.vertex_glsl, &shaders.fragment_glsl)?;
            // The run's own fragment pass (`--experiment quad` draws two triangles).
            let pass = FragmentPass::of(&run.variant.experiments);
            let _target = Target::new(gl, width, height, &pass)?;
            let vao = EmptyVertexArray::new(gl)?;
            program.bind(&vao);
            // SAFETY: program, VAO, buffers and FBO are bound and alive.
            unsafe { gl.draw_arrays(glow::TRIANGLES, 0, pass.vertices() as i32) };
        }
        RenderPath::Compute => {
            let shader = build_compute(&counting, run.workgroup)?;
            let compute = Compute::new(gl, &shader, None, width, height)?;
            compute.dispatch();
        }
    }
    let kinds = RayKinds::from_pixels(&counts.read());
    explain::step(
        "Ray count: one untimed frame of the COUNT_RAYS variant",
        || kinds.to_string(),
    );
    Ok(kinds)
}

/// The per-pixel count slots, zeroed and bound at binding 10; deleted on drop.
struct CountBuffer<'gl> {
    gl: &'gl glow::Context,
    buffer: glow::Buffer,
    pixels: usize,
}

impl<'gl> CountBuffer<'gl> {
    fn new(gl: &'gl glow::Context, pixels: usize) -> anyhow::Result<CountBuffer<'gl>> {
        let zeros = vec![0u8; pixels * size_of::<GpuRayCount>()];
        // SAFETY: a fresh buffer on the current context; `zeros` is copied by the driver.
        unsafe {
            let buffer = gl
                .create_buffer()
                .map_err(|e| anyhow!(e))
                .context("glCreateBuffer (ray counts)")?;
            gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(buffer));
            // Written by the GPU once, read back once.
            gl.buffer_data_u8_slice(glow::SHADER_STORAGE_BUFFER, &zeros, glow::DYNAMIC_READ);
            gl.bind_buffer_base(
                glow::SHADER_STORAGE_BUFFER,
                binding::RAY_COUNTS,
                Some(buffer),
            );
            Ok(CountBuffer { gl, buffer, pixels })
        }
    }

    /// The slots as the counting frame left them.
    fn read(&self) -> Vec<GpuRayCount> {
        let mut bytes = vec![0u8; self.pixels * size_of::<GpuRayCount>()];
        // SAFETY: the buffer holds exactly `pixels` slots; the barrier orders
        // the shader's writes before the read.
        unsafe {
            self.gl.memory_barrier(glow::BUFFER_UPDATE_BARRIER_BIT);
            self.gl
                .bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(self.buffer));
            self.gl
                .get_buffer_sub_data(glow::SHADER_STORAGE_BUFFER, 0, &mut bytes);
        }
        bytemuck::pod_collect_to_vec(&bytes)
    }
}

impl Drop for CountBuffer<'_> {
    fn drop(&mut self) {
        // SAFETY: created on this context, which outlives it.
        unsafe { self.gl.delete_buffer(self.buffer) }
    }
}
