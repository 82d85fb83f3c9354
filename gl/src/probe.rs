//! The warp probe (OpenGL, compute path, NVIDIA; docs/experiments.md): the buffer in
//! which each invocation of the probed tracer raises its multiprocessor's word
//! to its warp slot + 1 (`shader::post::warp_probe_glsl`), and what is read
//! off it: how many warps each multiprocessor held at once at most. OpenGL
//! reports no register count, so this is how its occupancy is seen; Vulkan's
//! follows from the register count in its pipeline statistics.

use crate::buffers::ReadbackBuffer;
use anyhow::bail;
use glow::HasContext;
use twinray_common::gpu::layout::binding;

/// More words than any GPU has multiprocessors (gl_SMIDNV indexes them).
const SLOTS: usize = 4096;

pub struct WarpProbe<'gl> {
    buffer: ReadbackBuffer<'gl>,
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
                "the warp probe needs GL_NV_shader_thread_group (NVIDIA's OpenGL driver), which this driver lacks",
            ));
        }
        let buffer = ReadbackBuffer::new(gl, binding::WARP_PROBE, SLOTS * 4, "warp probe")?;
        Ok(WarpProbe { buffer })
    }

    /// One sentence: the multiprocessors seen and their highest warp slots.
    pub fn summary(&self) -> anyhow::Result<String> {
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&self.buffer.read());
        let mut seen: Vec<u32> = words.into_iter().filter(|&w| w > 0).collect();
        if seen.is_empty() {
            bail!("the warp probe: no invocation wrote the probe buffer");
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
