//! The offscreen render target: an FBO with one RGBA32F colour renderbuffer
//! (float, so the PNG is quantised exactly as for Vulkan and the reference),
//! the device's size limits, and the readback.

use anyhow::{anyhow, bail, Context as _};
use glow::HasContext;
use twinray_common::error::bad_input;
use twinray_common::explain;

pub struct Target<'gl> {
    gl: &'gl glow::Context,
    fbo: glow::Framebuffer,
    colour: glow::Renderbuffer,
    pub width: u32,
    pub height: u32,
}

/// The smallest of the limits that apply to drawing into and reading from a
/// renderbuffer-backed FBO of this size.
pub fn check_size(gl: &glow::Context, width: u32, height: u32) -> anyhow::Result<()> {
    // SAFETY: plain queries on the current context.
    let (max_w, max_h) = unsafe {
        let mut viewport = [0i32; 2];
        gl.get_parameter_i32_slice(glow::MAX_VIEWPORT_DIMS, &mut viewport);
        let rb = gl.get_parameter_i32(glow::MAX_RENDERBUFFER_SIZE);
        let fb_w = gl.get_parameter_i32(glow::MAX_FRAMEBUFFER_WIDTH);
        let fb_h = gl.get_parameter_i32(glow::MAX_FRAMEBUFFER_HEIGHT);
        (
            viewport[0].min(rb).min(fb_w).max(0) as u32,
            viewport[1].min(rb).min(fb_h).max(0) as u32,
        )
    };
    if width > max_w || height > max_h {
        return Err(bad_input(format!(
            "--size {width}x{height} exceeds this device's limit of {max_w}x{max_h}"
        )));
    }
    Ok(())
}

/// GL_OUT_OF_MEMORY after allocating an RGBA32F image of `width` x `height`:
/// the size the user chose is too large for this device (bad input, said so).
pub fn out_of_memory(
    gl: &glow::Context,
    what: &str,
    width: u32,
    height: u32,
) -> anyhow::Result<()> {
    // SAFETY: a plain query on the current context.
    if unsafe { gl.get_error() } == glow::OUT_OF_MEMORY {
        return Err(bad_input(format!(
            "--size {width}x{height}: this device cannot allocate the {} RGBA32F {what} (GL_OUT_OF_MEMORY); use a smaller --size",
            twinray_common::limits::gib(width as u64 * height as u64 * 16)
        )));
    }
    Ok(())
}

impl<'gl> Target<'gl> {
    /// Creates the FBO and leaves it bound for drawing and reading.
    pub fn new(gl: &'gl glow::Context, width: u32, height: u32) -> anyhow::Result<Target<'gl>> {
        let format = "RGBA32F";
        // SAFETY: fresh objects on the current context; sizes were checked by `check_size`.
        unsafe {
            let colour = gl
                .create_renderbuffer()
                .map_err(|e| anyhow!(e))
                .context("glCreateRenderbuffer")?;
            let fbo = match gl.create_framebuffer() {
                Ok(f) => f,
                Err(e) => {
                    gl.delete_renderbuffer(colour);
                    return Err(anyhow!(e).context("glCreateFramebuffer"));
                }
            };
            let target = Target {
                gl,
                fbo,
                colour,
                width,
                height,
            };
            gl.bind_renderbuffer(glow::RENDERBUFFER, Some(colour));
            gl.renderbuffer_storage(
                glow::RENDERBUFFER,
                glow::RGBA32F,
                width as i32,
                height as i32,
            );
            out_of_memory(gl, "render target", width, height)?;
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
            gl.framebuffer_renderbuffer(
                glow::FRAMEBUFFER,
                glow::COLOR_ATTACHMENT0,
                glow::RENDERBUFFER,
                Some(colour),
            );
            let status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
            if status == glow::FRAMEBUFFER_INCOMPLETE_ATTACHMENT {
                // llvmpipe reports a renderbuffer it could not allocate this way,
                // without GL_OUT_OF_MEMORY; the size was within the device's limits.
                return Err(bad_input(format!(
                    "--size {width}x{height}: this device cannot allocate the {} RGBA32F render target (its framebuffer is incomplete); use a smaller --size",
                    twinray_common::limits::gib(width as u64 * height as u64 * 16)
                )));
            }
            if status != glow::FRAMEBUFFER_COMPLETE {
                bail!(
                    "the {format} {width}x{height} framebuffer is incomplete (status {status:#x})"
                );
            }
            gl.viewport(0, 0, width as i32, height as i32);
            explain::numbered(
                9,
                &format!("glCreateRenderbuffer + glCreateFramebuffer ({format} target)"),
                || {
                    format!("{width}x{height} {format} renderbuffer as COLOR_ATTACHMENT0; FRAMEBUFFER_COMPLETE; glViewport")
                },
            );
            Ok(target)
        }
    }

    /// RGBA pixels as floats.
    /// GL's first row is the bottom one, and the shader treats
    /// +y as down, so that first row is the image's TOP: no flip needed.
    pub fn read(&self) -> Vec<f32> {
        let mut px = vec![0f32; self.width as usize * self.height as usize * 4];
        // SAFETY: `px` holds exactly width*height RGBA floats, packed with alignment 1.
        unsafe {
            self.gl
                .bind_framebuffer(glow::READ_FRAMEBUFFER, Some(self.fbo));
            self.gl.read_buffer(glow::COLOR_ATTACHMENT0);
            self.gl.pixel_store_i32(glow::PACK_ALIGNMENT, 1);
            self.gl.read_pixels(
                0,
                0,
                self.width as i32,
                self.height as i32,
                glow::RGBA,
                glow::FLOAT,
                glow::PixelPackData::Slice(Some(bytemuck::cast_slice_mut(&mut px))),
            );
        }
        px
    }
}

impl Drop for Target<'_> {
    fn drop(&mut self) {
        // SAFETY: objects of this context; the FBO goes before the storage it references.
        unsafe {
            self.gl.bind_framebuffer(glow::FRAMEBUFFER, None);
            self.gl.delete_framebuffer(self.fbo);
            self.gl.delete_renderbuffer(self.colour);
        }
    }
}
