//! The scene on the GPU: the `Frame` uniform buffer and the storage buffers,
//! uploaded once from the bytes `common` builds for both APIs, with the buffer
//! texture over the wide tree's nodes where the variant reads them so
//! (`Variant::node_texels`); and the storage buffers a shader writes for the
//! app to read back once (the ray counts, the warp probe).
//!
//! The scene buffers are immutable (`glBufferStorage`) and filled by the GPU,
//! the way the Vulkan twin fills its device-local buffers (vk/src/memory.rs):
//! the CPU makes each chunk in one small staging buffer, mapped for the
//! writing (`glMapBufferRange`) and unmapped before `glCopyBufferSubData`
//! copies it across. A buffer the CPU may neither map nor rewrite is one the
//! driver need not shadow in system memory. Filled by `glBufferData` and
//! `glBufferSubData` directly, the buffers cost NVIDIA's GL driver about 150
//! bytes of host memory a triangle more than Vulkan's. Each chunk is mapped
//! and unmapped, not mapped once for good: the unmap is what the GL
//! specification makes the writes visible to the copy by, and a persistent
//! mapping without it gave NVIDIA's driver wrong BVH buffers
//! (docs/findings/startup.md#tried-and-not-kept; data:
//! f8d14ba:comparison/results/nvidia-h100/investigation/gl-upload/mapped/).

use anyhow::{anyhow, Context as _};
use glow::HasContext;
use twinray_common::explain;
use twinray_common::gpu::layout::binding;
use twinray_common::gpu::upload::{GpuScene, UPLOAD_CHUNK_BYTES};

pub struct SceneBuffers<'gl> {
    gl: &'gl glow::Context,
    /// UBO first, then the SSBOs in binding order.
    buffers: Vec<glow::Buffer>,
    /// The buffer texture over the node buffer, where the variant reads it.
    node_texels: Option<glow::Texture>,
}

impl<'gl> SceneBuffers<'gl> {
    /// Uploads and binds everything. Bound by number because naga renames
    /// the blocks; UBO and SSBO binding points are separate spaces in GL, so
    /// the numbers are the Vulkan descriptor bindings unchanged. The bytes are
    /// made in the staging buffer (`write_storage` converts the scene a chunk
    /// at a time), so the host never holds a second full copy of a large scene.
    /// With `node_texels` the node buffer is also bound as a buffer texture.
    pub fn new(
        gl: &'gl glow::Context,
        scene: &GpuScene,
        node_texels: bool,
    ) -> anyhow::Result<SceneBuffers<'gl>> {
        let frame = scene.frame_bytes();
        // One staging buffer, as large as the largest chunk any buffer needs.
        let chunk = UPLOAD_CHUNK_BYTES.min(scene.largest_storage().1.max(frame.len()));
        let mut uploads = Uploads::new(gl, chunk)?;
        // The uniform block first: the window rewrites it with glBufferSubData
        // when the camera moves, which needs DYNAMIC_STORAGE_BIT. Nothing
        // rewrites the storage buffers: no flags.
        let len = frame.len();
        uploads.add(
            (
                glow::UNIFORM_BUFFER,
                binding::FRAME,
                glow::DYNAMIC_STORAGE_BIT,
            ),
            len,
            std::slice::from_ref(&(0..len)),
            |_, bytes| bytes.copy_from_slice(frame),
        )?;
        for b in binding::STORAGE {
            let chunks = scene.chunks(b, chunk);
            uploads.add(
                (glow::SHADER_STORAGE_BUFFER, b, 0),
                scene.storage_len(b),
                &chunks,
                |offset, bytes| scene.write_storage(b, offset, bytes),
            )?;
        }
        let mut buffers = SceneBuffers {
            gl,
            buffers: uploads.finish(),
            node_texels: None,
        };
        if node_texels {
            buffers.bind_node_texels()?;
        }
        Ok(buffers)
    }

    /// The node buffer as an RGBA32F buffer texture at texture unit
    /// `binding::BVH_NODES`, where the tracer's `node_texels` sampler
    /// reads it (twinray_common::shader::node_texels): the same memory, no copy.
    fn bind_node_texels(&mut self) -> anyhow::Result<()> {
        let gl = self.gl;
        let slot = binding::STORAGE
            .iter()
            .position(|&b| b == binding::BVH_NODES);
        let buffer = self.buffers[1 + slot.expect("the nodes are a storage buffer")];
        // SAFETY: a fresh texture on the current context, made a view of a
        // live buffer of whole RGBA32F texels (GpuBvhWideNode is 7 of them);
        // the plan checked their count against GL_MAX_TEXTURE_BUFFER_SIZE.
        // `Drop` deletes it before the buffer.
        unsafe {
            let texture = gl
                .create_texture()
                .map_err(|e| anyhow!("creating the node buffer texture: {e}"))?;
            self.node_texels = Some(texture);
            gl.active_texture(glow::TEXTURE0 + binding::BVH_NODES);
            gl.bind_texture(glow::TEXTURE_BUFFER, Some(texture));
            gl.tex_buffer(glow::TEXTURE_BUFFER, glow::RGBA32F, Some(buffer));
            gl.active_texture(glow::TEXTURE0);
        }
        explain::numbered(
            5,
            &format!(
                "glCreateTextures + glTexBuffer (texture unit {})",
                binding::BVH_NODES
            ),
            || {
                "the node buffer again, as an RGBA32F buffer texture: the tracer reads the wide tree's nodes with texelFetch, which NVIDIA's OpenGL guards with no bounds check".to_string()
            },
        );
        Ok(())
    }

    /// Rewrites the `Frame` uniform block (windowed: the camera moves). The
    /// driver orders this after the draws that still read the old contents.
    pub fn update_frame(&self, bytes: &[u8]) {
        // SAFETY: the buffer holds exactly one Frame, which `bytes` is, and
        // was made with DYNAMIC_STORAGE_BIT.
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
        if let Some(texture) = self.node_texels {
            // SAFETY: made on this context, which outlives it.
            unsafe { self.gl.delete_texture(texture) }
        }
        delete_buffers(self.gl, &self.buffers);
    }
}

/// Deletes `buffers`, newest first. GL keeps a buffer alive for the commands
/// already issued that use it.
fn delete_buffers(gl: &glow::Context, buffers: &[glow::Buffer]) {
    for &b in buffers.iter().rev() {
        // SAFETY: the buffer was created on this context, which outlives it.
        unsafe { gl.delete_buffer(b) }
    }
}

/// A buffer's size as GL takes it. GL sizes and offsets are signed 32-bit
/// here; the run plan's storage limit keeps every scene buffer below that.
fn gl_size(len: usize) -> anyhow::Result<i32> {
    i32::try_from(len).map_err(|_| anyhow!("a {len}-byte buffer is too large for GL"))
}

/// Immutable buffers filled through one small staging buffer: each
/// [`Uploads::add`] makes a buffer and fills it a chunk at a time (the CPU
/// writes a chunk into the mapped staging buffer, the GPU copies it across,
/// and the CPU waits for the copy before writing the next), so that a scene
/// of any size needs only a few tens of MiB of memory. [`Uploads::finish`]
/// hands the buffers over; until then they are deleted with the uploads on an
/// error.
struct Uploads<'gl> {
    gl: &'gl glow::Context,
    staging: glow::Buffer,
    /// The staging buffer's size in bytes.
    len: usize,
    /// Filled and bound, in the order they were added.
    filled: Vec<glow::Buffer>,
}

impl<'gl> Uploads<'gl> {
    /// Uploads whose chunks are at most `len` bytes long.
    fn new(gl: &'gl glow::Context, len: usize) -> anyhow::Result<Uploads<'gl>> {
        let size = gl_size(len)?;
        // SAFETY: a fresh buffer on the current context, given `len` bytes of
        // storage that the CPU may map for writing; `Drop` deletes it.
        unsafe {
            let staging = gl
                .create_buffer()
                .map_err(|e| anyhow!(e))
                .context("glCreateBuffer (staging buffer)")?;
            gl.bind_buffer(glow::COPY_READ_BUFFER, Some(staging));
            gl.buffer_storage(glow::COPY_READ_BUFFER, size, None, glow::MAP_WRITE_BIT);
            Ok(Uploads {
                gl,
                staging,
                len,
                filled: Vec::new(),
            })
        }
    }

    /// An immutable buffer of `len` bytes with storage `flags`, bound at
    /// binding `index` of `target`, filled in `chunks` (byte ranges of at most
    /// the staging buffer's size): `write(offset, bytes)` writes the contents
    /// from `offset` into `bytes`, which is the staging buffer.
    fn add(
        &mut self,
        (target, index, flags): (u32, u32, u32),
        len: usize,
        chunks: &[std::ops::Range<usize>],
        write: impl Fn(usize, &mut [u8]),
    ) -> anyhow::Result<()> {
        let gl = self.gl;
        let size = gl_size(len)?;
        // SAFETY: a fresh buffer on the current context, given `len` bytes of
        // storage; every chunk lies within it and within the staging buffer
        // (so its offset and length fit in i32), whose mapping `write` gets
        // as a slice of exactly the chunk's length and no longer than the
        // map lasts; each copy is waited for before the staging buffer is
        // mapped again.
        unsafe {
            let buffer = gl
                .create_buffer()
                .map_err(|e| anyhow!(e))
                .with_context(|| format!("glCreateBuffer (binding {index})"))?;
            self.filled.push(buffer);
            gl.bind_buffer(glow::COPY_WRITE_BUFFER, Some(buffer));
            gl.buffer_storage(glow::COPY_WRITE_BUFFER, size, None, flags);
            gl.bind_buffer(glow::COPY_READ_BUFFER, Some(self.staging));
            for c in chunks {
                if c.len() > self.len {
                    let n = c.len();
                    return Err(anyhow!(
                        "a {n}-byte chunk for a {}-byte staging buffer",
                        self.len
                    ));
                }
                let (start, n) = (c.start as i32, c.len() as i32);
                // INVALIDATE_RANGE: nothing of the last chunk need survive,
                // so no driver copies it into the mapping (the copy that read
                // it has been waited for).
                let access = glow::MAP_WRITE_BIT | glow::MAP_INVALIDATE_RANGE_BIT;
                let mapped = gl.map_buffer_range(glow::COPY_READ_BUFFER, 0, n, access);
                if mapped.is_null() {
                    return Err(anyhow!(
                        "glMapBufferRange returned no memory for a {n}-byte chunk of binding {index}"
                    ));
                }
                // The map is at least GL_MIN_MAP_BUFFER_ALIGNMENT (64) bytes
                // aligned, enough for every GPU struct `write` fills in place.
                write(c.start, std::slice::from_raw_parts_mut(mapped, c.len()));
                gl.unmap_buffer(glow::COPY_READ_BUFFER);
                gl.copy_buffer_sub_data(
                    glow::COPY_READ_BUFFER,
                    glow::COPY_WRITE_BUFFER,
                    0,
                    start,
                    n,
                );
                wait_for_gpu(gl).with_context(|| format!("uploading binding {index}"))?;
            }
            // A shader that reads the buffer later sees what the copies wrote:
            // GL orders its own commands' writes, so unlike Vulkan no barrier.
            gl.bind_buffer_base(target, index, Some(buffer));
        }
        explain::numbered(
            5,
            &format!("glCreateBuffer + glBufferStorage + glCopyBufferSubData + glBindBufferBase (binding {index})"),
            || {
                let (kind, flags) = if target == glow::UNIFORM_BUFFER {
                    ("UNIFORM_BUFFER", "DYNAMIC_STORAGE_BIT")
                } else {
                    ("SHADER_STORAGE_BUFFER", "no flags: never mapped or rewritten by the CPU")
                };
                format!(
                    "{len} bytes, {kind}, immutable storage, {flags}\nfilled through a {}-byte staging buffer: {} glMapBufferRange + glUnmapBuffer + glCopyBufferSubData, each waited for with glFenceSync + glClientWaitSync",
                    self.len,
                    chunks.len()
                )
            },
        );
        Ok(())
    }

    /// The buffers in the order they were added. Every copy into them has
    /// been waited for, so the staging buffer can go.
    fn finish(mut self) -> Vec<glow::Buffer> {
        std::mem::take(&mut self.filled)
    }
}

impl Drop for Uploads<'_> {
    fn drop(&mut self) {
        // SAFETY: the staging buffer was created on this context, which
        // outlives it; GL keeps it alive for any copy still reading it.
        unsafe { self.gl.delete_buffer(self.staging) }
        delete_buffers(self.gl, &self.filled);
    }
}

/// Waits until the GPU has run every command issued so far: here, the copy
/// that read the staging buffer, before the CPU writes the next chunk into it.
fn wait_for_gpu(gl: &glow::Context) -> anyhow::Result<()> {
    /// glow takes the timeout in nanoseconds as an i32: wait a second at a time.
    const SECOND_NS: i32 = 1_000_000_000;
    // SAFETY: a fence on the current context, deleted before returning.
    unsafe {
        let fence = gl
            .fence_sync(glow::SYNC_GPU_COMMANDS_COMPLETE, 0)
            .map_err(|e| anyhow!(e))
            .context("glFenceSync")?;
        let result = loop {
            // SYNC_FLUSH_COMMANDS_BIT: the fence must reach the GPU, or the
            // wait would never end.
            match gl.client_wait_sync(fence, glow::SYNC_FLUSH_COMMANDS_BIT, SECOND_NS) {
                glow::TIMEOUT_EXPIRED => continue,
                glow::ALREADY_SIGNALED | glow::CONDITION_SATISFIED => break Ok(()),
                status => break Err(anyhow!("glClientWaitSync returned {status:#x}")),
            }
        };
        gl.delete_sync(fence);
        result
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
