//! Each app's own knobs (options that can also come from `TWINRAY_*`
//! variables) and the orchestrator's: a bad value is named with where it came
//! from, and a knob of one app never stops the other.

use crate::common::expect_one;
use twinray_tests::{bin, scratch};

#[test]
fn gl_spirv_is_an_opengl_option_and_the_vulkan_knobs_are_checked() {
    expect_one(
        &bin("twinray-vk"),
        &["--headless", "--gl-spirv"],
        &[],
        2,
        &["--gl-spirv", "OpenGL"],
    );
    expect_one(
        &bin("twinray-vk"),
        &["--headless"],
        &[("TWINRAY_VK_MEMORY", "vram")],
        2,
        &["TWINRAY_VK_MEMORY", "'vram'"],
    );
    expect_one(
        &bin("twinray-vk"),
        &["--headless"],
        &[("TWINRAY_VK_WAIT", "spin")],
        2,
        &["TWINRAY_VK_WAIT", "'spin'"],
    );
}

/// Each app's knobs are options that can also come from `TWINRAY_*`
/// variables: a bad value names the variable (or the option) it came from, and
/// exits 2 before any work.
#[test]
fn each_knob_names_its_variable_or_option_and_the_bad_value() {
    let vk = bin("twinray-vk");
    let gl = bin("twinray-gl");
    let small = ["--headless", "--size", "16x12"];
    for (exe, variable, option, bad) in [
        (&vk, "TWINRAY_VK_DEVICE", "--vk-device", "no-such-gpu"),
        (&vk, "TWINRAY_VK_MEMORY", "--vk-memory", "vram"),
        (&vk, "TWINRAY_VK_VALIDATION", "--vk-validation", "maybe"),
        (&vk, "TWINRAY_VK_WAIT", "--vk-wait", "spin"),
        (&vk, "TWINRAY_VK_SYNC2", "--vk-sync2", "maybe"),
        (&gl, "TWINRAY_GL_DEVICE", "--gl-device", "x"),
    ] {
        let quoted = format!("'{bad}'");
        expect_one(exe, &small, &[(variable, bad)], 2, &[variable, &quoted]);
        let on_the_command_line = format!("{option}={bad}");
        let mut args = small.to_vec();
        args.push(&on_the_command_line);
        expect_one(exe, &args, &[], 2, &[option, &quoted]);
    }
    // A device index the machine does not have is found only once the devices are listed.
    expect_one(
        &gl,
        &small,
        &[("TWINRAY_GL_DEVICE", "99")],
        2,
        &["TWINRAY_GL_DEVICE", "99"],
    );
    expect_one(
        &vk,
        &small,
        &[("TWINRAY_VK_DEVICE", "99")],
        2,
        &["TWINRAY_VK_DEVICE", "'99'"],
    );

    // The orchestrator's one knob: where the apps are.
    let tw = bin("twinray");
    let render = ["render", "--api", "vulkan", "--size", "16x12"];
    let nowhere = "/no/such/folder";
    expect_one(
        &tw,
        &render,
        &[("TWINRAY_BIN_DIR", nowhere)],
        2,
        &["TWINRAY_BIN_DIR", nowhere],
    );
    let empty = scratch("empty-bin-dir");
    let empty = empty.to_str().unwrap();
    expect_one(
        &tw,
        &render,
        &[("TWINRAY_BIN_DIR", empty)],
        2,
        &["TWINRAY_BIN_DIR", empty, "twinray-vk"],
    );
}

/// A knob belongs to one app: a Vulkan knob set for a whole comparison, even a
/// bad one, does not stop the OpenGL app, and the other way round.
#[test]
fn an_app_ignores_the_other_apps_knobs() {
    let small = ["--headless", "--size", "8x6"];
    let o = twinray_tests::run(&bin("twinray-gl"), &small, &[("TWINRAY_VK_MEMORY", "vram")]);
    assert!(
        o.status.success(),
        "twinray-gl read TWINRAY_VK_MEMORY: {o:?}"
    );
    let o = twinray_tests::run(&bin("twinray-vk"), &small, &[("TWINRAY_GL_DEVICE", "x")]);
    assert!(
        o.status.success(),
        "twinray-vk read TWINRAY_GL_DEVICE: {o:?}"
    );
}
