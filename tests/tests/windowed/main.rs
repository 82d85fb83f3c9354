//! Windowed mode under Xvfb (lavapipe + llvmpipe): both apps open a window,
//! render, survive resizes and minimize/restore, run every key's action, and
//! exit cleanly with zero validation messages and zero GL errors. Also
//! `--explain`, that a windowed `--out` equals the headless image, and that
//! real mouse input (xdotool through XTEST) orbits and zooms the camera.
//! The compute path in the window: `--path compute`, the live switch `C`
//! (the title says which path runs), a resize storm with scene and path
//! switches, every screenshot equal to the headless image of its path, all
//! under the validation layer's synchronisation validation too.
//! One test binary, one module per topic.

mod common;
mod compute;
mod fragment;
mod mouse;
mod no_window;
mod switches;
