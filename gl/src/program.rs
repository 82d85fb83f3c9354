//! The tracer program: compiles and links naga's GLSL 450 core output, or, with
//! `--gl-spirv`, loads naga's SPIR-V through GL_ARB_gl_spirv (the same binary
//! Vulkan runs). Blocks are bound by the explicit `binding` numbers naga writes,
//! never by name.

use anyhow::{anyhow, Context as _};
use glow::HasContext;

pub struct Program<'gl> {
    gl: &'gl glow::Context,
    raw: glow::Program,
}

impl<'gl> Program<'gl> {
    pub fn new(gl: &'gl glow::Context, vertex: &str, fragment: &str) -> anyhow::Result<Program<'gl>> {
        // SAFETY: objects are created and deleted on the current context; the
        // shaders are detached and deleted once linked (the linked program no longer needs them).
        unsafe {
            let raw = gl.create_program().map_err(|e| anyhow!(e)).context("glCreateProgram")?;
            let program = Program { gl, raw };
            let vs = compile(gl, glow::VERTEX_SHADER, vertex, "vertex")?;
            let fs = match compile(gl, glow::FRAGMENT_SHADER, fragment, "fragment") {
                Ok(fs) => fs,
                Err(e) => {
                    gl.delete_shader(vs);
                    return Err(e);
                }
            };
            gl.attach_shader(raw, vs);
            gl.attach_shader(raw, fs);
            gl.link_program(raw);
            let linked = gl.get_program_link_status(raw);
            for s in [fs, vs] {
                gl.detach_shader(raw, s);
                gl.delete_shader(s);
            }
            if !linked {
                return Err(anyhow!("linking the tracer program failed:\n{}", gl.get_program_info_log(raw)));
            }
            Ok(program)
        }
    }

    /// Loads SPIR-V modules (already adapted by `shader::spirv_for_opengl`).
    /// glow wraps neither glShaderBinary nor glSpecializeShader, so they are
    /// looked up directly.
    pub fn from_spirv(
        gl: &'gl glow::Context,
        proc_address: &dyn Fn(&std::ffi::CStr) -> *const std::ffi::c_void,
        vertex: &[u32],
        fragment: &[u32],
    ) -> anyhow::Result<Program<'gl>> {
        type ShaderBinary = unsafe extern "system" fn(i32, *const u32, u32, *const std::ffi::c_void, i32);
        type SpecializeShader = unsafe extern "system" fn(u32, *const std::ffi::c_char, u32, *const u32, *const u32);
        if !gl.supported_extensions().contains("GL_ARB_gl_spirv") {
            return Err(twinray_common::error::no_device(
                "--gl-spirv: this OpenGL driver does not support GL_ARB_gl_spirv (Mesa 22.3's llvmpipe does not; NVIDIA does)",
            ));
        }
        let binary = proc_address(c"glShaderBinary");
        let specialize = proc_address(c"glSpecializeShader");
        if binary.is_null() || specialize.is_null() {
            return Err(anyhow!("the driver lists GL_ARB_gl_spirv but has no glShaderBinary/glSpecializeShader"));
        }
        // SAFETY: both pointers are the driver's entry points with these C signatures (GL 4.6 core).
        let (binary, specialize): (ShaderBinary, SpecializeShader) =
            unsafe { (std::mem::transmute(binary), std::mem::transmute(specialize)) };
        // SAFETY: objects are created and used on the current context; the word
        // slices outlive the calls; the entry point name is NUL-terminated.
        unsafe {
            let raw = gl.create_program().map_err(|e| anyhow!(e)).context("glCreateProgram")?;
            let program = Program { gl, raw };
            let mut shaders = Vec::new();
            for (stage, words, name) in [(glow::VERTEX_SHADER, vertex, "vertex"), (glow::FRAGMENT_SHADER, fragment, "fragment")] {
                let s = gl.create_shader(stage).map_err(|e| anyhow!(e)).with_context(|| format!("glCreateShader({name})"))?;
                shaders.push(s);
                let id = s.0.get();
                binary(1, &id, glow::SHADER_BINARY_FORMAT_SPIR_V, words.as_ptr().cast(), (words.len() * 4) as i32);
                specialize(id, c"main".as_ptr(), 0, std::ptr::null(), std::ptr::null());
                if !gl.get_shader_compile_status(s) {
                    let log = gl.get_shader_info_log(s);
                    for s in &shaders {
                        gl.delete_shader(*s);
                    }
                    return Err(anyhow!("the driver rejected naga's {name} SPIR-V:\n{log}"));
                }
                gl.attach_shader(raw, s);
            }
            gl.link_program(raw);
            let linked = gl.get_program_link_status(raw);
            for s in shaders {
                gl.detach_shader(raw, s);
                gl.delete_shader(s);
            }
            if !linked {
                return Err(anyhow!("linking the SPIR-V tracer program failed:\n{}", gl.get_program_info_log(raw)));
            }
            Ok(program)
        }
    }

    /// Makes this program and `vao` the draw state; nothing else changes it.
    pub fn bind(&self, vao: &EmptyVertexArray) {
        // SAFETY: both objects are alive and belong to the current context.
        unsafe {
            self.gl.use_program(Some(self.raw));
            self.gl.bind_vertex_array(Some(vao.raw));
        }
    }
}

/// # Safety
/// Needs a current context.
unsafe fn compile(gl: &glow::Context, stage: u32, source: &str, name: &str) -> anyhow::Result<glow::Shader> {
    // SAFETY: forwarded from the caller.
    unsafe {
        let s = gl.create_shader(stage).map_err(|e| anyhow!(e)).with_context(|| format!("glCreateShader({name})"))?;
        gl.shader_source(s, source);
        gl.compile_shader(s);
        if !gl.get_shader_compile_status(s) {
            let log = gl.get_shader_info_log(s);
            gl.delete_shader(s);
            // naga's GLSL failing to compile is a naga/driver mismatch; the log says which line.
            return Err(anyhow!("the driver rejected naga's {name} GLSL:\n{log}"));
        }
        Ok(s)
    }
}

impl Drop for Program<'_> {
    fn drop(&mut self) {
        // SAFETY: the program was created on this context, which outlives it.
        unsafe { self.gl.delete_program(self.raw) }
    }
}

/// The vertex shader builds its triangle from gl_VertexID, but a core
/// profile refuses to draw with no vertex array object bound: an empty one.
pub struct EmptyVertexArray<'gl> {
    gl: &'gl glow::Context,
    raw: glow::VertexArray,
}

impl<'gl> EmptyVertexArray<'gl> {
    pub fn new(gl: &'gl glow::Context) -> anyhow::Result<EmptyVertexArray<'gl>> {
        // SAFETY: a fresh object on the current context.
        let raw = unsafe { gl.create_vertex_array() }.map_err(|e| anyhow!(e).context("glGenVertexArrays"))?;
        Ok(EmptyVertexArray { gl, raw })
    }
}

impl Drop for EmptyVertexArray<'_> {
    fn drop(&mut self) {
        // SAFETY: object of this context, which outlives it.
        unsafe { self.gl.delete_vertex_array(self.raw) }
    }
}
