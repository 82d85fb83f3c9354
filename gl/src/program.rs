//! The tracer program: compiles and links naga's GLSL 450 core output, or, with
//! `--gl-spirv`, loads naga's SPIR-V through GL_ARB_gl_spirv (the same binary
//! Vulkan runs). Blocks are bound by the explicit `binding` numbers naga writes,
//! never by name.

use anyhow::{anyhow, Context as _};
use glow::HasContext;
use std::ffi::c_void;
use twinray_common::explain;

pub struct Program<'gl> {
    gl: &'gl glow::Context,
    raw: glow::Program,
    /// Set for the `--gl-spirv` path: `raw` holds the SPIR-V fragment stage.
    pipeline: Option<SeparablePipeline>,
}

/// A program pipeline joining a GLSL vertex program and the SPIR-V tracer.
struct SeparablePipeline {
    fns: PipelineFns,
    pipeline: u32,
    vertex: glow::Program,
}

type ProgramParameteri = unsafe extern "system" fn(u32, u32, i32);
type GenProgramPipelines = unsafe extern "system" fn(i32, *mut u32);
type DeleteProgramPipelines = unsafe extern "system" fn(i32, *const u32);
type BindProgramPipeline = unsafe extern "system" fn(u32);
type UseProgramStages = unsafe extern "system" fn(u32, u32, u32);

/// GL 4.1/4.6 entry points glow does not wrap.
#[derive(Clone, Copy)]
struct PipelineFns {
    program_parameteri: ProgramParameteri,
    gen_program_pipelines: GenProgramPipelines,
    delete_program_pipelines: DeleteProgramPipelines,
    bind_program_pipeline: BindProgramPipeline,
    use_program_stages: UseProgramStages,
}

impl PipelineFns {
    fn load(
        proc_address: &dyn Fn(&std::ffi::CStr) -> *const std::ffi::c_void,
    ) -> anyhow::Result<PipelineFns> {
        let get = |name: &std::ffi::CStr| entry_point(proc_address, name);
        // SAFETY: each pointer is the driver's entry point of that name (non-null,
        // checked by entry_point), whose C signature in GL 4.6 core is the type
        // it is transmuted to; function pointers and data pointers have the same
        // size on every platform GL runs on.
        unsafe {
            Ok(PipelineFns {
                program_parameteri: std::mem::transmute::<*const c_void, ProgramParameteri>(get(
                    c"glProgramParameteri",
                )?),
                gen_program_pipelines: std::mem::transmute::<*const c_void, GenProgramPipelines>(
                    get(c"glGenProgramPipelines")?,
                ),
                delete_program_pipelines: std::mem::transmute::<
                    *const c_void,
                    DeleteProgramPipelines,
                >(get(c"glDeleteProgramPipelines")?),
                bind_program_pipeline: std::mem::transmute::<*const c_void, BindProgramPipeline>(
                    get(c"glBindProgramPipeline")?,
                ),
                use_program_stages: std::mem::transmute::<*const c_void, UseProgramStages>(get(
                    c"glUseProgramStages",
                )?),
            })
        }
    }
}

/// A GL entry point glow does not wrap, or a clear error naming it.
fn entry_point(
    proc_address: &dyn Fn(&std::ffi::CStr) -> *const std::ffi::c_void,
    name: &std::ffi::CStr,
) -> anyhow::Result<*const std::ffi::c_void> {
    let p = proc_address(name);
    if p.is_null() {
        Err(anyhow!(
            "the OpenGL driver has no {}",
            name.to_string_lossy()
        ))
    } else {
        Ok(p)
    }
}

/// Compiles one stage from naga's SPIR-V (adapted by `shader::spirv_for_opengl`)
/// through GL_ARB_gl_spirv; shared by the fragment and compute paths.
pub(crate) fn compile_spirv(
    gl: &glow::Context,
    proc_address: &dyn Fn(&std::ffi::CStr) -> *const std::ffi::c_void,
    stage: u32,
    words: &[u32],
    name: &str,
) -> anyhow::Result<glow::Shader> {
    type ShaderBinary =
        unsafe extern "system" fn(i32, *const u32, u32, *const std::ffi::c_void, i32);
    type SpecializeShader =
        unsafe extern "system" fn(u32, *const std::ffi::c_char, u32, *const u32, *const u32);
    if !gl.supported_extensions().contains("GL_ARB_gl_spirv") {
        return Err(twinray_common::error::no_device(
            "--gl-spirv: this OpenGL driver does not support GL_ARB_gl_spirv",
        ));
    }
    let binary = entry_point(proc_address, c"glShaderBinary")?;
    let specialize = entry_point(proc_address, c"glSpecializeShader")?;
    // SAFETY: both pointers are the driver's entry points with the GL 4.6 core
    // signatures the types spell out; the words outlive the calls; the shader
    // belongs to the current context.
    unsafe {
        let binary = std::mem::transmute::<*const std::ffi::c_void, ShaderBinary>(binary);
        let specialize =
            std::mem::transmute::<*const std::ffi::c_void, SpecializeShader>(specialize);
        let s = gl
            .create_shader(stage)
            .map_err(|e| anyhow!(e))
            .with_context(|| format!("glCreateShader({name})"))?;
        let id = s.0.get();
        binary(
            1,
            &id,
            glow::SHADER_BINARY_FORMAT_SPIR_V,
            words.as_ptr().cast(),
            (words.len() * 4) as i32,
        );
        specialize(id, c"main".as_ptr(), 0, std::ptr::null(), std::ptr::null());
        if !gl.get_shader_compile_status(s) {
            let log = gl.get_shader_info_log(s);
            gl.delete_shader(s);
            return Err(anyhow!("the driver rejected naga's {name} SPIR-V:\n{log}"));
        }
        Ok(s)
    }
}

/// Links compiled `shaders` into `program`, then detaches and deletes them
/// (the linked program no longer needs them), whether the link worked or not.
/// Every program here (vertex + fragment, a separable stage, compute) is made
/// this way; `program` stays the caller's to delete.
///
/// # Safety
/// Needs a current context that owns `program` and `shaders`.
pub(crate) unsafe fn link(
    gl: &glow::Context,
    program: glow::Program,
    shaders: &[glow::Shader],
    what: &str,
) -> anyhow::Result<()> {
    // SAFETY: forwarded from the caller.
    unsafe {
        for &s in shaders {
            gl.attach_shader(program, s);
        }
        gl.link_program(program);
        let linked = gl.get_program_link_status(program);
        for &s in shaders {
            gl.detach_shader(program, s);
            gl.delete_shader(s);
        }
        if !linked {
            return Err(anyhow!(
                "linking the {what} program failed:\n{}",
                gl.get_program_info_log(program)
            ));
        }
        Ok(())
    }
}

/// What `--dump-shaders` keeps of a linked program: the driver's program
/// binary, written to `dir/<name>.bin`, and the figures read off it. NVIDIA's
/// binary holds the program as readable NV assembly (`!!NVfp5.0`,
/// `!!NVcp5.0`), whose `TEMP lmem0[N]` is the local memory of one invocation
/// in 16-byte slots. Other drivers' binaries are opaque: then only the size.
/// `spirv`: the program was linked from SPIR-V (`--gl-spirv`), whose binary
/// Mesa 22.3 cannot save (its glGetProgramBinary reads the GLSL source that
/// such a program lacks, and crashes): on Mesa it is not asked for.
pub fn dump_binary(
    gl: &glow::Context,
    program: glow::Program,
    spirv: bool,
    dir: &std::path::Path,
    name: &str,
) -> anyhow::Result<twinray_common::report::ShaderStats> {
    // SAFETY: a plain string query on the current context.
    let mesa = unsafe { gl.get_parameter_string(glow::VERSION) }.contains("Mesa");
    let mut statistics = Vec::new();
    let binary = if spirv && mesa {
        statistics.push((
            "program binary bytes".to_string(),
            "0 (Mesa cannot save a SPIR-V program's binary)".to_string(),
        ));
        None
    } else {
        // SAFETY: a linked program of the current context.
        unsafe { gl.get_program_binary(program) }
    };
    if let Some(b) = binary.filter(|b| !b.buffer.is_empty()) {
        twinray_common::report::dump_file(dir, &format!("{name}.bin"), &b.buffer)?;
        statistics.push((
            "program binary bytes".to_string(),
            b.buffer.len().to_string(),
        ));
        if let Some(slots) = nv_local_memory_slots(&b.buffer) {
            statistics.push(("NV lmem0 slots (16 B each)".to_string(), slots.to_string()));
            statistics.push(("local memory bytes".to_string(), (slots * 16).to_string()));
        }
    } else if statistics.is_empty() {
        statistics.push((
            "program binary bytes".to_string(),
            "0 (not offered)".to_string(),
        ));
    }
    Ok(twinray_common::report::ShaderStats {
        pipeline: "program".to_string(),
        stage: name.to_string(),
        statistics,
    })
}

/// The N of the largest `TEMP lmem0[N]` in NV assembly, or 0 for NV assembly
/// that declares none; None where the binary holds no NV assembly.
pub fn nv_local_memory_slots(binary: &[u8]) -> Option<u64> {
    let text = String::from_utf8_lossy(binary);
    if !text.contains("!!NV") {
        return None;
    }
    let slots = text
        .match_indices("lmem0[")
        .filter_map(|(i, m)| {
            let rest = &text[i + m.len()..];
            rest[..rest.find(']')?].trim().parse::<u64>().ok()
        })
        .max()
        .unwrap_or(0);
    Some(slots)
}

impl<'gl> Program<'gl> {
    /// The linked tracer program (the SPIR-V stage's program on `--gl-spirv`).
    pub fn raw(&self) -> glow::Program {
        self.raw
    }

    pub fn new(
        gl: &'gl glow::Context,
        vertex: &str,
        fragment: &str,
    ) -> anyhow::Result<Program<'gl>> {
        // SAFETY: objects are created and deleted on the current context; the
        // shaders are detached and deleted once linked (the linked program no longer needs them).
        unsafe {
            let raw = gl
                .create_program()
                .map_err(|e| anyhow!(e))
                .context("glCreateProgram")?;
            let program = Program {
                gl,
                raw,
                pipeline: None,
            };
            let vs = compile(gl, glow::VERTEX_SHADER, vertex, "vertex")?;
            let fs = match compile(gl, glow::FRAGMENT_SHADER, fragment, "fragment") {
                Ok(fs) => fs,
                Err(e) => {
                    gl.delete_shader(vs);
                    return Err(e);
                }
            };
            link(gl, raw, &[vs, fs], "tracer")?;
            explain::numbered(
                8,
                "glCreateShader x2 + glCompileShader + glCreateProgram + glLinkProgram",
                || {
                    format!(
                    "vertex {} bytes, fragment {} bytes of naga's GLSL; the driver compiles here, no pipeline state",
                    vertex.len(),
                    fragment.len()
                )
                },
            );
            Ok(program)
        }
    }

    /// The tracer as SPIR-V (already adapted by `shader::spirv_for_opengl`) in a
    /// separable program, behind naga's GLSL vertex shader in a second one, joined
    /// by a program pipeline. Only the fragment shader (the whole tracer) needs to
    /// be the very binary Vulkan runs; NVIDIA's GL draws nothing with naga's SPIR-V
    /// vertex shader (its VertexIndex input is declared `uint`, and gl_Position is
    /// not in a gl_PerVertex block), so the trivial vertex stage stays GLSL.
    /// glow wraps none of the entry points needed here, so they are looked up.
    pub fn from_spirv(
        gl: &'gl glow::Context,
        proc_address: &dyn Fn(&std::ffi::CStr) -> *const std::ffi::c_void,
        vertex_glsl: &str,
        fragment: &[u32],
    ) -> anyhow::Result<Program<'gl>> {
        let fns = PipelineFns::load(proc_address)?;
        // Separable programs must redeclare the built-in output block they write.
        let vertex_glsl =
            vertex_glsl.replacen('\n', "\nout gl_PerVertex { vec4 gl_Position; };\n", 1);
        // SAFETY: objects are created and used on the current context; the word
        // slice outlives the calls; the entry point name is NUL-terminated.
        unsafe {
            let raw = gl
                .create_program()
                .map_err(|e| anyhow!(e))
                .context("glCreateProgram")?;
            let mut program = Program {
                gl,
                raw,
                pipeline: None,
            };
            let vertex = gl
                .create_program()
                .map_err(|e| anyhow!(e))
                .context("glCreateProgram")?;
            let mut pipeline = 0u32;
            (fns.gen_program_pipelines)(1, &mut pipeline);
            program.pipeline = Some(SeparablePipeline {
                fns,
                pipeline,
                vertex,
            });

            let fs = compile_spirv(
                gl,
                proc_address,
                glow::FRAGMENT_SHADER,
                fragment,
                "fragment",
            )?;
            (fns.program_parameteri)(raw.0.get(), glow::PROGRAM_SEPARABLE, 1);
            link(gl, raw, &[fs], "SPIR-V fragment")?;
            let vs = compile(gl, glow::VERTEX_SHADER, &vertex_glsl, "vertex")?;
            (fns.program_parameteri)(vertex.0.get(), glow::PROGRAM_SEPARABLE, 1);
            link(gl, vertex, &[vs], "GLSL vertex")?;
            (fns.use_program_stages)(pipeline, glow::VERTEX_SHADER_BIT, vertex.0.get());
            (fns.use_program_stages)(pipeline, glow::FRAGMENT_SHADER_BIT, raw.0.get());
            Ok(program)
        }
    }

    /// Makes this program and `vao` the draw state; nothing else changes it.
    pub fn bind(&self, vao: &EmptyVertexArray) {
        // SAFETY: both objects are alive and belong to the current context.
        unsafe {
            match &self.pipeline {
                Some(p) => {
                    self.gl.use_program(None);
                    (p.fns.bind_program_pipeline)(p.pipeline);
                }
                None => self.gl.use_program(Some(self.raw)),
            }
            self.gl.bind_vertex_array(Some(vao.raw));
        }
    }
}

/// # Safety
/// Needs a current context.
pub(crate) unsafe fn compile(
    gl: &glow::Context,
    stage: u32,
    source: &str,
    name: &str,
) -> anyhow::Result<glow::Shader> {
    // SAFETY: forwarded from the caller.
    unsafe {
        let s = gl
            .create_shader(stage)
            .map_err(|e| anyhow!(e))
            .with_context(|| format!("glCreateShader({name})"))?;
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
        // SAFETY: the objects were created on this context, which outlives them.
        unsafe {
            if let Some(p) = &self.pipeline {
                (p.fns.bind_program_pipeline)(0);
                (p.fns.delete_program_pipelines)(1, &p.pipeline);
                self.gl.delete_program(p.vertex);
            }
            self.gl.delete_program(self.raw)
        }
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
        let raw = unsafe { gl.create_vertex_array() }
            .map_err(|e| anyhow!(e).context("glGenVertexArrays"))?;
        explain::numbered(8, "glGenVertexArrays (empty VAO)", || {
            "the core profile draws nothing without one bound".into()
        });
        Ok(EmptyVertexArray { gl, raw })
    }
}

impl Drop for EmptyVertexArray<'_> {
    fn drop(&mut self) {
        // SAFETY: object of this context, which outlives it.
        unsafe { self.gl.delete_vertex_array(self.raw) }
    }
}
