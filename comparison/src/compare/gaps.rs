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
/// The same at the preset's large frame (1080p in the full preset), where
/// users measure rays per second: a lone frame's end weighs less than at
/// 1000², Vulkan's workgroup as much.
pub(crate) const TEAPOT_BVH_LARGE: Gap = Gap {
    name: "teapot BVH compute large frame",
    scene: "teapot",
    set: &[],
    frame: GapFrame::Large,
    accel: Accel::Auto,
    path: RenderPath::Compute,
    measure: GapMeasure::Ratio,
};
/// The same at the preset's largest frame (4K in the full preset), where the
/// frame's end weighs least.
pub(crate) const TEAPOT_BVH_LARGEST: Gap = Gap {
    name: "teapot BVH compute largest frame",
    scene: "teapot",
    set: &[],
    frame: GapFrame::Largest,
    accel: Accel::Auto,
    path: RenderPath::Compute,
    measure: GapMeasure::Ratio,
};
/// The box through the tree `auto` gives it (4-wide, 32 primitives): a frame
/// of a tenth of a millisecond at 1000², where a lone dispatch's start and
/// end weigh most.
pub(crate) const BOX_BVH_COMPUTE: Gap = Gap {
    name: "box BVH compute",
    scene: "box",
    set: &[],
    frame: GapFrame::Square,
    accel: Accel::Auto,
    path: RenderPath::Compute,
    measure: GapMeasure::Ratio,
};
/// The same at the preset's large frame (1080p in the full preset): the
/// frame whose tiles that see nothing (`plan::launch`) shortened Vulkan's
/// frame at 8x16 more than OpenGL's at 4x8.
pub(crate) const BOX_BVH_LARGE: Gap = Gap {
    name: "box BVH compute large frame",
    scene: "box",
    set: &[],
    frame: GapFrame::Large,
    accel: Accel::Auto,
    path: RenderPath::Compute,
    measure: GapMeasure::Ratio,
};
/// The teapot at 307k triangles, whose 4-wide tree needs a stack of 37
/// entries, deeper than any of the study's scenes: NVIDIA's OpenGL runs its
/// tracer on fewer multiprocessors (110 of an H200's 132).
pub(crate) const TEAPOT_DEEP_BVH_COMPUTE: Gap = Gap {
    name: "teapot 307k BVH compute",
    scene: "teapot",
    set: &["tessellation=80x60"],
    frame: GapFrame::Square,
    accel: Accel::Auto,
    path: RenderPath::Compute,
    measure: GapMeasure::Ratio,
};
/// The teapot at 4.9M triangles, the deepest of the scaling points: a stack
/// of 47 entries, on which NVIDIA's OpenGL runs the tracer on 88 of an
/// H200's 132 multiprocessors.
pub(crate) const TEAPOT_DEEPEST_BVH_COMPUTE: Gap = Gap {
    name: "teapot 4.9M BVH compute",
    scene: "teapot",
    set: &["tessellation=320x240"],
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

/// `Hold::Floor`'s sphere list: its camera, light and kinds of primitive, all
/// behind the camera.
const SPHERELIST_MISSED: &str = include_str!("../../plans/scenes/spherelist-missed.toml");
const TEAPOT: &str = include_str!("../../../scenes/teapot.toml");
const TEAPOT_PATCHES: &str = include_str!("../../../scenes/teapot.bpt");
/// The teapot's camera target, and where its empty frame looks instead:
/// straight up, above everything the scene holds.
const TEAPOT_LOOK_AT: &str = "look_at = [0.2, 1.4, 0.0]";
const TEAPOT_LOOK_UP: &str = "look_at = [0.0, 30.0, 8.6]";

/// The files `Hold::Floor` writes beside the why step's images: each gap
/// scene's empty frame (the same shader variant, tree and size, every primary
/// ray missing), and what it names. The teapot's is the built-in scene with
/// its camera turned up, so it stays the teapot as it ships.
pub(crate) fn floor_files() -> [(&'static str, String); 3] {
    [
        (floor_file("spherelist"), SPHERELIST_MISSED.to_string()),
        (
            floor_file("teapot"),
            TEAPOT.replacen(TEAPOT_LOOK_AT, TEAPOT_LOOK_UP, 1),
        ),
        ("teapot.bpt", TEAPOT_PATCHES.to_string()),
    ]
}

/// `dir` made, with `floor_files` in it.
pub(crate) fn write_floor_files(dir: &std::path::Path) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create '{}': {e}", dir.display()))?;
    floor_files().iter().try_for_each(|(name, text)| {
        std::fs::write(dir.join(name), text)
            .map_err(|e| format!("cannot write '{}': {e}", dir.join(name).display()))
    })
}

/// The empty frame `Hold::Floor` traces for a gap on `scene`.
pub(crate) fn floor_file(scene: &str) -> &'static str {
    match scene {
        "teapot" => "teapot-missed.toml",
        _ => "spherelist-missed.toml",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The teapot's empty frame is the teapot with only its camera's target
    /// moved: if the scene's camera line changed, the replacement would
    /// silently leave the teapot in view.
    #[test]
    fn the_teapots_empty_frame_turns_only_its_camera() {
        let [_, (_, missed), _] = floor_files();
        assert_eq!(TEAPOT.matches(TEAPOT_LOOK_AT).count(), 1);
        assert_eq!(missed.replacen(TEAPOT_LOOK_UP, TEAPOT_LOOK_AT, 1), TEAPOT);
    }
}
