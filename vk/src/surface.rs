//! The window surface (windowed mode only): Vulkan's handle on a window.
//!
//! Vulkan itself knows nothing about windows. Presenting is an extension
//! (VK_KHR_surface plus one per window system, e.g. VK_KHR_xlib_surface), so the
//! instance must enable the window system's extensions before any window can
//! be used, and a `VkSurfaceKHR` wraps the native window for the device to
//! draw to. ash-window turns winit's raw window handle into the right call.
//! The surface also answers the questions the swapchain needs: which formats,
//! present modes and image sizes this device can show in this window.

use crate::instance::Instance;
use anyhow::{Context, Result};
use ash::{khr, vk};
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use std::ffi::c_char;
use twinray_common::explain;
use winit::window::Window;

pub struct Surface {
    pub loader: khr::surface::Instance,
    pub surface: vk::SurfaceKHR,
}

/// The instance extensions this window system needs (VK_KHR_surface + its own).
pub fn required_extensions(window: &Window) -> Result<&'static [*const c_char]> {
    let display = window
        .display_handle()
        .context("getting the window's display handle")?
        .as_raw();
    ash_window::enumerate_required_extensions(display)
        .context("this window system has no Vulkan surface extension (ash-window)")
}

impl Surface {
    /// The window must outlive the surface (the windowed app declares it last,
    /// so it is dropped after everything made from it).
    pub fn new(instance: &Instance, window: &Window) -> Result<Surface> {
        let display = window
            .display_handle()
            .context("getting the window's display handle")?
            .as_raw();
        let handle = window
            .window_handle()
            .context("getting the window handle")?
            .as_raw();
        // SAFETY: both handles belong to a live window that outlives the surface.
        let surface = unsafe {
            ash_window::create_surface(&instance.entry, &instance.instance, display, handle, None)
        }
        .context("creating the window surface")?;
        explain::numbered(12, "VkSurfaceKHR (ash_window::create_surface)", || {
            format!("for the {} window", window_system(&handle))
        });
        Ok(Surface {
            loader: khr::surface::Instance::new(&instance.entry, &instance.instance),
            surface,
        })
    }

    /// Whether `family` of `physical` can present to this surface: not every
    /// queue that draws can show its results in a window.
    pub fn supports(&self, physical: vk::PhysicalDevice, family: u32) -> bool {
        // SAFETY: both handles are alive; an error counts as "no".
        unsafe {
            self.loader
                .get_physical_device_surface_support(physical, family, self.surface)
        }
        .unwrap_or(false)
    }
}

fn window_system(handle: &raw_window_handle::RawWindowHandle) -> &'static str {
    use raw_window_handle::RawWindowHandle as H;
    match handle {
        H::Xlib(_) => "X11 (Xlib)",
        H::Xcb(_) => "X11 (XCB)",
        H::Wayland(_) => "Wayland",
        H::Win32(_) => "Win32",
        H::AppKit(_) => "AppKit",
        _ => "native",
    }
}

impl Drop for Surface {
    fn drop(&mut self) {
        // SAFETY: the swapchain made from it is gone (see window.rs's field order).
        unsafe { self.loader.destroy_surface(self.surface, None) };
        explain::numbered(20, "Surface::drop: vkDestroySurfaceKHR", String::new);
    }
}
