//! The scene on the GPU: the `Frame` uniform buffer, the four storage buffers,
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
use twinray_common::gpu::upload::{storage_name, GpuScene};
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
/// Device-local memory, filled once through a staging buffer, is the careful
/// choice. `--vk-memory host` keeps the scene in host-visible memory instead,
/// so the comparison can show what a naive placement costs.
pub fn scene_buffers(device: &Device, scene: &GpuScene) -> Result<(Buffer, Vec<(u32, Buffer)>)> {
    // The run plan checked every buffer against `Device::storage_limit`.
    let host = device.scene_memory == SceneMemory::Host;
    // The uniform block first, then the storage buffers in binding order.
    let frame = (
        scene.frame_bytes(),
        vk::BufferUsageFlags::UNIFORM_BUFFER,
        "frame uniform buffer".to_string(),
    );
    let storage = binding::STORAGE.iter().map(|&b| {
        (
            scene.storage_bytes(b),
            vk::BufferUsageFlags::STORAGE_BUFFER,
            format!("{} storage buffer", storage_name(b)),
        )
    });
    let contents: Vec<_> = std::iter::once(frame).chain(storage).collect();
    let buffers = if host {
        contents
            .iter()
            .map(|(bytes, usage, what)| Buffer::host_visible_with(device, bytes, *usage, what))
            .collect::<Result<Vec<_>>>()?
    } else {
        let mut uploads = Uploads::new(device);
        for (bytes, usage, what) in &contents {
            uploads.add(bytes, *usage, what)?;
        }
        uploads.submit()?
    };
    let mut buffers = buffers.into_iter();
    let frame = buffers.next().expect("the uniform buffer comes first");
    let storage = binding::STORAGE.iter().copied().zip(buffers).collect();
    Ok((frame, storage))
}
