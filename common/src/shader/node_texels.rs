//! OpenGL's reads of the wide tree's nodes through a buffer texture: the pass
//! over naga's GLSL that turns each read of the node storage block into
//! `texelFetch` on a `samplerBuffer` over the same buffer (`Api::node_texels`
//! says where; gl/src/buffers.rs makes the texture). naga's IR has no buffer
//! textures, so the reads are rewritten in its output, as the warp probe is
//! added to it (`post::warp_probe_glsl`).
//!
//! naga writes two forms of node read, and the pass knows both:
//! - one bounds plane, `BLOCK.nodes[N].bounds[K]`, a `vec4`;
//! - a whole node, `BvhWideNode X = BLOCK.nodes[N];`, whose children it then
//!   takes (`X.child`).
//!
//! Any other mention of the block is refused, as is a shader without a node
//! read: a naga that writes the reads differently fails here, not on a GPU.

use crate::gpu::layout::{binding, WIDE_NODE_TEXELS};
use anyhow::{anyhow, bail};
use naga::ShaderStage;

/// The sampler's name in the rewritten GLSL.
const SAMPLER: &str = "node_texels";

/// naga's name for the node block's instance in a `stage` shader.
fn block(stage: ShaderStage) -> String {
    let suffix = match stage {
        ShaderStage::Compute => "cs",
        ShaderStage::Fragment => "fs",
        _ => "vs",
    };
    format!("_group_0_binding_{}_{suffix}", binding::BVH_NODES)
}

/// The `stage` GLSL with every node read a texel fetch, and the sampler
/// declared at texture unit `binding::BVH_NODES` (GL's texture units are a
/// space of their own, so the number is the node buffer's binding).
pub fn node_texels_glsl(glsl: &str, stage: ShaderStage) -> anyhow::Result<String> {
    let block = block(stage);
    let reads = format!("{block}.nodes[");
    let mut out = String::with_capacity(glsl.len() + 4096);
    let mut rewritten = 0;
    for line in glsl.lines() {
        if line.contains(&block) && !line.contains(&reads) && !line.starts_with('}') {
            bail!("node texels: naga's GLSL names the node block in a form the pass does not know: `{}`", line.trim());
        }
        let mut rest = line;
        while let Some(k) = rest.find(&reads) {
            let (before, after) = (&rest[..k], &rest[k + reads.len()..]);
            let (node, after) = bracketed(after)?;
            if let Some(after) = after.strip_prefix(".bounds[") {
                let (plane, after) = bracketed(after)?;
                out.push_str(before);
                out.push_str(&fetch(node, plane));
                rest = after;
            } else {
                out.push_str(&whole_node(before, node, after)?);
                rest = "";
            }
            rewritten += 1;
        }
        out.push_str(rest);
        out.push('\n');
    }
    if rewritten == 0 {
        bail!("node texels: naga's GLSL has no read of {reads}...]");
    }
    // After the #version and #extension lines, before the first declaration
    // that uses a binding.
    let at = out
        .find("layout(")
        .ok_or_else(|| anyhow!("node texels: the GLSL declares no resource"))?;
    out.insert_str(
        at,
        &format!(
            "layout(binding = {}) uniform highp samplerBuffer {SAMPLER};\n",
            binding::BVH_NODES
        ),
    );
    Ok(out)
}

/// The text up to the `]` that closes the one before it, and the text after.
fn bracketed(s: &str) -> anyhow::Result<(&str, &str)> {
    let mut depth = 0u32;
    for (i, c) in s.char_indices() {
        match c {
            '[' => depth += 1,
            ']' if depth == 0 => return Ok((&s[..i], &s[i + 1..])),
            ']' => depth -= 1,
            _ => {}
        }
    }
    bail!("node texels: an unclosed `[` in naga's GLSL: `{s}`")
}

/// Texel `texel` of node `node`, as a `vec4`.
fn fetch(node: &str, texel: &str) -> String {
    format!("texelFetch({SAMPLER}, int(({node}) * {WIDE_NODE_TEXELS}u + ({texel})))")
}

/// `BvhWideNode X = BLOCK.nodes[N];` built from its texels: the six bounds
/// planes, then the children's references as the last texel's bits. A
/// driver drops the fetches of what the shader never reads.
fn whole_node(before: &str, node: &str, after: &str) -> anyhow::Result<String> {
    let name = before
        .trim()
        .strip_prefix("BvhWideNode ")
        .and_then(|s| s.strip_suffix('='))
        .map(str::trim)
        .filter(|_| after.trim() == ";")
        .ok_or_else(|| {
            anyhow!(
                "node texels: a node read of a form the pass does not know: `{}`",
                before.trim()
            )
        })?;
    let planes = WIDE_NODE_TEXELS - 1;
    let bounds: Vec<String> = (0..planes).map(|k| fetch(node, &format!("{k}u"))).collect();
    let indent = &before[..before.len() - before.trim_start().len()];
    Ok(format!(
        "{indent}BvhWideNode {name} = BvhWideNode(vec4[{planes}]({}), floatBitsToUint({}));",
        bounds.join(", "),
        fetch(node, &format!("{planes}u"))
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shader(body: &str) -> String {
        format!(
            "#version 450 core\nlayout(std430, binding = 6) restrict readonly buffer B {{\n    BvhWideNode nodes[];\n}} {};\n\nvoid main() {{\n{body}}}\n",
            block(ShaderStage::Compute)
        )
    }

    #[test]
    fn every_node_read_becomes_a_texel_fetch() {
        let b = block(ShaderStage::Compute);
        let glsl = shader(&format!(
            "    vec4 _e1 = {b}.nodes[_e2].bounds[_e3.x];\n    BvhWideNode _e4 = {b}.nodes[(_e5 + 1u)];\n"
        ));
        let out = node_texels_glsl(&glsl, ShaderStage::Compute).unwrap();
        assert!(!out.contains(&format!("{b}.nodes[")), "{out}");
        assert!(out.contains("vec4 _e1 = texelFetch(node_texels, int((_e2) * 7u + (_e3.x)));"));
        assert!(out.contains("BvhWideNode _e4 = BvhWideNode(vec4[6](texelFetch(node_texels, int(((_e5 + 1u)) * 7u + (0u))),"));
        assert!(out
            .contains("floatBitsToUint(texelFetch(node_texels, int(((_e5 + 1u)) * 7u + (6u)))));"));
        let decl = out
            .find("uniform highp samplerBuffer node_texels;")
            .unwrap();
        assert!(decl > out.find("#version").unwrap() && decl < out.find("buffer B").unwrap());
        assert!(out.starts_with("#version 450 core\nlayout(binding = 6) uniform"));
    }

    #[test]
    fn a_read_the_pass_does_not_know_is_refused() {
        let b = block(ShaderStage::Compute);
        for body in [
            format!("    uvec4 c = {b}.nodes[_e2].child;\n"),
            format!("    uint n = uint({b}.nodes.length());\n"),
            String::new(),
        ] {
            let err = node_texels_glsl(&shader(&body), ShaderStage::Compute)
                .unwrap_err()
                .to_string();
            assert!(err.starts_with("node texels:"), "{err}");
        }
    }
}
