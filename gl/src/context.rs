//! The headless OpenGL context: EGL device platform, surfaceless 4.5 core
//! context, and the glow function table loaded from it. Owns device choice.

use anyhow::Context as _;
use glow::HasContext;
use glutin::api::egl::{context::PossiblyCurrentContext, device::Device, display::Display};
use glutin::config::{Api, ConfigSurfaceTypes, ConfigTemplateBuilder};
use glutin::context::{ContextApi, ContextAttributesBuilder, GlProfile, Robustness, Version};
use glutin::prelude::*;
use twinray_common::cli::OpenGlKnobs;
use twinray_common::error::{bad_input, no_device};
use twinray_common::explain;
use twinray_common::limits::StorageLimit;
use twinray_common::report::DeviceInfo;

const NO_DEVICE: &str =
    "no EGL device found: install libegl1 and libegl-mesa0 + libgl1-mesa-dri (or a GPU driver)";

/// Mesa's llvmpipe device carries this extension; a hardware device does not.
const SOFTWARE_EXT: &str = "EGL_MESA_device_software";

/// Field order is drop order: the function table goes before the context it
/// came from, and the context before its display.
pub struct Gl {
    pub gl: glow::Context,
    _context: PossiblyCurrentContext,
    _display: Display,
}

impl Gl {
    /// An entry point glow does not wrap (glShaderBinary, glSpecializeShader).
    pub fn proc_address(&self, name: &std::ffi::CStr) -> *const std::ffi::c_void {
        self._display.get_proc_address(name)
    }

    /// Creates the context on the preferred device (or `knobs`'s); `debug` asks
    /// for a debug context so that KHR_debug reports everything the driver checks.
    pub fn headless(debug: bool, knobs: &OpenGlKnobs) -> anyhow::Result<Gl> {
        // No libEGL, or one without the device extensions, is a missing driver
        // for the user, not a bug: glutin's error alone would not say what to install.
        let devices: Vec<Device> = Device::query_devices()
            .map_err(|e| no_device(format!("{NO_DEVICE} ({e})")))?
            .collect();
        if devices.is_empty() {
            return Err(no_device(NO_DEVICE));
        }
        explain::numbered(3, "EGL devices (eglQueryDevicesEXT)", || {
            devices
                .iter()
                .enumerate()
                .map(|(i, d)| {
                    let soft = if d.extensions().contains(SOFTWARE_EXT) {
                        " (software)"
                    } else {
                        ""
                    };
                    format!("{i}: {}{soft}\n", d.name().unwrap_or("unnamed"))
                })
                .collect::<String>()
                + "hardware devices are tried first; --gl-device (TWINRAY_GL_DEVICE) overrides"
        });
        let mut failures = Vec::new();
        for (index, device) in candidates(&devices, knobs.device)? {
            match create(index, device, debug) {
                Ok(gl) => {
                    // A run that fell back to another device must say so: its
                    // timings would otherwise pass for the skipped device's.
                    for f in &failures {
                        eprintln!("twinray-gl: note: skipped {f}");
                    }
                    return Ok(gl);
                }
                Err(e) => failures.push(format!("{e:#}")),
            }
        }
        Err(no_device(format!(
            "no EGL device offers an OpenGL 4.5 core context: {}",
            failures.join("; ")
        )))
    }
}

/// Devices to try in order. Hardware first: the software rasteriser would
/// silently turn a GPU benchmark into a CPU one.
fn candidates(devices: &[Device], wanted: Option<usize>) -> anyhow::Result<Vec<(usize, &Device)>> {
    if let Some(i) = wanted {
        let device = devices.get(i).ok_or_else(|| {
            bad_input(format!(
                "--gl-device (TWINRAY_GL_DEVICE) {i} is not a device index; this machine has {} EGL device(s), 0..{}",
                devices.len(),
                devices.len() - 1
            ))
        })?;
        return Ok(vec![(i, device)]);
    }
    let (soft, hard): (Vec<_>, Vec<_>) = devices
        .iter()
        .enumerate()
        .partition(|(_, d)| d.extensions().contains(SOFTWARE_EXT));
    Ok(hard.into_iter().chain(soft).collect())
}

fn create(index: usize, device: &Device, debug: bool) -> anyhow::Result<Gl> {
    let what = format!(
        "EGL device {index} ({})",
        device.name().unwrap_or("unnamed")
    );
    // SAFETY: no native display handle is passed, only the device.
    let display = unsafe { Display::with_device(device, None) }
        .with_context(|| format!("opening an EGL display on {what}"))?;
    // No surface types: the context renders into our own FBO only.
    let template = ConfigTemplateBuilder::new()
        .with_surface_type(ConfigSurfaceTypes::empty())
        .with_api(Api::OPENGL)
        .build();
    // SAFETY: the display outlives the configs iterator (same scope).
    let config = unsafe { display.find_configs(template) }
        .with_context(|| format!("listing EGL configs on {what}"))?
        .next()
        .with_context(|| format!("{what} has no OpenGL EGL config"))?;
    let attributes = ContextAttributesBuilder::new()
        .with_debug(debug)
        .with_robustness(Robustness::NotRobust)
        .with_profile(GlProfile::Core)
        .with_context_api(ContextApi::OpenGl(Some(Version::new(4, 5))))
        .build(None);
    // SAFETY: config belongs to display.
    let context = unsafe { display.create_context(&config, &attributes) }
        .with_context(|| format!("creating an OpenGL 4.5 core context on {what}"))?
        .make_current_surfaceless()
        .with_context(|| format!("making the context current without a surface on {what}"))?;
    explain::numbered(
        4,
        "EGL display + config + context, made current without a surface",
        || {
            format!(
                "{what}: OpenGL 4.5 core{}, surfaceless (renders into our own FBO)",
                if debug { ", debug" } else { "" }
            )
        },
    );
    // SAFETY: the context is current on this thread, which glow requires.
    let gl = unsafe { glow::Context::from_loader_function_cstr(|s| display.get_proc_address(s)) };
    Ok(Gl {
        gl,
        _context: context,
        _display: display,
    })
}

/// What the `--json` report says about the context's device: the renderer,
/// the vendor and version strings, as the driver gives them.
pub fn device_info(gl: &glow::Context) -> DeviceInfo {
    // SAFETY: plain string queries on the current context.
    let (renderer, vendor, version) = unsafe {
        (
            gl.get_parameter_string(glow::RENDERER),
            gl.get_parameter_string(glow::VENDOR),
            gl.get_parameter_string(glow::VERSION),
        )
    };
    DeviceInfo {
        device: renderer,
        driver: format!("{vendor} {version}"),
        api_version: format!("OpenGL {version}"),
    }
}

/// The largest storage block the context binds: what every run plan is checked
/// against; and the largest buffer texture, which the plan checks the tree's
/// nodes against before OpenGL reads them through one (`Api::node_texels`).
pub fn storage_limit(gl: &glow::Context) -> StorageLimit {
    // SAFETY: plain queries; 64-bit because the limits may exceed 2 GiB.
    let (bytes, texels) = unsafe {
        (
            gl.get_parameter_i64(glow::MAX_SHADER_STORAGE_BLOCK_SIZE),
            gl.get_parameter_i64(glow::MAX_TEXTURE_BUFFER_SIZE),
        )
    };
    StorageLimit {
        bytes: bytes.max(0) as u64,
        name: "this device's GL_MAX_SHADER_STORAGE_BLOCK_SIZE limit",
        texel_buffer: texels.max(0) as u64,
    }
}
