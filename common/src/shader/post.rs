//! Passes over naga's output: they take out what naga adds on its own (the
//! zero initialisers of function-local arrays) and make the Vulkan SPIR-V
//! loadable by OpenGL (GL_ARB_gl_spirv).

// naga zero-initialises every function-local variable it writes, in both back
// ends: an `OpConstantNull` initialiser in SPIR-V, `T a[N] = T[N](0, ...)` in
// GLSL. For a scalar the driver drops the dead store; for an array it cannot
// prove every element is written before it is read, so it stores N zeros at
// every call: the tracer's ray stack at every pixel and the BVH stack at every
// traversal (128 stores into NVIDIA's local memory per traversal, 1.2-1.85x the
// BVH time on an H100). trace.glsl only reads stack entries below the stack
// pointer, each written by a push first, so the zeros are never read: both
// passes remove the initialisers of function-local arrays, and only those.
// trace.glsl gives no array an explicit initialiser (a test holds it to that),
// so every initialiser removed here is naga's.

/// Removes the `OpConstantNull` initialiser of every `Function`-storage
/// `OpVariable` whose type is an array.
pub fn strip_local_array_zero_init_spirv(words: &[u32]) -> Vec<u32> {
    const OP_TYPE_ARRAY: u32 = 28;
    const OP_TYPE_POINTER: u32 = 32;
    const OP_CONSTANT_NULL: u32 = 46;
    const OP_VARIABLE: u32 = 59;
    const STORAGE_FUNCTION: u32 = 7;
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
                && i[2] == STORAGE_FUNCTION
                && arrays.contains(&i[3])
        })
        .map(|i| i[1])
        .collect();
    let mut out = words[..5.min(words.len())].to_vec();
    for i in instructions() {
        let strip = i[0] & 0xffff == OP_VARIABLE
            && i.len() == 5
            && i[3] == STORAGE_FUNCTION
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
fn spirv_instructions(words: &[u32]) -> impl Iterator<Item = &[u32]> {
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

/// Removes naga's zero initialiser from every function-local array declaration
/// (`    T name[N] = T[N](zeros);` becomes `    T name[N];`). Only initialisers
/// made of zero literals and constructors are touched.
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

/// For an indented `T name[N] = T[N](...);` line whose initialiser holds only
/// zeros, the declaration part `    T name[N]`.
fn local_array_zero_init(line: &str) -> Option<&str> {
    let body = line.trim_end();
    if !line.starts_with(' ') || !body.ends_with(");") {
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

/// naga's Vulkan SPIR-V made loadable by OpenGL (GL_ARB_gl_spirv), so both APIs
/// can run the very same binary: GL has no descriptor sets, so the
/// `DescriptorSet` decorations go, and GL's window origin is the lower left, so
/// `OriginUpperLeft` becomes `OriginLowerLeft` (with glReadPixels' bottom-up rows
/// this gives the same upright image as the GLSL path). Nothing else changes.
pub fn spirv_for_opengl(words: &[u32]) -> Vec<u32> {
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
