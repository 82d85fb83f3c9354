//! The scene on the GPU: the `Frame` uniform buffer and the four storage
//! buffers, uploaded once from the bytes `common` builds for both APIs; and
//! the storage buffers a shader writes for the app to read back once (the ray
//! counts, the warp probe).

use anyhow::{anyhow, Context as _};
use glow::HasContext;
use twinray_common::explain;
use twinray_common::gpu::layout::binding;
use twinray_common::gpu::upload::{GpuScene, UPLOAD_CHUNK_BYTES};

pub struct SceneBuffers<'gl> {
    gl: &'gl glow::Context,
    /// UBO first, then the SSBOs in binding order.
    buffers: Vec<glow::Buffer>,
}

impl<'gl> SceneBuffers<'gl> {
    /// Uploads and binds everything. Bound by number because naga renames
    /// the blocks; UBO and SSBO binding points are separate spaces in GL, so
    /// the numbers are the Vulkan descriptor bindings unchanged. A storage
    /// buffer is allocated whole, then filled a chunk at a time from one
    /// reused chunk of host memory (`write_storage` converts the scene into
    /// it), so the host never holds a second full copy of a large scene.
    pub fn new(gl: &'gl glow::Context, scene: &GpuScene) -> anyhow::Result<SceneBuffers<'gl>> {
        let mut this = SceneBuffers {
            gl,
            buffers: Vec::with_capacity(1 + binding::STORAGE.len()),
        };
        let frame = scene.frame_bytes();
        let chunk_bytes = UPLOAD_CHUNK_BYTES.min(scene.largest_storage().1.max(frame.len()));
        // u32s: aligned for every GPU struct, which `write_storage` fills in place.
        let mut chunk = vec![0u32; chunk_bytes.div_ceil(4)];
        let chunk: &mut [u8] = bytemuck::cast_slice_mut(&mut chunk);
        let (len, ubo) = (frame.len(), glow::UNIFORM_BUFFER);
        this.upload(
            (ubo, binding::FRAME),
            len,
            std::slice::from_ref(&(0..len)),
            chunk,
            |_, bytes| bytes.copy_from_slice(frame),
        )?;
        for b in binding::STORAGE {
            let chunks = scene.chunks(b, chunk_bytes);
            let (len, ssbo) = (scene.storage_len(b), glow::SHADER_STORAGE_BUFFER);
            this.upload((ssbo, b), len, &chunks, chunk, |offset, bytes| {
                scene.write_storage(b, offset, bytes)
            })?;
        }
        Ok(this)
    }

    /// A buffer of `len` bytes at binding `index` of `target`, filled in
    /// `chunks` (byte ranges, none longer than `chunk`): `write(offset,
    /// bytes)` writes the contents from `offset` into `bytes`, part of `chunk`.
    fn upload(
        &mut self,
        (target, index): (u32, u32),
        len: usize,
        chunks: &[std::ops::Range<usize>],
        chunk: &mut [u8],
        write: impl Fn(usize, &mut [u8]),
    ) -> anyhow::Result<()> {
        // GL sizes and offsets are signed 32-bit here; the run plan's storage
        // limit keeps every scene buffer below that.
        let len =
            i32::try_from(len).map_err(|_| anyhow!("a {len}-byte buffer is too large for GL"))?;
        // SAFETY: a fresh buffer on the current context, allocated with
        // `len` bytes; every chunk lies within it (so its offset fits in i32)
        // and its bytes are copied by the driver.
        unsafe {
            let buf = self
                .gl
                .create_buffer()
                .map_err(|e| anyhow!(e))
                .with_context(|| format!("glCreateBuffer (binding {index})"))?;
            self.buffers.push(buf);
            self.gl.bind_buffer(target, Some(buf));
            // Written once, read every frame: STATIC_DRAW.
            self.gl.buffer_data_size(target, len, glow::STATIC_DRAW);
            for c in chunks {
                let bytes = &mut chunk[..c.len()];
                write(c.start, bytes);
                self.gl
                    .buffer_sub_data_u8_slice(target, c.start as i32, bytes);
            }
            self.gl.bind_buffer_base(target, index, Some(buf));
        }
        explain::numbered(
            5,
            &format!("glCreateBuffer + glBufferData + glBufferSubData + glBindBufferBase (binding {index})"),
            || {
                let kind = if target == glow::UNIFORM_BUFFER {
                    "UNIFORM_BUFFER"
                } else {
                    "SHADER_STORAGE_BUFFER"
                };
                format!(
                    "{len} bytes, {kind}, STATIC_DRAW: the driver picks the memory; filled in {} glBufferSubData",
                    chunks.len()
                )
            },
        );
        Ok(())
    }

    /// Rewrites the `Frame` uniform block (windowed: the camera moves). The
    /// driver orders this after the draws that still read the old contents.
    pub fn update_frame(&self, bytes: &[u8]) {
        // SAFETY: the buffer holds exactly one Frame, which `bytes` is.
        unsafe {
            self.gl
                .bind_buffer(glow::UNIFORM_BUFFER, Some(self.buffers[0]));
            self.gl
                .buffer_sub_data_u8_slice(glow::UNIFORM_BUFFER, 0, bytes);
        }
    }
}

impl Drop for SceneBuffers<'_> {
    fn drop(&mut self) {
        for &b in self.buffers.iter().rev() {
            // SAFETY: the buffer was created on this context, which outlives it;
            // GL keeps it alive for draws already issued.
            unsafe { self.gl.delete_buffer(b) }
        }
    }
}

/// A zeroed storage buffer bound at one binding, which a shader writes and the
/// app reads back once; deleted on drop.
pub struct ReadbackBuffer<'gl> {
    gl: &'gl glow::Context,
    buffer: glow::Buffer,
    bytes: usize,
}

impl<'gl> ReadbackBuffer<'gl> {
    /// `what` names it in errors (`glCreateBuffer (what)`).
    pub fn new(
        gl: &'gl glow::Context,
        index: u32,
        bytes: usize,
        what: &str,
    ) -> anyhow::Result<ReadbackBuffer<'gl>> {
        let zeros = vec![0u8; bytes];
        // SAFETY: a fresh buffer on the current context; `zeros` is copied by the driver.
        unsafe {
            let buffer = gl
                .create_buffer()
                .map_err(|e| anyhow!(e))
                .with_context(|| format!("glCreateBuffer ({what})"))?;
            gl.bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(buffer));
            // Written by the GPU, read back once.
            gl.buffer_data_u8_slice(glow::SHADER_STORAGE_BUFFER, &zeros, glow::DYNAMIC_READ);
            gl.bind_buffer_base(glow::SHADER_STORAGE_BUFFER, index, Some(buffer));
            Ok(ReadbackBuffer { gl, buffer, bytes })
        }
    }

    /// The contents as the shader left them.
    pub fn read(&self) -> Vec<u8> {
        let mut bytes = vec![0u8; self.bytes];
        // SAFETY: the buffer holds exactly `self.bytes`; the barrier orders the
        // shader's writes before the read.
        unsafe {
            self.gl.memory_barrier(glow::BUFFER_UPDATE_BARRIER_BIT);
            self.gl
                .bind_buffer(glow::SHADER_STORAGE_BUFFER, Some(self.buffer));
            self.gl
                .get_buffer_sub_data(glow::SHADER_STORAGE_BUFFER, 0, &mut bytes);
        }
        bytes
    }
}

impl Drop for ReadbackBuffer<'_> {
    fn drop(&mut self) {
        // SAFETY: created on this context, which outlives it.
        unsafe { self.gl.delete_buffer(self.buffer) }
    }
}
