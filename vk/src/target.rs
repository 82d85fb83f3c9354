//! The offscreen render target and its readback.
//!
//! Without a window there is no swapchain to draw into, so the app makes its own
//! *image*: memory laid out in the GPU's private (OPTIMAL) tiling. Pipelines do
//! not see images directly but through an *image view* (which format, which mip
//! levels and layers), and a render pass sees views through a *framebuffer*,
//! which fills its attachment slots for one size.
//!
//! An OPTIMAL-tiled image cannot be mapped, so after the last frame the GPU
//! copies it into a host-visible *readback* buffer as plain rows, top row first.

use crate::barrier;
use crate::device::Device;
use crate::memory::{self, Buffer};
use crate::pipeline::COLOR_FORMAT;
use crate::pipeline_barrier::{self, On};
use anyhow::{Context, Result};
use ash::vk;
use ash::vk::MemoryPropertyFlags as Flags;
use twinray_common::explain;
use twinray_common::reference::image_io::FloatImage;

pub struct Target {
    device: ash::Device,
    pub image: vk::Image,
    memory: vk::DeviceMemory,
    view: vk::ImageView,
    pub framebuffer: vk::Framebuffer,
    pub width: u32,
    pub height: u32,
    readback: Buffer,
}

impl Target {
    pub fn new(
        device: &Device,
        render_pass: vk::RenderPass,
        width: u32,
        height: u32,
    ) -> Result<Target> {
        let d = &device.device;
        // One RGBA32F texel, 16 bytes, per pixel.
        let readback = sized_readback(device, width as u64 * height as u64 * 16)?;
        let bytes = readback.size;
        explain::numbered(9, "VkBuffer + VkDeviceMemory: readback buffer", || {
            format!(
                "{bytes} bytes, TRANSFER_DST, memory {:?} (the CPU reads it)",
                readback.memory_flags
            )
        });
        let mut this = Target {
            device: d.clone(),
            image: vk::Image::null(),
            memory: vk::DeviceMemory::null(),
            view: vk::ImageView::null(),
            framebuffer: vk::Framebuffer::null(),
            width,
            height,
            readback,
        };
        let format = COLOR_FORMAT;
        let image_bytes = create_image_with_view(
            device,
            format,
            (width, height),
            vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
            "colour image",
            (&mut this.image, &mut this.memory, &mut this.view),
        )?;
        explain::numbered(9, "VkImage + VkDeviceMemory: colour target", || {
            format!("{width}x{height} {format:?}, OPTIMAL tiling, usage COLOR_ATTACHMENT|TRANSFER_SRC, {image_bytes} bytes DEVICE_LOCAL")
        });
        explain::numbered(9, "VkImageView", || {
            "2D, COLOR aspect, 1 mip level, 1 layer".into()
        });

        let views = [this.view];
        let info = vk::FramebufferCreateInfo::default()
            .render_pass(render_pass)
            .attachments(&views)
            .width(width)
            .height(height)
            .layers(1);
        // SAFETY: the view was just made (owned by `this`) at this size, in the format the render
        // pass (alive, the caller's) was made for; `this` destroys the framebuffer first.
        this.framebuffer =
            unsafe { d.create_framebuffer(&info, None) }.context("creating the framebuffer")?;
        explain::numbered(9, "VkFramebuffer", || {
            format!("{width}x{height}, 1 layer, attachment 0 = the view")
        });
        Ok(this)
    }

    /// Copies the last frame to the CPU. The render pass left the image in
    /// TRANSFER_SRC_OPTIMAL and its outgoing dependency orders the copy after the draw.
    pub fn read_back(&self, device: &Device) -> Result<FloatImage> {
        device.run_once("reading the image back", |cmd| {
            record_copy_to_host(
                device,
                cmd,
                self.image,
                &self.readback,
                self.width,
                self.height,
            );
        })?;
        read_image(&self.readback, self.width, self.height)
    }
}

/// Records the copy of a `TRANSFER_SRC_OPTIMAL` RGBA32F image into `readback`,
/// then the barrier that makes it visible to the CPU: a queue or fence wait
/// covers only the GPU's side, the copy's writes reach the CPU's reads only
/// through a barrier to HOST (and, in memory that is not host-coherent, an
/// invalidate before the read: `Buffer::read`). Shared by the fragment and
/// compute paths.
pub fn record_copy_to_host(
    device: &Device,
    cmd: vk::CommandBuffer,
    image: vk::Image,
    readback: &Buffer,
    width: u32,
    height: u32,
) {
    let region = vk::BufferImageCopy::default()
        .image_subresource(vk::ImageSubresourceLayers {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            mip_level: 0,
            base_array_layer: 0,
            layer_count: 1,
        })
        .image_extent(vk::Extent3D {
            width,
            height,
            depth: 1,
        });
    let d = &device.device;
    // SAFETY: `cmd` is run_once's, recording; the caller owns `image` (in
    // TRANSFER_SRC_OPTIMAL, as the region's layout says) and `readback`, which
    // holds width x height texels of the image's format (its maker sized it so).
    unsafe {
        d.cmd_copy_image_to_buffer(
            cmd,
            image,
            barrier::layout_for(barrier::Access::CopyRead),
            readback.buffer,
            &[region],
        );
        // Read after write: the CPU maps what the copy wrote.
        let to_host = [readback.buffer];
        pipeline_barrier::record(device, cmd, &[(barrier::READBACK, On::Buffers(&to_host))]);
    }
}

/// The readback buffer's RGBA32F rows as an image, top row first.
pub fn read_image(readback: &Buffer, width: u32, height: u32) -> Result<FloatImage> {
    let rgba: Vec<f32> = readback.read().context("reading the readback buffer")?;
    Ok(FloatImage::from_rgba(width, height, &rgba))
}

/// A buffer the CPU reads an RGBA32F image back from: 16 bytes a pixel, rows
/// packed tightly. Cached memory where there is some: uncached reads of mapped
/// memory are very slow.
pub fn readback_buffer(device: &Device, width: u32, height: u32) -> Result<Buffer> {
    sized_readback(device, width as u64 * height as u64 * 16)
}

fn sized_readback(device: &Device, bytes: u64) -> Result<Buffer> {
    let wishes = [
        Flags::HOST_VISIBLE | Flags::HOST_CACHED,
        Flags::HOST_VISIBLE,
    ];
    Buffer::new(
        device,
        bytes,
        vk::BufferUsageFlags::TRANSFER_DST,
        &wishes,
        "readback buffer",
    )
}

/// A device-local 2D image with one mip level and its colour view. Each handle
/// goes into the owner's field as soon as it exists, so the owner's Drop frees
/// a half-built one. Returns the image's size in bytes.
pub fn create_image_with_view(
    device: &Device,
    format: vk::Format,
    (width, height): (u32, u32),
    usage: vk::ImageUsageFlags,
    what: &str,
    (image, memory, view): (&mut vk::Image, &mut vk::DeviceMemory, &mut vk::ImageView),
) -> Result<u64> {
    let d = &device.device;
    let info = vk::ImageCreateInfo::default()
        .image_type(vk::ImageType::TYPE_2D)
        .format(format)
        .extent(vk::Extent3D {
            width,
            height,
            depth: 1,
        })
        .mip_levels(1)
        .array_layers(1)
        .samples(vk::SampleCountFlags::TYPE_1)
        .tiling(vk::ImageTiling::OPTIMAL)
        .usage(usage)
        .initial_layout(barrier::layout_for(barrier::Access::Nothing));
    // SAFETY: a create on the live device from a local info; the size is within the device's
    // limits (check_size for --size and captures; in the window the swapchain's extent, which the
    // surface bounds); RGBA32F supports these usages on every device (the spec makes them
    // mandatory); the owner whose fields the handles go into destroys the image.
    *image = unsafe { d.create_image(&info, None) }
        .map_err(|e| memory::too_large(e, width as u64 * height as u64 * 16, what))?;
    // SAFETY: a query on the image just made.
    let needs = unsafe { d.get_image_memory_requirements(*image) };
    *memory = memory::allocate(device, needs, &[Flags::DEVICE_LOCAL, Flags::empty()], what)?.0;
    // SAFETY: the image has no memory yet; the allocation was sized from its requirements and of a
    // type they allow; offset 0 meets any alignment.
    unsafe { d.bind_image_memory(*image, *memory, 0) }
        .with_context(|| format!("binding the {what}'s memory"))?;
    let info = vk::ImageViewCreateInfo::default()
        .image(*image)
        .view_type(vk::ImageViewType::TYPE_2D)
        .format(format)
        .subresource_range(crate::barrier::COLOR_IMAGE);
    // SAFETY: the image is bound to its memory and has the format, one level and one layer the view
    // describes.
    *view = unsafe { d.create_image_view(&info, None) }
        .with_context(|| format!("creating the {what} view"))?;
    Ok(needs.size)
}

impl Drop for Target {
    fn drop(&mut self) {
        // SAFETY: no command buffer using them is pending (see Commands::drop).
        // The readback buffer drops itself after this.
        unsafe {
            self.device.destroy_framebuffer(self.framebuffer, None);
            self.device.destroy_image_view(self.view, None);
            self.device.destroy_image(self.image, None);
            self.device.free_memory(self.memory, None);
        }
    }
}
