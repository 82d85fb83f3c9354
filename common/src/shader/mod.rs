//! The shader: which variant a run compiles (`variant`, the single decider),
//! the naga build of that variant into SPIR-V and GLSL (`build`), and the
//! passes over naga's output (`post`, and OpenGL's node reads through a buffer
//! texture, `node_texels`).

pub mod build;
pub mod node_texels;
pub mod post;
pub mod variant;
