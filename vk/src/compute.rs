//! The compute path: the same tracer as a compute shader (`shaders/trace.comp`),
//! the counterpart of the render pass and graphics pipeline in pipeline.rs and
//! the colour target in target.rs.
//!
//! A compute pipeline needs far less than a graphics one: one shader stage and a
//! pipeline layout. No render pass, framebuffer, viewport, rasteriser or blend
//! state: nothing is rasterised, each invocation computes one pixel and writes
//! it into a *storage image* with `imageStore`. What the render pass did for us
//! must now be said explicitly:
//! - the image's *layout*: shaders may write an image only in GENERAL layout, so
//!   it is moved there once at setup and stays until the readback (in the
//!   window, until each frame's blit, and back);
//! - the *barriers*: without a render pass's subpass dependencies, one frame's
//!   writes are ordered against the next frame's writes, and the last frame's
//!   against the readback copy, by pipeline barriers;
//! - the *grid*: the dispatch covers the image in ceil(w / WG_X) x ceil(h / WG_Y)
//!   workgroups; the shader skips invocations past the edges.
//!
//! The descriptor set is descriptors.rs's with the compute stage and binding 5.
//!
//! In the window ([`WindowCompute`]) the same pipeline and storage image serve
//! the swapchain: the image is sized to the swapchain and made anew when it
//! changes size, and each frame *blits* it into the acquired swapchain image
//! (a copy cannot: RGBA32F and the 8-bit swapchain formats differ in size per
//! texel, and a blit converts, as the render pass's colour write does). The
//! shader cannot write the swapchain image itself: its `rgba32f` image format
//! is not the swapchain's, and few surfaces offer STORAGE usage anyway.

use crate::barrier::{self, Access};
use crate::commands::Commands;
use crate::descriptors::Descriptors;
use crate::device::Device;
use crate::memory::Buffer;
use crate::pipeline_barrier::{self, On};
use crate::scene::scene_buffers;
use crate::target::{create_image_with_view, read_image, readback_buffer, record_copy_to_host};
use crate::timestamps::{Span, Timestamps};
use anyhow::{Context, Result};
use ash::vk;
use twinray_common::explain;
use twinray_common::gpu::upload::GpuScene;
use twinray_common::reference::image_io::FloatImage;
use twinray_common::shader::build::ComputeShader;

/// The same float format as the fragment path's colour image (pipeline.rs), and
/// the `rgba32f` of the shader's image declaration. Storage-image support for it
/// is mandatory in Vulkan, so no format query is needed.
pub const IMAGE_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;

/// Everything the compute path owns. Fields drop in declaration order: the
/// commands first (their Drop waits for the GPU), then what they use.
pub struct Compute {
    pub commands: Commands,
    // Only kept alive for the recorded commands, which use them.
    _pipeline: ComputePipeline,
    _descriptors: Descriptors,
    image: StorageImage,
    readback: Buffer,
    width: u32,
    height: u32,
}

impl Compute {
    /// `frame` and `storage` are the scene's buffers, as for the fragment path.
    pub fn new(
        device: &Device,
        frame: &Buffer,
        storage: &[(u32, Buffer)],
        shader: &ComputeShader,
        width: u32,
        height: u32,
        (timestamps, span): (Option<&Timestamps>, Span),
    ) -> Result<Compute> {
        let groups = device
            .compute_limits()
            .dispatch(shader.workgroup, width, height)?;
        let readback = readback_buffer(device, width, height)?;
        let image = StorageImage::new(device, width, height)?;
        let descriptors = Descriptors::for_stage(
            device,
            frame,
            storage,
            vk::ShaderStageFlags::COMPUTE,
            Some(image.view),
        )?;
        let pipeline = ComputePipeline::new(device, descriptors.set_layout, &shader.stage.spirv)?;
        explain::numbered(
            21,
            "Storage VkImage (GENERAL) + VkPipelineLayout + VkShaderModule + VkPipeline (vkCreateComputePipelines)",
            || {
                format!(
                    "{width}x{height} {IMAGE_FORMAT:?} at binding 5; workgroup {}, {}x{} workgroups",
                    shader.workgroup, groups.0, groups.1
                )
            },
        );
        let commands = Commands::record_with(device, |_, cmd| {
            if let Some(t) = timestamps {
                t.record_reset(cmd);
            }
            // Write-after-write: this frame's imageStores must come after the
            // previous frame's (same image). A render pass's external subpass
            // dependency says this for the fragment path; here it is a barrier.
            // The first timestamp goes after it, so that the span is the
            // dispatch alone, as OpenGL's timer is (`Span`).
            let after_last_frame = (barrier::FRAME_AFTER_FRAME, On::Image(image.image));
            let first = |on: bool| {
                if let (Some(t), true) = (timestamps, on) {
                    t.record(cmd, 0);
                }
            };
            first(span.barrier);
            // SAFETY: `cmd` is recording (inside record_with); the storage image
            // is owned by the `Compute` that will own these commands too.
            unsafe { pipeline_barrier::record(device, cmd, &[after_last_frame]) };
            first(!span.barrier);
            // A second dispatch (`Span::dispatches`) needs no barrier after the
            // first: both store the same value in each texel, so their order
            // cannot change the image, and without one the second's workgroups
            // start as the first's finish.
            for _ in 0..span.dispatches {
                // SAFETY: as above; the set matches the pipeline's layout.
                unsafe { pipeline.dispatch(cmd, descriptors.set, groups) };
            }
            if let Some(t) = timestamps {
                t.record(cmd, 1);
            }
        })?;
        Ok(Compute {
            commands,
            _pipeline: pipeline,
            _descriptors: descriptors,
            image,
            readback,
            width,
            height,
        })
    }

    /// Copies the last frame to the CPU: a barrier orders the copy after the
    /// last dispatch's writes (nothing else would), then the same copy and host
    /// barrier as target.rs. Rows come out top first, as the shader wrote them.
    /// Leaves the image in TRANSFER_SRC_OPTIMAL: call it once, after the frames.
    pub fn read_back(&self, device: &Device) -> Result<FloatImage> {
        device.run_once("reading the image back", |cmd| {
            // GENERAL works for copies too, but the layer (rightly) says the
            // copy may be faster from TRANSFER_SRC_OPTIMAL; this runs once, after
            // the last frame, so the move costs the timed frames nothing.
            let after_dispatch = (barrier::STORAGE_IMAGE_TO_COPY, On::Image(self.image.image));
            // SAFETY: `cmd` is run_once's, recording; `self` owns the image.
            unsafe { pipeline_barrier::record(device, cmd, &[after_dispatch]) };
            record_copy_to_host(
                device,
                cmd,
                self.image.image,
                &self.readback,
                self.width,
                self.height,
            );
        })?;
        read_image(&self.readback, self.width, self.height)
    }
}

/// The compute path in the window: its scene buffers, descriptor set and
/// pipeline (all per scene and variant, like `SceneResources` for the fragment
/// path), and a storage image the size of the swapchain. frames.rs records
/// [`WindowCompute::record`] into each frame. Fields drop in declaration order:
/// the pipeline and the set before the image and the buffers they use.
pub struct WindowCompute {
    pipeline: ComputePipeline,
    descriptors: Descriptors,
    image: StorageImage,
    pub storage: Vec<(u32, Buffer)>,
    /// Binding 0, rewritten by each frame's command buffer, as for the fragment path.
    pub frame: Buffer,
    pub shader: ComputeShader,
    groups: (u32, u32),
    /// The storage image's size, which must be the swapchain's.
    pub extent: vk::Extent2D,
}

impl WindowCompute {
    /// `swapchain_format` is the surface format the blit writes; `extent` the
    /// swapchain's (or the window's while minimized).
    pub fn new(
        device: &Device,
        scene: &GpuScene,
        shader: &ComputeShader,
        swapchain_format: vk::Format,
        extent: vk::Extent2D,
    ) -> Result<WindowCompute> {
        let groups =
            device
                .compute_limits()
                .dispatch(shader.workgroup, extent.width, extent.height)?;
        let (frame, storage) = scene_buffers(device, scene)?;
        let image = StorageImage::new(device, extent.width, extent.height)?;
        let descriptors = Descriptors::for_stage(
            device,
            &frame,
            &storage,
            vk::ShaderStageFlags::COMPUTE,
            Some(image.view),
        )?;
        let pipeline = ComputePipeline::new(device, descriptors.set_layout, &shader.stage.spirv)?;
        explain::numbered(22,
            "Compute path in the window: VkPipeline (compute) + storage VkImage sized to the swapchain",
            || {
                format!(
                    "{}x{} {IMAGE_FORMAT:?}, usage STORAGE|TRANSFER_SRC, binding 5 of the set; workgroup {}, {}x{} groups
                     per frame: storage image UNDEFINED->GENERAL, vkCmdDispatch, GENERAL->TRANSFER_SRC_OPTIMAL and the
                     acquired swapchain image UNDEFINED->TRANSFER_DST_OPTIMAL, vkCmdBlitImage (NEAREST, {IMAGE_FORMAT:?} -> {swapchain_format:?}),
                     swapchain image TRANSFER_DST_OPTIMAL->PRESENT_SRC_KHR; the submit waits for the image at {:?}",
                    extent.width, extent.height, shader.workgroup, groups.0, groups.1,
                    barrier::acquire_wait_stage(Access::BlitWrite, device.recording)
                )
            },
        );
        Ok(WindowCompute {
            pipeline,
            descriptors,
            image,
            storage,
            frame,
            shader: shader.clone(),
            groups,
            extent,
        })
    }

    /// A new storage image for a new swapchain size, and the set pointed at it.
    /// The caller waits for the GPU first: the old image may still be in use.
    pub fn resize(&mut self, device: &Device, extent: vk::Extent2D) -> Result<()> {
        self.groups =
            device
                .compute_limits()
                .dispatch(self.shader.workgroup, extent.width, extent.height)?;
        let image = StorageImage::new(device, extent.width, extent.height)?;
        self.descriptors.write_image(image.view);
        self.image = image; // the old one is destroyed here, no longer referenced
        self.extent = extent;
        Ok(())
    }

    /// The frame's GPU work after the uniform write: trace into the storage
    /// image, then blit it into the acquired swapchain image `target` and hand
    /// that to presentation. The submit must wait for `target` to be acquired
    /// at the TRANSFER stage, where the first barrier on it starts.
    pub fn record(&self, device: &Device, cmd: vk::CommandBuffer, target: vk::Image) {
        let d = &device.device;
        // Every pixel is written again, so the old contents may go (UNDEFINED).
        // The barrier waits for the previous frame's blit to have read the
        // image (write after read: no access to flush).
        let to_general = (
            barrier::STORAGE_IMAGE_AFTER_BLIT,
            On::Image(self.image.image),
        );
        // The blit reads what the dispatch wrote; the swapchain image's old
        // contents go, and its transition starts at the stage where the submit
        // waits for the acquire (Access::Acquire), so it follows the acquire.
        let to_blit = [
            (barrier::STORAGE_IMAGE_TO_BLIT, On::Image(self.image.image)),
            (barrier::SWAPCHAIN_TO_BLIT, On::Image(target)),
        ];
        // Presentation needs PRESENT_SRC_KHR; the render-finished semaphore,
        // signalled after every command, makes the blit's writes visible to it.
        let to_present = (barrier::SWAPCHAIN_TO_PRESENT, On::Image(target));
        let layers = vk::ImageSubresourceLayers {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            mip_level: 0,
            base_array_layer: 0,
            layer_count: 1,
        };
        let corner = vk::Offset3D {
            x: self.extent.width as i32,
            y: self.extent.height as i32,
            z: 1,
        };
        // Same size both sides: texel for texel, converted to the swapchain's format.
        let region = vk::ImageBlit {
            src_subresource: layers,
            src_offsets: [vk::Offset3D::default(), corner],
            dst_subresource: layers,
            dst_offsets: [vk::Offset3D::default(), corner],
        };
        // SAFETY: frames.rs records into its slot's command buffer, which is
        // recording; `self` owns the pipeline, set and storage image and lives
        // until the GPU is idle (a path switch or resize waits first); `target`
        // is the swapchain image acquired for this frame, alive with the swapchain.
        unsafe {
            pipeline_barrier::record(device, cmd, &[to_general]);
            self.pipeline
                .dispatch(cmd, self.descriptors.set, self.groups);
            pipeline_barrier::record(device, cmd, &to_blit);
            d.cmd_blit_image(
                cmd,
                self.image.image,
                barrier::layout_for(Access::BlitRead),
                target,
                barrier::layout_for(Access::BlitWrite),
                &[region],
                vk::Filter::NEAREST,
            );
            pipeline_barrier::record(device, cmd, &[to_present]);
        }
    }
}

/// Why the compute path cannot show its image in this window, if it cannot:
/// the blit needs TRANSFER_DST on the swapchain images (`transfer_dst`, from
/// the surface), BLIT_SRC on the storage format and BLIT_DST on the
/// swapchain's (mandatory for these formats, but a missing one would otherwise
/// be undefined behaviour rather than a message).
pub fn window_blocker(
    instance: &ash::Instance,
    device: &Device,
    transfer_dst: bool,
    swapchain_format: vk::Format,
) -> Option<String> {
    let features = |format| {
        // SAFETY: a plain query on a live physical device.
        unsafe { instance.get_physical_device_format_properties(device.physical, format) }
            .optimal_tiling_features
    };
    let why = if !transfer_dst {
        "this surface does not let its images be transfer destinations".to_string()
    } else if !features(IMAGE_FORMAT).contains(vk::FormatFeatureFlags::BLIT_SRC)
        || !features(swapchain_format).contains(vk::FormatFeatureFlags::BLIT_DST)
    {
        format!("this driver cannot blit {IMAGE_FORMAT:?} into {swapchain_format:?}")
    } else {
        return None;
    };
    Some(format!(
        "{why}, which the compute path needs to show its image in a window; use --path fragment, or --headless"
    ))
}

/// The compute pipeline: one stage and the layout it reads its descriptors through.
struct ComputePipeline {
    device: ash::Device,
    layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
}

impl ComputePipeline {
    fn new(
        device: &Device,
        set_layout: vk::DescriptorSetLayout,
        spirv: &[u32],
    ) -> Result<ComputePipeline> {
        let d = &device.device;
        // Owned from here on, so that an error below frees the layout (dropping
        // a null pipeline does nothing).
        let mut this = ComputePipeline {
            device: d.clone(),
            layout: crate::pipeline::layout(d, set_layout, "compute")?,
            pipeline: vk::Pipeline::null(),
        };
        // Dropped after the pipeline is made: it keeps its own copy of the code.
        let module = crate::pipeline::module(d, spirv, "compute")?;
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module.1)
            .name(c"main");
        let info = vk::ComputePipelineCreateInfo::default()
            .flags(crate::statistics::pipeline_flags(device))
            .stage(stage)
            .layout(this.layout);
        // SAFETY: the module and layout are alive until after the call (the module drops at the end
        // of this function); the SPIR-V was validated by naga and declares the `main` entry point
        // the stage names; the layout's set layout is the one the shader's bindings were written
        // for.
        let made = unsafe { d.create_compute_pipelines(vk::PipelineCache::null(), &[info], None) };
        this.pipeline = made
            .map_err(|(_, e)| e)
            .context("creating the compute pipeline")?[0];
        crate::statistics::capture(device, this.pipeline, "compute");
        Ok(this)
    }

    /// Binds the pipeline and `set`, then dispatches `groups` workgroups.
    ///
    /// # Safety
    /// `cmd` is recording; `set` matches the pipeline's layout, and both
    /// outlive the commands' execution.
    unsafe fn dispatch(&self, cmd: vk::CommandBuffer, set: vk::DescriptorSet, groups: (u32, u32)) {
        let d = &self.device;
        // SAFETY: forwarded from the caller.
        unsafe {
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline);
            d.cmd_bind_descriptor_sets(
                cmd,
                vk::PipelineBindPoint::COMPUTE,
                self.layout,
                0,
                &[set],
                &[],
            );
            d.cmd_dispatch(cmd, groups.0, groups.1, 1);
        }
    }
}

impl Drop for ComputePipeline {
    fn drop(&mut self) {
        // SAFETY: no command buffer using them is pending (Commands drops first).
        unsafe {
            self.device.destroy_pipeline(self.pipeline, None);
            self.device.destroy_pipeline_layout(self.layout, None);
        }
    }
}

/// The RGBA32F storage image the shader writes, its memory and view. It is
/// moved to GENERAL once, here, for the shader's writes, and leaves it only to
/// be copied or blitted from (TRANSFER_SRC_OPTIMAL): headless once, after the
/// last frame; in the window every frame, and back to GENERAL after the blit.
struct StorageImage {
    device: ash::Device,
    image: vk::Image,
    memory: vk::DeviceMemory,
    view: vk::ImageView,
}

impl StorageImage {
    fn new(device: &Device, width: u32, height: u32) -> Result<StorageImage> {
        let d = &device.device;
        let mut this = StorageImage {
            device: d.clone(),
            image: vk::Image::null(),
            memory: vk::DeviceMemory::null(),
            view: vk::ImageView::null(),
        };
        create_image_with_view(
            device,
            IMAGE_FORMAT,
            (width, height),
            vk::ImageUsageFlags::STORAGE | vk::ImageUsageFlags::TRANSFER_SRC,
            "storage image",
            (&mut this.image, &mut this.memory, &mut this.view),
        )?;

        // UNDEFINED → GENERAL once: the old contents (none) may be discarded.
        let to_general = (barrier::STORAGE_IMAGE_SETUP, On::Image(this.image));
        device.run_once("moving the storage image to GENERAL layout", |cmd| {
            // SAFETY: `cmd` is run_once's, recording; `this` owns the image.
            unsafe { pipeline_barrier::record(device, cmd, &[to_general]) }
        })?;
        Ok(this)
    }
}

impl Drop for StorageImage {
    fn drop(&mut self) {
        // SAFETY: no command buffer using them is pending (Commands drops first).
        unsafe {
            self.device.destroy_image_view(self.view, None);
            self.device.destroy_image(self.image, None);
            self.device.free_memory(self.memory, None);
        }
    }
}
