//! `twinray render --api reference --unsettled MASK.png`: besides the image,
//! the mask of the pixels f32 cannot settle (common's `reference::unsettled`),
//! for `twinray diff --exclude`.

use crate::apps::{self, Api};
use std::path::Path;
use twinray_common::cli::RenderArgs;
use twinray_common::error::bad_input;
use twinray_common::reference::image_io::{check_output_file, write_png};
use twinray_common::reference::unsettled::{mask_image, unsettled};
use twinray_common::scene::Scene;

/// `twinray render` (`truth`: the reference's f64 truth), and with `mask`
/// (reference only) the mask written there too.
pub fn render(api: Api, args: &RenderArgs, truth: bool, mask: Option<&Path>) -> anyhow::Result<()> {
    let Some(mask) = mask else {
        return apps::render(api, args, truth);
    };
    // Said before anything renders.
    if api != Api::Reference {
        return Err(bad_input(
            "--unsettled is the f64 reference's: use it with --api reference",
        ));
    }
    // That it is neither --out nor an input, `main` has checked with every command's outputs.
    check_output_file("--unsettled", mask)?;
    apps::render(api, args, truth)?;
    let scene = Scene::load(&args.scene, &args.overrides()?)?;
    let (w, h) = (args.size.width, args.size.height);
    write_png(
        &mask_image(&unsettled(&scene, w, h), w, h),
        "--unsettled",
        mask,
    )
}
