//! Options with values the apps refuse: sizes, scene overrides past a limit,
//! and the compute path's options.

use crate::common::expect_both;
use twinray_tests::{fail, App};

#[test]
fn bad_sizes() {
    // clap prints its own usage error naming the option; the exit code is 2.
    for app in App::BOTH {
        let (code, stderr) = fail(&app.exe(), &["--headless", "--size", "0x10"], &[]);
        assert_eq!(code, 2, "{stderr}");
        assert!(
            stderr.contains("--size") && stderr.contains("zero"),
            "{stderr}"
        );
    }
    expect_both(
        &["--headless", "--size", "20000x16"],
        &[],
        2,
        &["--size 20000x16", "limit"],
    );
}

#[test]
fn too_many_primitives_for_the_storage_buffer_limit() {
    // Above Mesa's 128 MiB limit (and most GPUs' 2^27..2^32): 5 million
    // spheres in brute force's 32-byte spheres (160 MB), refused as the scene
    // is read; 3.5 million fit there (112 MB), but not in the BVH's 48-byte
    // leaf primitives (168 MB), refused once the tree is built.
    for (accel, count, buffer, remedy) in [
        (
            "none",
            "extra_spheres=5000000",
            "spheres",
            "fewer primitives",
        ),
        (
            "bvh",
            "extra_spheres=3500000",
            "BVH primitive",
            "--accel none",
        ),
    ] {
        expect_both(
            &[
                "--headless",
                "--size",
                "16x16",
                "--scene",
                "spherelist",
                "--set",
                count,
                "--accel",
                accel,
            ],
            &[],
            2,
            &[buffer, "limit", remedy],
        );
    }
}

/// A tessellation past the device's storage limit is refused before a single
/// patch is tessellated: 10.2 million triangles (980 MB) against Mesa's 128 MiB,
/// in a fraction of a second (it took 15.9 s and 3.7 GB when the limit was
/// checked after the tessellation and the BVH).
#[test]
fn a_tessellation_past_the_device_limit_is_refused_before_the_work() {
    let start = std::time::Instant::now();
    expect_both(
        &[
            "--headless",
            "--size",
            "8x8",
            "--scene",
            "teapot",
            "--set",
            "tessellation=400x400",
        ],
        &[],
        2,
        &["--set tessellation", "triangles buffer", "limit"],
    );
    let secs = start.elapsed().as_secs_f64();
    // Generous for a loaded 2-core machine; tessellating first takes minutes here.
    assert!(secs < 30.0, "both apps took {secs:.1} s to refuse");
}

#[test]
fn unknown_override_key() {
    expect_both(&["--headless", "--set", "warp=9"], &[], 2, &["warp"]);
}

#[test]
fn bad_path_and_workgroup_options() {
    // A workgroup means nothing to the fragment path: said, not ignored.
    expect_both(
        &["--headless", "--size", "16x16", "--workgroup", "8x8"],
        &[],
        2,
        &["--workgroup", "--path compute"],
    );
    for app in App::BOTH {
        for args in [
            ["--path", "warp"],
            ["--workgroup", "0x8"],
            ["--workgroup", "64x64"],
        ] {
            let mut all = vec!["--headless", "--size", "16x16", "--path", "compute"];
            all.extend(args);
            let (code, stderr) = fail(&app.exe(), &all, &[]);
            assert_eq!(code, 2, "{args:?}: {stderr}");
            assert!(stderr.contains(args[0]), "{args:?}: {stderr}");
        }
    }
}

#[test]
fn dump_shaders_to_a_place_that_takes_no_folder() {
    let dir = twinray_tests::scratch("dump-shaders");
    let file = dir.join("a-file");
    std::fs::write(&file, "not a folder").unwrap();
    for place in [file.to_str().unwrap(), "/proc/twinray-shaders"] {
        expect_both(
            &["--headless", "--size", "16x16", "--dump-shaders", place],
            &[],
            2,
            &["--dump-shaders", place],
        );
    }
}

#[test]
fn an_output_name_of_255_bytes_is_written() {
    // Its temporary name would be longer than 255 bytes; it must still be written.
    let dir = twinray_tests::scratch("out-255");
    for (app, name) in App::BOTH.into_iter().zip(["v", "g"]) {
        let out = dir.join(format!("{name}{}.png", "a".repeat(250)));
        twinray_tests::run_ok(
            &app.exe(),
            &[
                "--headless",
                "--size",
                "16x16",
                "--out",
                out.to_str().unwrap(),
            ],
            &[],
        );
        assert!(out.is_file(), "{app:?}");
    }
    let mut left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    left.sort();
    assert_eq!(left.len(), 2, "{left:?}");
}

#[test]
fn experiments_that_exclude_each_other_are_named_as_a_pair() {
    // Both accepted alone; together naga refused a macro the user never wrote
    // (`Unknown variable: BVH_STACK_DECLARE`), exit 1.
    for (a, b) in twinray_common::lab::EXCLUSIVE.iter().map(|(a, b, _)| {
        use twinray_common::value_name::ValueName;
        (a.name(), b.name())
    }) {
        expect_both(
            &[
                "--headless",
                "--size",
                "16x16",
                "--scene",
                "teapot",
                "--path",
                "compute",
                "--accel",
                "bvh",
                "--experiment",
                &a,
                "--experiment",
                &b,
            ],
            &[],
            2,
            &[
                &format!("--experiment {a} with --experiment {b}"),
                "drop one",
            ],
        );
    }
}
