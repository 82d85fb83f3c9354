//! Passes over naga's output: they take out what naga adds on its own (the
//! zero initialisers of function-local arrays) and make the Vulkan SPIR-V
//! loadable by OpenGL (GL_ARB_gl_spirv).

// naga zero-initialises every function-local variable it writes, in both back
// ends: an `OpConstantNull` initialiser in SPIR-V, `T a[N] = T[N](0, ...)` in
// GLSL. For a scalar the driver drops the dead store; for an array it cannot
// prove every element is written before it is read, so it stores N zeros at
// every call: the tracer's ray stack at every pixel and the BVH stack at every
// traversal (stores into NVIDIA's local memory; what they cost:
// docs/findings/shader-compilers.md#what-naga-adds-and-what-the-source-now-says).
// The tracer only reads stack entries below the stack
// pointer, each written by a push first, so the zeros are never read: both
// passes remove the initialisers of per-invocation arrays (function-local, or
// private at module scope), and only those.
// The tracer gives no array an explicit initialiser (a test holds it to that),
// so every initialiser removed here is naga's.

/// Removes the `OpConstantNull` initialiser of every `Function`- or
/// `Private`-storage `OpVariable` whose type is an array (a private array is
/// per invocation too: the module-scope BVH stack both walks share).
pub fn strip_local_array_zero_init_spirv(words: &[u32]) -> Vec<u32> {
    const OP_TYPE_ARRAY: u32 = 28;
    const OP_TYPE_POINTER: u32 = 32;
    const OP_CONSTANT_NULL: u32 = 46;
    const OP_VARIABLE: u32 = 59;
    const STORAGE_PRIVATE: u32 = 6;
    const STORAGE_FUNCTION: u32 = 7;
    let per_invocation = |class: u32| class == STORAGE_FUNCTION || class == STORAGE_PRIVATE;
    let instructions = || spirv_instructions(words);
    let arrays: std::collections::HashSet<u32> = instructions()
        .filter(|i| i[0] & 0xffff == OP_TYPE_ARRAY && i.len() >= 2)
        .map(|i| i[1])
        .collect();
    let nulls: std::collections::HashSet<u32> = instructions()
        .filter(|i| i[0] & 0xffff == OP_CONSTANT_NULL && i.len() >= 3)
        .map(|i| i[2])
        .collect();
    let array_pointers: std::collections::HashSet<u32> = instructions()
        .filter(|i| {
            i[0] & 0xffff == OP_TYPE_POINTER
                && i.len() >= 4
                && per_invocation(i[2])
                && arrays.contains(&i[3])
        })
        .map(|i| i[1])
        .collect();
    let mut out = words[..5.min(words.len())].to_vec();
    for i in instructions() {
        let strip = i[0] & 0xffff == OP_VARIABLE
            && i.len() == 5
            && per_invocation(i[3])
            && array_pointers.contains(&i[1])
            && nulls.contains(&i[4]);
        if strip {
            out.push((4 << 16) | OP_VARIABLE);
            out.extend_from_slice(&i[1..4]);
        } else {
            out.extend_from_slice(i);
        }
    }
    out
}

/// The instructions of a SPIR-V module after its 5-word header; a malformed
/// tail is returned as one last slice so nothing is lost.
pub(crate) fn spirv_instructions(words: &[u32]) -> impl Iterator<Item = &[u32]> {
    let mut i = 5.min(words.len());
    std::iter::from_fn(move || {
        if i >= words.len() {
            return None;
        }
        let count = (words[i] >> 16) as usize;
        let end = if count == 0 || i + count > words.len() {
            words.len()
        } else {
            i + count
        };
        let inst = &words[i..end];
        i = end;
        Some(inst)
    })
}

/// Removes naga's zero initialiser from every function-local or module-scope
/// array declaration (`    T name[N] = T[N](zeros);` becomes `    T name[N];`).
/// Only initialisers made of zero literals and constructors are touched, so a
/// `const` array, whose first word is no type, stays as it is.
pub fn strip_local_array_zero_init_glsl(glsl: &str) -> String {
    let mut out = String::with_capacity(glsl.len());
    for line in glsl.split_inclusive('\n') {
        match local_array_zero_init(line) {
            Some(decl) => {
                out.push_str(decl);
                out.push_str(";\n");
            }
            None => out.push_str(line),
        }
    }
    out
}

/// For a `T name[N] = T[N](...);` line whose initialiser holds only zeros,
/// the declaration part `    T name[N]`.
fn local_array_zero_init(line: &str) -> Option<&str> {
    let body = line.trim_end();
    if !body.ends_with(");") {
        return None;
    }
    let (decl, init) = body.split_once(" = ")?;
    let ty = decl.split_whitespace().next()?;
    let size = &decl[decl.find('[')?..];
    if !decl.ends_with(']') {
        return None;
    }
    let args = init
        .strip_prefix(&format!("{ty}{size}("))?
        .strip_suffix(");")?;
    let zeros_only = args
        .split(|c: char| "(), ".contains(c))
        .filter(|t| !t.is_empty())
        .all(|t| t == ty || t == "false" || is_glsl_type(t) || is_zero_literal(t));
    zeros_only.then_some(decl)
}

fn is_zero_literal(t: &str) -> bool {
    let digits = t.trim_end_matches(['u', 'f']);
    !digits.is_empty() && digits.chars().all(|c| c == '0' || c == '.') && digits.contains('0')
}

fn is_glsl_type(t: &str) -> bool {
    matches!(t, "float" | "int" | "uint" | "bool")
        || ["vec", "ivec", "uvec", "bvec", "mat"].iter().any(|p| {
            t.strip_prefix(p)
                .is_some_and(|n| n.chars().all(|c| c.is_ascii_digit() || c == 'x'))
        })
}

// `--experiment no-contraction`. SPIR-V and GLSL both let a driver contract
// `a * b + c` into one fused multiply-add (one rounding instead of two) unless
// told not to; the two APIs' compilers need not contract the same expressions,
// which is one way the same shader can give different pixels. These passes
// forbid it everywhere, to measure how much of the Vulkan/OpenGL image
// difference it explains and what it costs.

/// Adds a `NoContraction` decoration to the result of every float arithmetic
/// instruction.
pub fn no_contraction_spirv(words: &[u32]) -> Vec<u32> {
    const OP_DECORATE: u32 = 71;
    const DECORATION_NO_CONTRACTION: u32 = 42;
    // OpFNegate, OpFAdd, OpFSub, OpFMul, OpFDiv, OpFRem, OpFMod,
    // OpVectorTimesScalar .. OpDot: all have (type, result, operands...).
    const FLOAT_ARITHMETIC: [u32; 14] = [
        127, 129, 131, 133, 136, 140, 141, 142, 143, 144, 145, 146, 147, 148,
    ];
    let decorations: Vec<u32> = spirv_instructions(words)
        .filter(|inst| FLOAT_ARITHMETIC.contains(&(inst[0] & 0xffff)) && inst.len() >= 3)
        .flat_map(|inst| [(3 << 16) | OP_DECORATE, inst[2], DECORATION_NO_CONTRACTION])
        .collect();
    with_annotations(words, &decorations)
}

/// `words` with `annotations` (whole instructions) added after its last
/// annotation, where SPIR-V's layout puts them: after the debug
/// instructions and the existing decorations, before the first type.
fn with_annotations(words: &[u32], annotations: &[u32]) -> Vec<u32> {
    // The instructions that may precede the end of the annotations.
    const PREAMBLE: [u32; 19] = [
        2, 3, 4, 5, 6, 7, 10, 11, 14, 15, 16, 17, 71, 72, 73, 74, 75, 330, 331,
    ];
    let mut out = words[..5.min(words.len())].to_vec();
    let mut inserted = false;
    for inst in spirv_instructions(words) {
        if !inserted && !PREAMBLE.contains(&(inst[0] & 0xffff)) {
            out.extend_from_slice(annotations);
            inserted = true;
        }
        out.extend_from_slice(inst);
    }
    out
}

/// Marks every initialised float local `precise`, GLSL's way to forbid
/// contraction of the operations that compute it.
pub fn precise_float_locals_glsl(glsl: &str) -> String {
    let mut out = String::with_capacity(glsl.len() + glsl.len() / 8);
    for line in glsl.lines() {
        let body = line.trim_start();
        let indent = &line[..line.len() - body.len()];
        let ty = body.split(' ').next().unwrap_or("");
        let float_type = matches!(ty, "float" | "vec2" | "vec3" | "vec4")
            || (ty.starts_with("mat") && ty[3..].chars().all(|c| c.is_ascii_digit() || c == 'x'));
        if !indent.is_empty() && float_type && body.contains(" = ") {
            out.push_str(indent);
            out.push_str("precise ");
            out.push_str(body);
        } else {
            out.push_str(line);
        }
        out.push('\n');
    }
    out
}

/// `--experiment float-controls`: declares SPV_KHR_float_controls' strict
/// modes for 32-bit floats on every entry point (denormals preserved; signed
/// zero, Inf and NaN preserved), which forbid the driver's fast-math
/// shortcuts that assume none of them occur. Vulkan 1.2 accepts them where
/// the device's float-controls properties say so.
pub fn float_controls_spirv(words: &[u32]) -> Vec<u32> {
    const OP_EXTENSION: u32 = 10;
    const OP_EXT_INST_IMPORT: u32 = 11;
    const OP_MEMORY_MODEL: u32 = 14;
    const OP_ENTRY_POINT: u32 = 15;
    const OP_EXECUTION_MODE: u32 = 16;
    const OP_CAPABILITY: u32 = 17;
    const CAPABILITY_DENORM_PRESERVE: u32 = 4464;
    const CAPABILITY_SIGNED_ZERO_INF_NAN_PRESERVE: u32 = 4466;
    const MODE_DENORM_PRESERVE: u32 = 4459;
    const MODE_SIGNED_ZERO_INF_NAN_PRESERVE: u32 = 4461;
    let instructions: Vec<&[u32]> = spirv_instructions(words).collect();
    let entry_points: Vec<u32> = instructions
        .iter()
        .filter(|inst| inst[0] & 0xffff == OP_ENTRY_POINT && inst.len() >= 3)
        .map(|inst| inst[2])
        .collect();
    let mut name = b"SPV_KHR_float_controls".to_vec();
    name.resize((name.len() / 4 + 1) * 4, 0);
    let mut extension = vec![((1 + name.len() as u32 / 4) << 16) | OP_EXTENSION];
    extension.extend(
        name.chunks_exact(4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
    );
    // The module's layout fixes the places: capabilities first, then
    // extensions, imports, the memory model, entry points, execution modes.
    let mut out = words[..5.min(words.len())].to_vec();
    let (mut capabilities_done, mut modes_done) = (false, false);
    for inst in instructions {
        let op = inst[0] & 0xffff;
        if !capabilities_done && op != OP_CAPABILITY {
            for c in [
                CAPABILITY_DENORM_PRESERVE,
                CAPABILITY_SIGNED_ZERO_INF_NAN_PRESERVE,
            ] {
                out.extend_from_slice(&[(2 << 16) | OP_CAPABILITY, c]);
            }
            out.extend_from_slice(&extension);
            capabilities_done = true;
        }
        let before_modes = [
            OP_CAPABILITY,
            OP_EXTENSION,
            OP_EXT_INST_IMPORT,
            OP_MEMORY_MODEL,
            OP_ENTRY_POINT,
        ];
        if !modes_done && !before_modes.contains(&op) {
            for &e in &entry_points {
                for m in [MODE_DENORM_PRESERVE, MODE_SIGNED_ZERO_INF_NAN_PRESERVE] {
                    out.extend_from_slice(&[(4 << 16) | OP_EXECUTION_MODE, e, m, 32]);
                }
            }
            modes_done = true;
        }
        out.extend_from_slice(inst);
    }
    out
}

// Vulkan's SPIR-V lets a driver assume that no two resources alias unless one
// is decorated `Aliased`; OpenGL assumes the opposite: two buffer variables, or
// a buffer and an image, may name the same memory unless declared `restrict`
// (GLSL) or decorated `Restrict` (SPIR-V for GL_ARB_gl_spirv). naga writes
// neither, so the same shader told Vulkan's compiler more than OpenGL's. The
// apps bind every resource to a buffer or texture of its own, so `restrict` is
// true of each, and with it OpenGL's compiler may treat the tracer's read-only
// buffers as read-only for the whole dispatch, as Vulkan's already does.

/// Declares every buffer block and image of naga's GLSL `restrict`:
/// `layout(...) readonly buffer B {` becomes `layout(...) restrict readonly
/// buffer B {`, and likewise for `uniform image2D`.
pub fn restrict_resources_glsl(glsl: &str) -> String {
    let mut out = String::with_capacity(glsl.len() + 256);
    for line in glsl.split_inclusive('\n') {
        let resource = line.starts_with("layout(")
            && (line.contains(" buffer ") || line.contains(" uniform image"));
        match line.find(") ").filter(|_| resource) {
            Some(close) => {
                out.push_str(&line[..close + 2]);
                out.push_str("restrict ");
                out.push_str(&line[close + 2..]);
            }
            None => out.push_str(line),
        }
    }
    out
}

/// Decorates every storage buffer and image variable `Restrict`: the SPIR-V
/// form of [`restrict_resources_glsl`], for OpenGL's SPIR-V path.
pub fn restrict_resources_spirv(words: &[u32]) -> Vec<u32> {
    const OP_TYPE_IMAGE: u32 = 25;
    const OP_TYPE_POINTER: u32 = 32;
    const OP_VARIABLE: u32 = 59;
    const OP_DECORATE: u32 = 71;
    const DECORATION_RESTRICT: u32 = 19;
    const UNIFORM_CONSTANT: u32 = 0;
    const STORAGE_BUFFER: u32 = 12;
    // naga's storage buffers are `Uniform` variables of a `BufferBlock`
    // struct in SPIR-V 1.0 and `StorageBuffer` ones after; both count, and so
    // does a `Uniform` block, where `Restrict` is true and changes nothing.
    const UNIFORM: u32 = 2;
    let instructions: Vec<&[u32]> = spirv_instructions(words).collect();
    let images: std::collections::HashSet<u32> = instructions
        .iter()
        .filter(|i| i[0] & 0xffff == OP_TYPE_IMAGE && i.len() >= 2)
        .map(|i| i[1])
        .collect();
    let resource_pointers: std::collections::HashSet<u32> = instructions
        .iter()
        .filter(|i| i[0] & 0xffff == OP_TYPE_POINTER && i.len() >= 4)
        .filter(|i| {
            matches!(i[2], STORAGE_BUFFER | UNIFORM)
                || (i[2] == UNIFORM_CONSTANT && images.contains(&i[3]))
        })
        .map(|i| i[1])
        .collect();
    let decorations: Vec<u32> = instructions
        .iter()
        .filter(|i| i[0] & 0xffff == OP_VARIABLE && i.len() >= 4)
        .filter(|i| resource_pointers.contains(&i[1]))
        .flat_map(|i| [(3 << 16) | OP_DECORATE, i[2], DECORATION_RESTRICT])
        .collect();
    with_annotations(words, &decorations)
}

/// `--experiment warp-probe`: OpenGL's compute GLSL with, first thing in
/// `main`, each invocation raising its multiprocessor's word of a buffer at
/// `binding` to its warp's slot + 1 (GL_NV_shader_thread_group), so the
/// buffer ends up holding each multiprocessor's highest resident warp slot.
pub fn warp_probe_glsl(glsl: &str, binding: u32) -> anyhow::Result<String> {
    let version_end = glsl
        .find('\n')
        .filter(|_| glsl.starts_with("#version"))
        .ok_or_else(|| anyhow::anyhow!("warp probe: the GLSL does not start with #version"))?;
    let main = glsl
        .find("void main() {\n")
        .ok_or_else(|| anyhow::anyhow!("warp probe: the GLSL has no `void main() {{`"))?;
    let body = main + "void main() {\n".len();
    Ok(format!(
        "{}\n#extension GL_NV_shader_thread_group : require\n{}\
         layout(std430, binding = {binding}) buffer WarpProbe {{ uint slots[]; }} warp_probe;\n\n\
         {}    atomicMax(warp_probe.slots[uint(gl_SMIDNV)], uint(gl_WarpIDNV) + 1u);\n{}",
        &glsl[..version_end],
        &glsl[version_end + 1..main],
        &glsl[main..body],
        &glsl[body..]
    ))
}

/// naga's Vulkan SPIR-V made loadable by OpenGL (GL_ARB_gl_spirv), so both APIs
/// can run the very same binary: GL has no descriptor sets, so the
/// `DescriptorSet` decorations go, and GL's window origin is the lower left, so
/// `OriginUpperLeft` becomes `OriginLowerLeft` (with glReadPixels' bottom-up rows
/// this gives the same upright image as the GLSL path). With `restrict`, every
/// resource is also decorated `Restrict` ([`restrict_resources_spirv`]), as
/// the GLSL path declares them. Nothing else changes.
pub fn spirv_for_opengl(words: &[u32], restrict: bool) -> Vec<u32> {
    let words = if restrict {
        &restrict_resources_spirv(words)
    } else {
        words
    };
    const OP_EXECUTION_MODE: u32 = 16;
    const OP_DECORATE: u32 = 71;
    const DECORATION_DESCRIPTOR_SET: u32 = 34;
    const ORIGIN_UPPER_LEFT: u32 = 7;
    const ORIGIN_LOWER_LEFT: u32 = 8;
    let mut out = words[..5.min(words.len())].to_vec();
    let mut i = 5;
    while i < words.len() {
        let count = (words[i] >> 16) as usize;
        let op = words[i] & 0xffff;
        if count == 0 || i + count > words.len() {
            // Malformed; keep the rest untouched and let the driver report it.
            out.extend_from_slice(&words[i..]);
            break;
        }
        let inst = &words[i..i + count];
        if op == OP_DECORATE && count >= 3 && inst[2] == DECORATION_DESCRIPTOR_SET {
            // dropped
        } else if op == OP_EXECUTION_MODE && count >= 3 && inst[2] == ORIGIN_UPPER_LEFT {
            out.extend_from_slice(&[inst[0], inst[1], ORIGIN_LOWER_LEFT]);
            out.extend_from_slice(&inst[3..]);
        } else {
            out.extend_from_slice(inst);
        }
        i += count;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warp_probe_goes_after_version_and_first_in_main() {
        let glsl = "#version 450 core\n#extension GL_ARB_shader_storage_buffer_object : require\nlayout(local_size_x = 16) in;\nvoid main() {\n    uint x = 1u;\n}\n";
        let out = warp_probe_glsl(glsl, 11).unwrap();
        let lines: Vec<&str> = out.lines().collect();
        assert_eq!(lines[0], "#version 450 core");
        assert_eq!(lines[1], "#extension GL_NV_shader_thread_group : require");
        let main = lines.iter().position(|l| *l == "void main() {").unwrap();
        assert!(lines[main + 1]
            .contains("atomicMax(warp_probe.slots[uint(gl_SMIDNV)], uint(gl_WarpIDNV) + 1u)"));
        assert!(out.contains("layout(std430, binding = 11) buffer WarpProbe"));
        assert!(warp_probe_glsl("void main() {\n}\n", 11).is_err());
    }

    #[test]
    fn restrict_marks_every_buffer_and_image_and_nothing_else() {
        let glsl = "layout(std140, binding = 0) uniform Frame_block { Frame f; };\nlayout(std430, binding = 1) readonly buffer Spheres_block {\nlayout(binding = 5,rgba32f) writeonly uniform image2D img;\n    uint buffer_count = 0u;\n";
        let out = restrict_resources_glsl(glsl);
        assert_eq!(
            out,
            "layout(std140, binding = 0) uniform Frame_block { Frame f; };\nlayout(std430, binding = 1) restrict readonly buffer Spheres_block {\nlayout(binding = 5,rgba32f) restrict writeonly uniform image2D img;\n    uint buffer_count = 0u;\n"
        );
    }
}
