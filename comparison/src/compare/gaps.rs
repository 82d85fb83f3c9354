//! The points where the why step measures a Vulkan/OpenGL gap (why.rs's
//! `CASES` names the experiments run at each): scene, values, frame, tree,
//! path, and what the gap is a gap in; and the empty frame `Hold::Floor`
//! traces beside them.

use crate::compare::runs::{Gap, GapFrame, GapMeasure};
use twinray_common::cli::RenderPath;
use twinray_common::scene::accel::Accel;

pub(crate) const BOX_FRAGMENT: Gap = Gap {
    name: "box brute fragment",
    scene: "box",
    set: &[],
    frame: GapFrame::Square,
    accel: Accel::None,
    path: RenderPath::Fragment,
    measure: GapMeasure::Ratio,
};
pub(crate) const BOX_COMPUTE: Gap = Gap {
    name: "box brute compute",
    scene: "box",
    set: &[],
    frame: GapFrame::Square,
    accel: Accel::None,
    path: RenderPath::Compute,
    measure: GapMeasure::Ratio,
};
pub(crate) const TEAPOT_FRAGMENT: Gap = Gap {
    name: "teapot brute fragment",
    scene: "teapot",
    set: &[],
    frame: GapFrame::Square,
    accel: Accel::None,
    path: RenderPath::Fragment,
    measure: GapMeasure::Ratio,
};
/// Through the tree every user gets (`--accel auto`: the 4-wide one).
pub(crate) const TEAPOT_BVH_COMPUTE: Gap = Gap {
    name: "teapot BVH compute",
    scene: "teapot",
    set: &[],
    frame: GapFrame::Square,
    accel: Accel::Auto,
    path: RenderPath::Compute,
    measure: GapMeasure::Ratio,
};
/// The sphere list at its largest: the deepest tree of the study's scenes.
pub(crate) const SPHERELIST_BVH_COMPUTE: Gap = Gap {
    name: "sphere list BVH compute",
    scene: "spherelist",
    set: &["extra_spheres=100000"],
    frame: GapFrame::Large,
    accel: Accel::Auto,
    path: RenderPath::Compute,
    measure: GapMeasure::Ratio,
};
/// The sphere list at its largest in a frame of one wave (300² in the full
/// preset: 2,850 one-warp workgroups in OpenGL), where each API's fixed
/// cost of a dispatch is a tenth of the frame or more.
pub(crate) const SPHERELIST_BVH_SMALL: Gap = Gap {
    name: "sphere list BVH compute small frame",
    scene: "spherelist",
    set: &["extra_spheres=100000"],
    frame: GapFrame::Small,
    accel: Accel::Auto,
    path: RenderPath::Compute,
    measure: GapMeasure::Ratio,
};
pub(crate) const BOX_IMAGES: Gap = Gap {
    name: "box image agreement",
    scene: "box",
    set: &[],
    frame: GapFrame::Square,
    accel: Accel::None,
    path: RenderPath::Fragment,
    measure: GapMeasure::Agreement,
};

/// `Hold::Floor`'s scene, written beside the why step's images.
pub(crate) const FLOOR_SCENE: &str = include_str!("../../plans/scenes/spherelist-missed.toml");
pub(crate) const FLOOR_FILE: &str = "spherelist-missed.toml";
