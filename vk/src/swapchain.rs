//! The swapchain (windowed mode only): the images the window shows, with an
//! image view and a framebuffer for each, and one "render finished" semaphore
//! per image.
//!
//! Vulkan cannot draw into a window directly. The *swapchain* is a small ring
//! of images owned by the presentation engine: the app acquires one, renders
//! into it and hands it back to be shown ("presented"). Everything about it is
//! the app's choice, made from what the surface supports:
//!
//! - **format**: UNORM, not sRGB. The tracer writes colour values that the PNGs
//!   store as they are (`image_io` clamps and rounds, no sRGB encoding); an
//!   `_SRGB` format would encode on store and the window would look brighter
//!   than every PNG and than the OpenGL window.
//! - **present mode**: MAILBOX (newest frame replaces a waiting one) or
//!   IMMEDIATE, so the frame rate is not capped by the display; FIFO (wait for
//!   vertical blank, always supported) with `--vsync`.
//! - **image count**: one more than the minimum, so acquiring rarely waits for
//!   the presentation engine to give an image back.
//! - **extent**: the window's size; 0×0 (minimized) means no swapchain at all.
//! - **usage**: COLOR_ATTACHMENT for the fragment path's render pass, and
//!   TRANSFER_DST, where the surface allows it, for the compute path, which
//!   blits its storage image into the acquired image (compute.rs). Both are
//!   asked for up front, so a live switch between the paths needs no new
//!   swapchain.
//!
//! When the window changes size the swapchain no longer fits and must be made
//! again (with the old one passed as `oldSwapchain`), with new views and
//! framebuffers. The render-finished semaphores are per image, not per frame in
//! flight: presentation holds on to a semaphore until that image is shown
//! again, which only re-acquiring that image proves.

use crate::device::Device;
use crate::surface::Surface;
use anyhow::{Context, Result};
use ash::{khr, vk};
use twinray_common::explain;

/// The surface's formats, best first for this app: 8-bit UNORM in the standard
/// colour space (see the module comment for why not sRGB).
pub fn choose_format(device: &Device, surface: &Surface) -> Result<vk::SurfaceFormatKHR> {
    // SAFETY: the surface and the physical device are borrowed from their owners, so alive for the query, and come from the same instance.
    let formats = unsafe {
        surface
            .loader
            .get_physical_device_surface_formats(device.physical, surface.surface)
    }
    .context("listing the surface's formats")?;
    let preferred = [
        vk::Format::B8G8R8A8_UNORM,
        vk::Format::R8G8B8A8_UNORM,
        vk::Format::A8B8G8R8_UNORM_PACK32,
    ];
    let chosen = preferred
        .iter()
        .find_map(|&want| {
            formats
                .iter()
                .find(|f| f.format == want && f.color_space == vk::ColorSpaceKHR::SRGB_NONLINEAR)
        })
        .or_else(|| formats.first())
        .copied()
        .context("the surface offers no formats")?;
    explain::numbered(13, "Surface format chosen", || {
        let offered: Vec<String> = formats
            .iter()
            .map(|f| format!("{:?}/{:?}", f.format, f.color_space))
            .collect();
        format!(
            "offered: {}\nchosen: {:?} / {:?}: UNORM, because the tracer's values are stored unencoded\n\
             in the PNGs (image_io quantises without sRGB); an _SRGB format would make the window brighter",
            offered.join(", "),
            chosen.format,
            chosen.color_space
        )
    });
    Ok(chosen)
}

/// MAILBOX, else IMMEDIATE (both uncapped), else FIFO; FIFO with `--vsync`.
pub fn choose_present_mode(
    device: &Device,
    surface: &Surface,
    vsync: bool,
) -> Result<vk::PresentModeKHR> {
    // SAFETY: the surface and the physical device are borrowed from their owners, so alive for the query, and come from the same instance.
    let modes = unsafe {
        surface
            .loader
            .get_physical_device_surface_present_modes(device.physical, surface.surface)
    }
    .context("listing the surface's present modes")?;
    let uncapped = [vk::PresentModeKHR::MAILBOX, vk::PresentModeKHR::IMMEDIATE];
    let chosen = if vsync {
        vk::PresentModeKHR::FIFO
    } else {
        uncapped
            .into_iter()
            .find(|m| modes.contains(m))
            .unwrap_or(vk::PresentModeKHR::FIFO)
    };
    explain::numbered(13, "Present mode chosen", || {
        let why = match (vsync, chosen) {
            (true, _) => "--vsync: FIFO waits for the display's refresh (every device supports it)",
            (false, vk::PresentModeKHR::FIFO) => {
                "no uncapped mode offered: FIFO, capped at the refresh rate"
            }
            _ => "uncapped, so the FPS in the title measures the tracer, not the display",
        };
        format!("offered: {modes:?}\nchosen: {chosen:?}: {why}")
    });
    Ok(chosen)
}

/// Whether the surface lets swapchain images be transfer destinations, which
/// the compute path's blit needs (most drivers do; the spec does not promise it).
pub fn accepts_transfer_writes(device: &Device, surface: &Surface) -> Result<bool> {
    // SAFETY: the surface and the physical device are borrowed from their owners, so alive for the query, and come from the same instance.
    let caps = unsafe {
        surface
            .loader
            .get_physical_device_surface_capabilities(device.physical, surface.surface)
    }
    .context("reading the surface's capabilities")?;
    Ok(caps
        .supported_usage_flags
        .contains(vk::ImageUsageFlags::TRANSFER_DST))
}

pub struct Swapchain {
    device: ash::Device,
    loader: khr::swapchain::Device,
    pub swapchain: vk::SwapchainKHR,
    pub extent: vk::Extent2D,
    /// Owned by the swapchain (destroyed with it); the compute path blits into them.
    pub images: Vec<vk::Image>,
    views: Vec<vk::ImageView>,
    pub framebuffers: Vec<vk::Framebuffer>,
    /// Per image: signalled by the submit that drew into it, waited on by its present.
    pub render_finished: Vec<vk::Semaphore>,
}

impl Swapchain {
    /// `None` when the window has no area (minimized): there is nothing to show.
    // Long function: the walkthrough's swapchain step in order (the extent, the swapchain, its images and their views), one block each.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        device: &Device,
        surface: &Surface,
        loader: &khr::swapchain::Device,
        render_pass: vk::RenderPass,
        format: vk::SurfaceFormatKHR,
        present_mode: vk::PresentModeKHR,
        window_size: (u32, u32),
        old: Option<&Swapchain>,
    ) -> Result<Option<Swapchain>> {
        let d = &device.device;
        // SAFETY: the surface and the physical device are borrowed from their owners, so alive for the query, and come from the same instance.
        let caps = unsafe {
            surface
                .loader
                .get_physical_device_surface_capabilities(device.physical, surface.surface)
        }
        .context("reading the surface's capabilities")?;
        // u32::MAX means "the swapchain decides" (Wayland); otherwise it must match the window.
        let extent = if caps.current_extent.width != u32::MAX {
            caps.current_extent
        } else {
            vk::Extent2D {
                width: window_size
                    .0
                    .clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: window_size
                    .1
                    .clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            }
        };
        if extent.width == 0 || extent.height == 0 {
            return Ok(None);
        }
        device.check_size(extent.width, extent.height)?;
        let mut image_count = caps.min_image_count + 1;
        if caps.max_image_count > 0 {
            image_count = image_count.min(caps.max_image_count);
        }
        let alpha = [
            vk::CompositeAlphaFlagsKHR::OPAQUE,
            vk::CompositeAlphaFlagsKHR::INHERIT,
            vk::CompositeAlphaFlagsKHR::PRE_MULTIPLIED,
            vk::CompositeAlphaFlagsKHR::POST_MULTIPLIED,
        ]
        .into_iter()
        .find(|&a| caps.supported_composite_alpha.contains(a))
        .unwrap_or(vk::CompositeAlphaFlagsKHR::OPAQUE);
        let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT
            | (caps.supported_usage_flags & vk::ImageUsageFlags::TRANSFER_DST);
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(surface.surface)
            .min_image_count(image_count)
            .image_format(format.format)
            .image_color_space(format.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(usage)
            // One queue draws and presents, so no sharing between families.
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(alpha)
            .present_mode(present_mode)
            // Pixels hidden behind other windows need not be drawn.
            .clipped(true)
            .old_swapchain(old.map_or(vk::SwapchainKHR::null(), |o| o.swapchain));
        let mut this = Swapchain {
            device: d.clone(),
            loader: loader.clone(),
            swapchain: vk::SwapchainKHR::null(),
            extent,
            images: Vec::new(),
            views: Vec::new(),
            framebuffers: Vec::new(),
            render_finished: Vec::new(),
        };
        // SAFETY: the surface is alive (the window owns it, and it outlives the
        // swapchain); size, format, present mode, usage and image count were
        // chosen from what this surface reports; the old swapchain (if any) is
        // retired by this call and destroyed by its owner after the GPU is idle.
        this.swapchain =
            unsafe { loader.create_swapchain(&info, None) }.context("creating the swapchain")?;
        // SAFETY: the swapchain was just made; its images are its own and go with it.
        this.images = unsafe { loader.get_swapchain_images(this.swapchain) }
            .context("getting the swapchain images")?;
        let images = this.images.clone();
        explain::numbered(14, "VkSwapchainKHR", || {
            format!(
                "{}x{} {:?}, {} images (asked {image_count}: min {} + 1), {present_mode:?}\n\
                 usage {usage:?}, EXCLUSIVE, transform {:?}, alpha {alpha:?}, clipped{}",
                extent.width,
                extent.height,
                format.format,
                images.len(),
                caps.min_image_count,
                caps.current_transform,
                if old.is_some() {
                    "; replaces the old swapchain (oldSwapchain)"
                } else {
                    ""
                }
            )
        });

        for &image in &images {
            let info = vk::ImageViewCreateInfo::default()
                .image(image)
                .view_type(vk::ImageViewType::TYPE_2D)
                .format(format.format)
                .subresource_range(crate::barrier::COLOR_IMAGE);
            // SAFETY: `image` is one of this swapchain's images and `format` its
            // format; `this` destroys the view before the swapchain.
            let view = unsafe { d.create_image_view(&info, None) }
                .context("creating a swapchain image view")?;
            this.views.push(view);
            let views = [view];
            let info = vk::FramebufferCreateInfo::default()
                .render_pass(render_pass)
                .attachments(&views)
                .width(extent.width)
                .height(extent.height)
                .layers(1);
            // SAFETY: the view was just made at the swapchain's extent, in the
            // format the render pass (alive, the window's) was made for; `this`
            // destroys the framebuffer before the view.
            let framebuffer = unsafe { d.create_framebuffer(&info, None) }
                .context("creating a swapchain framebuffer")?;
            this.framebuffers.push(framebuffer);
            // SAFETY: a create on the live device; `this` destroys it after the GPU is idle.
            let semaphore =
                unsafe { d.create_semaphore(&vk::SemaphoreCreateInfo::default(), None) }
                    .context("creating a render-finished semaphore")?;
            this.render_finished.push(semaphore);
        }
        explain::numbered(
            14,
            "VkImageView + VkFramebuffer + VkSemaphore per swapchain image",
            || {
                format!(
                "{} of each: the views let the render pass see the images; the semaphores order present after draw",
                images.len()
            )
            },
        );
        Ok(Some(this))
    }
}

impl Drop for Swapchain {
    fn drop(&mut self) {
        // SAFETY: the owner waited for the device to go idle first (window.rs).
        unsafe {
            for &s in &self.render_finished {
                self.device.destroy_semaphore(s, None);
            }
            for &f in &self.framebuffers {
                self.device.destroy_framebuffer(f, None);
            }
            for &v in &self.views {
                self.device.destroy_image_view(v, None);
            }
            self.loader.destroy_swapchain(self.swapchain, None);
        }
        explain::numbered(
            20,
            "Swapchain::drop: per image vkDestroySemaphore, vkDestroyFramebuffer, vkDestroyImageView; vkDestroySwapchainKHR",
            String::new,
        );
    }
}
