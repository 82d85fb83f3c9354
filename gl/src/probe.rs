//! `--experiment warp-probe` (OpenGL, compute path, NVIDIA): the buffer in
//! which each invocation of the probed tracer raises its multiprocessor's word
//! to its warp slot + 1 (`shader::post::warp_probe_glsl`), and what is read
//! off it: how many warps each multiprocessor held at once at most. OpenGL
//! reports no register count, so this is how its occupancy is seen; Vulkan's
//! follows from the register count in its pipeline statistics.

use anyhow::{anyhow, bail, Context as _};
use glow::HasContext;
use twinray_common::gpu::layout::binding;

/// More words than any GPU has multiprocessors (gl_SMIDNV indexes them).
const SLOTS: usize = 4096;

pub struct WarpProbe<'gl> {
    gl: &'gl glow::Context,
    buffer: glow::Buffer,
}

impl<'gl> WarpProbe<'gl> {
    /// The zeroed buffer, bound where the probed shader writes; refused (exit
    /// 2) where the driver lacks GL_NV_shader_thread_group.
    pub fn new(gl: &'gl glow::Context) -> anyhow::Result<WarpProbe<'gl>> {
        if !gl
            .supported_extensions()
            .contains("GL_NV_shader_thread_group")
        {
            return Err(twinray_common::error::bad_input(
                "--experiment warp-probe needs GL_NV_shader_thread_group (NVIDIA's OpenGL driver), which this driver lacks",
            ));
        }
        let zeros = vec![0u8; SLOTS * 4];
        // SAFETY: a fresh buffer on the current context; `zeros` is copied by the driver.
        unsafe {
            let buffer = gl
                .create_buffer()
                .map_err(|e| anyhow!(e))
                .context("glCreateBuffer (warp probe)")?;
            gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(buffer));
            gl.buffer_data_u8_slice(glow::SHADER_STORAGE_BUFFER, &zeros, glow::DYNAMIC_READ);
            gl.bind_buffer_base(
                glow::SHADER_STORAGE_BUFFER,
                binding::WARP_PROBE,
                Some(buffer),
            );
            Ok(WarpProbe { gl, buffer })
        }
    }

    /// One sentence: the multiprocessors seen and their highest warp slots.
    pub fn summary(&self) -> anyhow::Result<String> {
        let mut bytes = vec![0u8; SLOTS * 4];
        // SAFETY: the buffer holds SLOTS words; the barrier orders the
        // shader's atomics before the read.
        unsafe {
            self.gl.memory_barrier(glow::BUFFER_UPDATE_BARRIER_BIT);
            self.gl
                .bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(self.buffer));
            self.gl
                .get_buffer_sub_data(glow::SHADER_STORAGE_BUFFER, 0, &mut bytes);
        }
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
        let mut seen: Vec<u32> = words.into_iter().filter(|&w| w > 0).collect();
        if seen.is_empty() {
            bail!("--experiment warp-probe: no invocation wrote the probe buffer");
        }
        seen.sort_unstable();
        Ok(format!(
            "warp probe: {} multiprocessors; warps resident at once per multiprocessor (highest gl_WarpIDNV + 1): min {}, median {}, max {}",
            seen.len(),
            seen[0],
            seen[seen.len() / 2],
            seen[seen.len() - 1]
        ))
    }
}

impl Drop for WarpProbe<'_> {
    fn drop(&mut self) {
        // SAFETY: created on this context, which outlives it.
        unsafe { self.gl.delete_buffer(self.buffer) }
    }
}
