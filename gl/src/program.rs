//! The tracer program: compiles and links naga's GLSL 450 core output. Blocks
//! are bound by the explicit `binding` numbers naga writes, never by name.

use anyhow::{anyhow, Context as _};
use glow::HasContext;
use twinray_common::explain;

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
            explain::step("glCreateShader x2 + glCompileShader + glCreateProgram + glLinkProgram", || {
                format!(
                    "vertex {} bytes, fragment {} bytes of naga's GLSL; the driver compiles here, no pipeline state",
                    vertex.len(),
                    fragment.len()
                )
            });
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
        explain::step("glGenVertexArrays (empty VAO)", || "the core profile draws nothing without one bound".into());
        Ok(EmptyVertexArray { gl, raw })
    }
}

impl Drop for EmptyVertexArray<'_> {
    fn drop(&mut self) {
        // SAFETY: object of this context, which outlives it.
        unsafe { self.gl.delete_vertex_array(self.raw) }
    }
}
