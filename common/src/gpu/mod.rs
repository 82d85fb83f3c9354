//! What the GPU receives, shared byte for byte by both apps: the buffer
//! layouts (`layout`, the bottom layer, which imports nothing of this crate)
//! and the conversion of a scene into those bytes (`upload`).

pub mod layout;
pub mod upload;
