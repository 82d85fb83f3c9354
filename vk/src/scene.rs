//! The scene on the GPU: the `Frame` uniform buffer, the seven storage buffers,
//! the descriptor set pointing at them and the pipeline compiled for the
//! scene's shader variant. Everything here depends on the scene (and nothing
//! else does), so a scene switch or a new variant in the window rebuilds
//! exactly this bundle and keeps the device, swapchain and render pass.

use crate::descriptors::Descriptors;
use crate::device::Device;
use crate::memory::{Buffer, Uploads};
use crate::pipeline::Pipeline;
use anyhow::Result;
use ash::vk;
use twinray_common::cli::SceneMemory;
use twinray_common::gpu::layout::binding;
use twinray_common::gpu::upload::{storage_name, GpuScene, UPLOAD_CHUNK_BYTES};
use twinray_common::shader::build::Shaders;

/// Fields in reverse creation order, so that they drop in the order Vulkan needs:
/// the pipeline and the set before the buffers they use.
pub struct SceneResources {
    pub pipeline: Pipeline,
    pub descriptors: Descriptors,
    pub storage: Vec<(u32, Buffer)>,
    /// Binding 0. Headless it never changes; windowed, each frame's command
    /// buffer rewrites it (camera, size, depth) with vkCmdUpdateBuffer.
    pub frame: Buffer,
}

impl SceneResources {
    /// `fixed_size` is the headless image size (None: dynamic viewport, windowed).
    pub fn new(
        device: &Device,
        scene: &GpuScene,
        shaders: &Shaders,
        render_pass: vk::RenderPass,
        fixed_size: Option<(u32, u32)>,
    ) -> Result<SceneResources> {
        let (frame, storage) = scene_buffers(device, scene)?;
        let descriptors = Descriptors::new(device, &frame, &storage)?;
        let pipeline = Pipeline::new(
            device,
            descriptors.set_layout,
            shaders,
            render_pass,
            fixed_size,
        )?;
        Ok(SceneResources {
            pipeline,
            descriptors,
            storage,
            frame,
        })
    }
}

/// The `Frame` uniform buffer and the storage buffers, filled with the scene's
/// bytes: what both the graphics and the compute pipeline read.
///
/// Device-local memory, filled through a staging buffer, is the careful
/// choice. `--vk-memory host` keeps the scene in host-visible memory instead,
/// so the comparison can show what a naive placement costs. Either way the
/// bytes are written where the copy or the GPU reads them (`write_storage`
/// converts the scene a chunk at a time), so the host never holds a second
/// full copy of a large scene.
pub fn scene_buffers(device: &Device, scene: &GpuScene) -> Result<(Buffer, Vec<(u32, Buffer)>)> {
    // The run plan checked every buffer against `Device::storage_limit`.
    let host = device.scene_memory == SceneMemory::Host;
    let frame_bytes = scene.frame_bytes();
    let (uniform, storage) = (
        vk::BufferUsageFlags::UNIFORM_BUFFER,
        vk::BufferUsageFlags::STORAGE_BUFFER,
    );
    let frame_what = "frame uniform buffer";
    let what = |b: u32| format!("{} storage buffer", storage_name(b));
    if host {
        let frame = Buffer::host_visible_with(device, frame_bytes, uniform, frame_what)?;
        let mut buffers = Vec::new();
        for b in binding::STORAGE {
            let len = scene.storage_len(b);
            let buffer = Buffer::host_visible(device, len, storage, &what(b))?;
            buffer.fill(len, |bytes| scene.write_storage(b, 0, bytes))?;
            buffers.push((b, buffer));
        }
        return Ok((frame, buffers));
    }
    // One staging buffer, as large as the largest chunk any buffer needs.
    let chunk = UPLOAD_CHUNK_BYTES.min(scene.largest_storage().1.max(frame_bytes.len()));
    let mut uploads = Uploads::new(device, chunk as u64)?;
    // The uniform block first, then the storage buffers in binding order.
    let len = frame_bytes.len();
    uploads.add(
        len,
        (uniform, frame_what),
        std::slice::from_ref(&(0..len)),
        |_, bytes| bytes.copy_from_slice(frame_bytes),
    )?;
    for b in binding::STORAGE {
        let chunks = scene.chunks(b, chunk);
        uploads.add(
            scene.storage_len(b),
            (storage, &what(b)),
            &chunks,
            |offset, bytes| scene.write_storage(b, offset, bytes),
        )?;
    }
    let mut buffers = uploads.finish()?.into_iter();
    let frame = buffers.next().expect("the uniform buffer comes first");
    let storage = binding::STORAGE.iter().copied().zip(buffers).collect();
    Ok((frame, storage))
}
