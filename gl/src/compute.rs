//! The compute path: the tracer as a compute shader (naga's GLSL of
//! `shaders/trace.comp`, or with `--gl-spirv` naga's SPIR-V), the RGBA32F
//! texture it writes through image unit 5, the dispatch, and the readback.
//!
//! What the fragment path gets from the framebuffer, GL asks for explicitly
//! here: `imageStore` writes are *incoherent*, so a `glMemoryBarrier` must order
//! them before anything else touches the texture, the next dispatch's stores
//! (SHADER_IMAGE_ACCESS; in the window: a headless frame ends in glFinish,
//! which has completed them) and the readback (TEXTURE_UPDATE, for
//! glGetTexImage).
//!
//! In the window the texture is also the colour attachment of a read
//! framebuffer, and each frame blits it into the window's default framebuffer
//! (`glBlitFramebuffer`, after a FRAMEBUFFER barrier: the blit reads through a
//! framebuffer); a new window size makes a new texture.

use anyhow::{anyhow, bail, Context as _};
use glow::HasContext;
use twinray_common::cli::Workgroup;
use twinray_common::error::bad_input;
use twinray_common::explain;
use twinray_common::gpu::layout::binding;
use twinray_common::plan::requests::ComputeLimits;
use twinray_common::shader::build::ComputeShader;

/// The compute program, the storage texture and the dispatch grid.
pub struct Compute<'gl> {
    gl: &'gl glow::Context,
    program: glow::Program,
    texture: glow::Texture,
    /// Windowed only: the framebuffer the blit reads the texture through.
    read_fbo: Option<glow::Framebuffer>,
    workgroup: Workgroup,
    groups: (u32, u32),
    pub width: u32,
    pub height: u32,
}

impl<'gl> Compute<'gl> {
    /// The linked compute program (for `--dump-shaders`).
    pub fn program(&self) -> glow::Program {
        self.program
    }

    /// Builds the program (GLSL, or SPIR-V when `spirv_proc` is given), makes the
    /// texture, and leaves both bound: nothing else changes them during the run.
    pub fn new(
        gl: &'gl glow::Context,
        shader: &ComputeShader,
        spirv_proc: Option<&dyn Fn(&std::ffi::CStr) -> *const std::ffi::c_void>,
        width: u32,
        height: u32,
    ) -> anyhow::Result<Compute<'gl>> {
        let groups = check_limits(gl, shader.workgroup, width, height)?;
        let compiled = match spirv_proc {
            Some(proc_address) => crate::program::compile_spirv(
                gl,
                proc_address,
                glow::COMPUTE_SHADER,
                &shader.spirv_for_opengl(),
                "compute",
            )?,
            // SAFETY: the context is current (the caller made it so).
            None => unsafe {
                crate::program::compile(gl, glow::COMPUTE_SHADER, &shader.stage.glsl, "compute")
            }?,
        };
        let program = link(gl, compiled)?;
        // SAFETY: a fresh texture on the current context; sizes were checked.
        let texture = match unsafe { gl.create_texture() } {
            Ok(t) => t,
            Err(e) => {
                // SAFETY: the program was linked above on this context and nothing uses it yet.
                unsafe { gl.delete_program(program) };
                return Err(anyhow!(e).context("glGenTextures"));
            }
        };
        let this = Compute {
            gl,
            program,
            texture,
            read_fbo: None,
            workgroup: shader.workgroup,
            groups,
            width,
            height,
        };
        this.storage()?;
        // SAFETY: the program is alive on the current context.
        unsafe { gl.use_program(Some(program)) };
        explain::numbered(
            21,
            "Compute program + RGBA32F texture at image unit 5 (glBindImageTexture)",
            || {
                format!(
                    "{width}x{height}, workgroup {}, {}x{} workgroups",
                    shader.workgroup, groups.0, groups.1
                )
            },
        );
        Ok(this)
    }

    /// Gives the texture its storage and binds it to the shader's image unit;
    /// a size the driver cannot hold is bad input naming --size.
    fn storage(&self) -> anyhow::Result<()> {
        // SAFETY: the texture is alive on the current context; sizes were checked.
        unsafe {
            let gl = self.gl;
            gl.bind_texture(glow::TEXTURE_2D, Some(self.texture));
            // Immutable storage, one level: image units need a complete texture.
            gl.tex_storage_2d(
                glow::TEXTURE_2D,
                1,
                glow::RGBA32F,
                self.width as i32,
                self.height as i32,
            );
            crate::target::out_of_memory(gl, "storage image", self.width, self.height)?;
            // WRITE_ONLY matches the shader's `writeonly`; the format its `rgba32f`.
            gl.bind_image_texture(
                binding::IMAGE,
                Some(self.texture),
                0,
                false,
                0,
                glow::WRITE_ONLY,
                glow::RGBA32F,
            );
        }
        Ok(())
    }

    /// Windowed: a texture of the new size (storage is immutable, so a new
    /// texture), re-attached to the blit's framebuffer if there is one.
    pub fn resize(&mut self, width: u32, height: u32) -> anyhow::Result<()> {
        let gl = self.gl;
        self.groups = check_limits(gl, self.workgroup, width, height)?;
        // SAFETY: a new name on the context that is current (the window's).
        let texture = unsafe { gl.create_texture() }
            .map_err(|e| anyhow!(e))
            .context("glGenTextures")?;
        // SAFETY: the old texture is this context's; GL keeps it alive for
        // commands already issued, and storage() and attach() below point the
        // image unit and the framebuffer at the new one.
        unsafe { gl.delete_texture(self.texture) };
        self.texture = texture;
        (self.width, self.height) = (width, height);
        self.storage()?;
        if self.read_fbo.is_some() {
            self.attach()?;
        }
        Ok(())
    }

    /// Windowed: the program in use again (the fragment path may have replaced it).
    pub fn bind(&self) {
        // SAFETY: the program is alive on the current context.
        unsafe { self.gl.use_program(Some(self.program)) }
    }

    /// Windowed: makes the texture the colour attachment of a read
    /// framebuffer, for [`Compute::blit_to_window`].
    pub fn attach(&mut self) -> anyhow::Result<()> {
        let gl = self.gl;
        // SAFETY: objects of the current context.
        unsafe {
            let fbo = match self.read_fbo {
                Some(f) => f,
                None => {
                    let f = gl
                        .create_framebuffer()
                        .map_err(|e| anyhow!(e))
                        .context("glCreateFramebuffer")?;
                    self.read_fbo = Some(f);
                    f
                }
            };
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, Some(fbo));
            gl.framebuffer_texture_2d(
                glow::READ_FRAMEBUFFER,
                glow::COLOR_ATTACHMENT0,
                glow::TEXTURE_2D,
                Some(self.texture),
                0,
            );
            let status = gl.check_framebuffer_status(glow::READ_FRAMEBUFFER);
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, None);
            if status != glow::FRAMEBUFFER_COMPLETE {
                bail!(
                    "the RGBA32F {}x{} texture is no complete read framebuffer (status {status:#x})",
                    self.width,
                    self.height
                );
            }
        }
        Ok(())
    }

    /// Windowed: the last dispatch's image into the window's back buffer.
    /// The texture's row 0 is the top of the image, the default framebuffer's
    /// the bottom of the window, so the blit flips (destination y from the top
    /// down); same size, NEAREST: texel for texel, converted to the window's
    /// 8-bit format as the fragment path's colour write is.
    pub fn blit_to_window(&self) {
        let (w, h) = (self.width as i32, self.height as i32);
        // SAFETY: objects of the current context; `attach` made the FBO complete.
        unsafe {
            let gl = self.gl;
            // imageStore is incoherent: the blit reads through a framebuffer.
            gl.memory_barrier(glow::FRAMEBUFFER_BARRIER_BIT);
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, self.read_fbo);
            gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, None);
            gl.blit_framebuffer(
                0,
                0,
                w,
                h,
                0,
                h,
                w,
                0,
                glow::COLOR_BUFFER_BIT,
                glow::NEAREST,
            );
            gl.bind_framebuffer(glow::READ_FRAMEBUFFER, None);
        }
    }

    /// One frame's GPU work: the dispatch. The timer brackets exactly this.
    pub fn dispatch(&self) {
        // SAFETY: program, texture and buffers are bound and alive.
        unsafe { self.gl.dispatch_compute(self.groups.0, self.groups.1, 1) }
    }

    /// Orders this frame's image stores before the next frame's (the same
    /// texels): the counterpart of Vulkan's barrier between dispatches. The
    /// window's frames need it; headless ones end in glFinish (app.rs).
    pub fn barrier_between_frames(&self) {
        // SAFETY: plain state call on the current context.
        unsafe {
            self.gl
                .memory_barrier(glow::SHADER_IMAGE_ACCESS_BARRIER_BIT)
        }
    }

    /// RGBA32F pixels, row 0 first. The shader wrote the top row at y = 0, so
    /// this is top first, as the PNG wants: no flip, as in the fragment path.
    pub fn read(&self) -> Vec<f32> {
        let mut px = vec![0f32; self.width as usize * self.height as usize * 4];
        // SAFETY: `px` holds exactly width*height RGBA floats, packed with alignment 1.
        unsafe {
            // glGetTexImage must see the incoherent image stores.
            self.gl.memory_barrier(glow::TEXTURE_UPDATE_BARRIER_BIT);
            self.gl.bind_texture(glow::TEXTURE_2D, Some(self.texture));
            self.gl.pixel_store_i32(glow::PACK_ALIGNMENT, 1);
            self.gl.get_tex_image(
                glow::TEXTURE_2D,
                0,
                glow::RGBA,
                glow::FLOAT,
                glow::PixelPackData::Slice(Some(bytemuck::cast_slice_mut(&mut px))),
            );
        }
        px
    }
}

impl Drop for Compute<'_> {
    fn drop(&mut self) {
        // SAFETY: objects of this context, which outlives them.
        unsafe {
            self.gl.use_program(None);
            if let Some(f) = self.read_fbo {
                self.gl.delete_framebuffer(f);
            }
            self.gl.delete_program(self.program);
            self.gl.delete_texture(self.texture);
        }
    }
}

/// The workgroup and the grid against this driver's limits (bad input: the
/// user chose the size and workgroup), and the image against the largest
/// texture. Returns the group counts.
fn check_limits(
    gl: &glow::Context,
    wg: Workgroup,
    width: u32,
    height: u32,
) -> anyhow::Result<(u32, u32)> {
    // SAFETY: plain queries on the current context.
    let (group_size, invocations, group_count, texture) = unsafe {
        (
            [0, 1].map(|i| {
                gl.get_parameter_indexed_i32(glow::MAX_COMPUTE_WORK_GROUP_SIZE, i)
                    .max(0) as u32
            }),
            gl.get_parameter_i32(glow::MAX_COMPUTE_WORK_GROUP_INVOCATIONS)
                .max(0) as u32,
            [0, 1].map(|i| {
                gl.get_parameter_indexed_i32(glow::MAX_COMPUTE_WORK_GROUP_COUNT, i)
                    .max(0) as u32
            }),
            gl.get_parameter_i32(glow::MAX_TEXTURE_SIZE).max(0) as u32,
        )
    };
    let limits = ComputeLimits {
        group_size,
        invocations,
        group_count,
        names: [
            "GL_MAX_COMPUTE_WORK_GROUP_SIZE",
            "GL_MAX_COMPUTE_WORK_GROUP_INVOCATIONS",
            "GL_MAX_COMPUTE_WORK_GROUP_COUNT",
        ],
    };
    if width > texture || height > texture {
        // The workgroup is checked first, as in Vulkan.
        limits.dispatch(wg, 1, 1)?;
        return Err(bad_input(format!("--size {width}x{height} exceeds this device's limit of {texture} (GL_MAX_TEXTURE_SIZE)")));
    }
    limits.dispatch(wg, width, height)
}

/// The compute program, linked from one compiled shader, which goes either way.
fn link(gl: &glow::Context, shader: glow::Shader) -> anyhow::Result<glow::Program> {
    // SAFETY: the shader was compiled on the current context (the caller's),
    // which makes the program too; a program that fails to link is deleted
    // here, so nothing leaks.
    unsafe {
        let program = match gl.create_program() {
            Ok(p) => p,
            Err(e) => {
                gl.delete_shader(shader);
                return Err(anyhow!(e).context("glCreateProgram"));
            }
        };
        crate::program::link(gl, program, &[shader], "compute")
            .inspect_err(|_| gl.delete_program(program))?;
        Ok(program)
    }
}
