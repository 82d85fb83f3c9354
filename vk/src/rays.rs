//! The ray-counting frame (`--count-rays`): the run's own shader variant with
//! COUNT_RAYS, drawn or dispatched once on the run's path, untimed and after
//! the timed frames, on scene buffers of its own. Each pixel writes its rays
//! by kind into its slot of a host-visible storage buffer (binding 10), which
//! is read back and added up. The timed pipeline never sees that buffer.

use crate::barrier;
use crate::commands::Commands;
use crate::compute::Compute;
use crate::descriptors::Descriptors;
use crate::device::Device;
use crate::memory::Buffer;
use crate::pipeline::{Pipeline, RenderPass};
use crate::pipeline_barrier::{self, On};
use crate::scene::scene_buffers;
use crate::target::Target;
use crate::timestamps::Span;
use anyhow::Result;
use ash::vk;
use twinray_common::error::no_device;
use twinray_common::explain;
use twinray_common::gpu::layout::{binding, GpuRayCount};
use twinray_common::limits::pixel_count;
use twinray_common::plan::CountingRun;
use twinray_common::rays::RayKinds;
use twinray_common::shader::build::PathShaders;

/// Renders the counting frame of `run` and returns its rays by kind.
pub fn count_rays(device: &Device, run: &CountingRun) -> Result<RayKinds> {
    let (width, height) = (run.width, run.height);
    // Declared first, so dropped last: after the pipelines that use them.
    let (frame, mut storage) = scene_buffers(device, run.gpu)?;
    let bytes = pixel_count(width, height) * size_of::<GpuRayCount>();
    let counts = Buffer::host_visible_with(
        device,
        &vec![0u8; bytes],
        vk::BufferUsageFlags::STORAGE_BUFFER,
        "ray count buffer",
    )?;
    let counts_handle = counts.buffer;
    storage.push((binding::RAY_COUNTS, counts));
    match PathShaders::build(&run.variant)? {
        PathShaders::Fragment(shaders) => {
            if !device.fragment_stores {
                return Err(no_device(format!(
                        "--count-rays on the fragment path needs fragmentStoresAndAtomics, which '{}' does not offer; count with --path compute",
                        device.name
                    )));
            }
            let render_pass = RenderPass::offscreen(device)?;
            let rp = render_pass.render_pass;
            let descriptors = Descriptors::new(device, &frame, &storage)?;
            let size = Some((width, height));
            let pipeline = Pipeline::new(device, descriptors.set_layout, &shaders, rp, size)?;
            let target = Target::new(device, rp, width, height)?;
            let commands = Commands::record(device, rp, &pipeline, &descriptors, &target, None)?;
            commands.submit()?;
            commands.wait(false)?;
        }
        PathShaders::Compute(shader) => {
            let compute = Compute::new(
                device,
                &frame,
                &storage,
                &shader,
                width,
                height,
                (None, Span::DISPATCH),
            )?;
            compute.commands.submit()?;
            compute.commands.wait(false)?;
        }
    }
    // Read after write: the CPU maps what the shader wrote. A barrier in a
    // later submission still orders the frame's writes, submitted before it.
    device.run_once("making the ray counts visible to the CPU", |cmd| {
        let counts = [counts_handle];
        // SAFETY: `cmd` is recording (inside run_once); the buffer is
        // alive in `storage` until the end of this function.
        unsafe {
            pipeline_barrier::record(device, cmd, &[(barrier::RAY_COUNTS, On::Buffers(&counts))])
        };
    })?;
    let (_, counts) = storage
        .last()
        .expect("the ray count buffer was pushed last");
    let kinds = RayKinds::from_pixels(&counts.read::<GpuRayCount>()?);
    explain::numbered(
        11,
        "Ray count: one untimed frame of the COUNT_RAYS variant",
        || kinds.to_string(),
    );
    Ok(kinds)
}
