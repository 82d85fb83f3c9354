//! `twinray sweep PLAN.toml --out DIR` on Mesa: two builds (two folders of
//! links to the same built apps) × two apps × two option sets × two rounds
//! run in alternating order, one fresh process per run, and sweep.md's
//! medians are the ones sweep.jsonl gives; a bad plan exits 2 naming its
//! line before anything runs; SIGINT keeps the finished runs in both files.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use twinray_tests::{bin, bin_dir, run, scratch};

/// Two build folders, `a` and `b`, each holding links to the built apps.
fn two_builds(dir: &Path) {
    for build in ["a", "b"] {
        let folder = dir.join(build);
        std::fs::create_dir_all(&folder).unwrap();
        for app in ["twinray-vk", "twinray-gl"] {
            std::os::unix::fs::symlink(bin_dir().join(app), folder.join(app)).unwrap();
        }
    }
}

const PLAN: &str = r#"rounds = 2
frames = 3
apps = ["vulkan", "opengl"]
ratios = [["vulkan", "opengl"], ["a", "b"]]

[builds]
a = "a"
b = "b"

[axes]
scene = ["box"]
size = ["32x24"]
path = ["fragment", "compute"]
"#;

fn sweep(dir: &Path, plan: &str) -> std::process::Output {
    let file = dir.join("plan.toml");
    std::fs::write(&file, plan).unwrap();
    let out = dir.join("out");
    run(
        &bin("twinray"),
        &[
            "sweep",
            file.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        &[],
    )
}

/// The median round's median, as sweep.md states it: the lower middle of
/// the rounds' medians.
fn median_round(mut medians: Vec<f64>) -> f64 {
    medians.sort_by(f64::total_cmp);
    medians[(medians.len() - 1) / 2]
}

#[test]
fn two_builds_two_apps_two_sets_two_rounds() {
    let dir = scratch("sweep");
    two_builds(&dir);
    let o = sweep(&dir, PLAN);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    let jsonl = std::fs::read_to_string(dir.join("out/sweep.jsonl")).unwrap();
    let lines: Vec<serde_json::Value> = jsonl
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let cells = 2 * 2 * 2;
    assert_eq!(lines.len(), cells * 2, "{jsonl}");

    // The order: the lines in run order, round 0 forwards, round 1 backwards.
    let mut pids = BTreeSet::new();
    let mut first_cells = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        assert_eq!(line["run"], i, "{line}");
        let round = line["round"].as_u64().unwrap() as usize;
        let order = line["order"].as_u64().unwrap() as usize;
        let cell = line["cell"].as_u64().unwrap() as usize;
        assert_eq!(round, i / cells);
        assert_eq!(order, i % cells);
        let expected = if round % 2 == 0 {
            order
        } else {
            cells - 1 - order
        };
        assert_eq!(cell, expected, "round {round} ran cell {cell} at {order}");
        if order == 0 {
            first_cells.push((line["build"].clone(), line["app"].clone()));
        }
        // One fresh process per run.
        assert!(pids.insert(line["pid"].as_u64().unwrap()), "{line}");
        assert_eq!(line["report"]["api"], line["app"], "{line}");
        assert_eq!(line["report"]["width"], 32);
    }
    // Each round starts with another build and app.
    assert_eq!(
        first_cells,
        [
            (serde_json::json!("a"), serde_json::json!("vulkan")),
            (serde_json::json!("b"), serde_json::json!("opengl"))
        ]
    );
    // Every cell ran once a round.
    let mut per_cell: BTreeMap<(String, String, String), Vec<&serde_json::Value>> = BTreeMap::new();
    for line in &lines {
        let key = |k: &str| line[k].as_str().unwrap().to_string();
        per_cell
            .entry((key("build"), key("app"), key("set")))
            .or_default()
            .push(line);
    }
    assert_eq!(per_cell.len(), cells);

    // The table's medians are the jsonl's, for both clocks.
    let md = std::fs::read_to_string(dir.join("out/sweep.md")).unwrap();
    for ((build, app, set), runs) in &per_cell {
        assert_eq!(runs.len(), 2);
        let row = md
            .lines()
            .find(|l| l.starts_with(&format!("| {build} | {app} | {set} |")))
            .unwrap_or_else(|| panic!("no row for {build} {app} {set} in\n{md}"));
        let columns: Vec<&str> = row.split('|').map(str::trim).collect();
        for (column, clock) in [(5, "gpu_ms"), (6, "wall_ms")] {
            let medians: Vec<f64> = runs
                .iter()
                .filter_map(|r| r["report"][clock]["median"].as_f64())
                .collect();
            let expected = if medians.is_empty() {
                "–".to_string()
            } else {
                format!("{:.3}", median_round(medians))
            };
            let stated = columns[column].split_whitespace().next().unwrap();
            assert_eq!(stated, expected, "{clock} of {row}");
        }
    }
    assert!(md.contains("| vulkan / opengl | build a |"), "{md}");
    assert!(md.contains("| a / b | opengl |"), "{md}");
    assert!(!md.contains("interrupted"), "{md}");
}

/// A bad plan exits 2 with one sentence naming the plan and `line`, and
/// nothing ran: the output folder was not even made.
fn refused(test: &str, plan: &str, line: usize, words: &str) {
    let dir = scratch(test);
    two_builds(&dir);
    let o = sweep(&dir, plan);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(stderr.contains("plan.toml"), "{stderr}");
    assert!(stderr.contains(&format!("line {line}:")), "{stderr}");
    assert!(stderr.contains(words), "{stderr}");
    assert!(!dir.join("out").exists(), "{stderr}");
}

#[test]
fn an_unknown_key_is_refused_at_its_line() {
    let plan = PLAN.replace("frames = 3\n", "frames = 3\nframe_count = 3\n");
    refused("sweep-key", &plan, 3, "unknown field `frame_count`");
}

#[test]
fn a_missing_build_is_refused_at_its_line() {
    let plan = PLAN.replace("b = \"b\"", "b = \"c\"");
    refused("sweep-build", &plan, 8, "not a folder");
    // A folder without an app the plan runs.
    let dir = scratch("sweep-build-app");
    std::fs::create_dir_all(dir.join("c")).unwrap();
    two_builds(&dir);
    std::os::unix::fs::symlink(bin_dir().join("twinray-vk"), dir.join("c/twinray-vk")).unwrap();
    let o = sweep(&dir, &plan);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("line 8:") && stderr.contains("holds no twinray-gl"),
        "{stderr}"
    );
    assert!(!dir.join("out").exists());
}

#[test]
fn an_empty_axis_is_refused_at_its_line() {
    let plan = PLAN.replace("size = [\"32x24\"]", "size = []");
    refused("sweep-axis", &plan, 12, "the axis 'size' is empty");
}

#[test]
fn an_option_an_app_refuses_is_refused_at_its_line() {
    // Unknown to both apps.
    let plan = PLAN.replace("size = [\"32x24\"]", "size = [\"32x24\"]\nsamples = [4]");
    refused("sweep-option", &plan, 13, "unexpected argument '--samples'");
    // A value an app refuses.
    let plan = PLAN.replace("size = [\"32x24\"]", "size = [\"32y24\"]");
    refused("sweep-value", &plan, 12, "twinray-vk refuses");
    // The plan's own settle, at its own line.
    let plan = PLAN.replace("frames = 3\n", "frames = 3\nsettle = 80\n");
    refused("sweep-settle", &plan, 3, "invalid value '80' for '--settle");
    // A Vulkan knob, in an explicit set: OpenGL refuses it.
    let plan = r#"rounds = 1
apps = ["vulkan", "opengl"]
[builds]
a = "a"

[[sets]]
name = "fence"
options = { scene = "box", vk-wait = "fence" }
"#;
    refused(
        "sweep-knob",
        plan,
        6,
        "twinray-gl refuses the option set 'fence'",
    );
}

#[test]
fn sigint_keeps_the_finished_runs_and_marks_both_files() {
    use std::time::{Duration, Instant};
    let dir = scratch("sweep-sigint");
    two_builds(&dir);
    let file = dir.join("plan.toml");
    std::fs::write(&file, PLAN.replace("rounds = 2", "rounds = 50")).unwrap();
    let out = dir.join("out");
    let mut child = std::process::Command::new(bin("twinray"))
        .args([
            "sweep",
            file.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .env(
            "MESA_SHADER_CACHE_DIR",
            std::env::temp_dir().join("twinray-mesa-cache"),
        )
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // Once two runs are on disk, in the middle of the sweep.
    let jsonl = out.join("sweep.jsonl");
    let started = Instant::now();
    while std::fs::read_to_string(&jsonl).map_or(0, |s| s.lines().count()) < 2 {
        assert!(
            started.elapsed() < Duration::from_secs(120),
            "no run finished"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let killed = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        assert!(
            started.elapsed() < Duration::from_secs(180),
            "twinray sweep did not stop"
        );
        std::thread::sleep(Duration::from_millis(20));
    };
    assert_eq!(status.code(), Some(130));
    let text = std::fs::read_to_string(&jsonl).unwrap();
    let lines: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let (mark, runs) = lines.split_last().unwrap();
    assert_eq!(mark["interrupted"], "SIGINT", "{text}");
    assert_eq!(mark["runs"], runs.len(), "{text}");
    assert!(runs.len() >= 2 && runs.len() < 400, "{text}");
    assert!(
        runs.iter().all(|r| r["report"]["api"] == r["app"]),
        "{text}"
    );
    let md = std::fs::read_to_string(out.join("sweep.md")).unwrap();
    assert!(
        md.lines().next().unwrap().contains("interrupted by SIGINT"),
        "{md}"
    );
}

/// sweep.jsonl's lines of one step ("device" or "images").
fn step_lines(dir: &Path, step: &str) -> Vec<serde_json::Value> {
    std::fs::read_to_string(dir.join("out/sweep.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .filter(|l| l["step"] == step)
        .collect()
}

#[test]
fn the_device_side_steps_dump_shaders_and_compare_two_builds_images() {
    let dir = scratch("sweep-steps");
    two_builds(&dir);
    let plan = PLAN
        .replace(
            "rounds = 2",
            "rounds = 1\nshaders = true\nimages = \"builds\"",
        )
        .replace("path = [\"fragment\", \"compute\"]", "path = [\"compute\"]");
    let o = sweep(&dir, &plan);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    // One device-side run per cell, after the timed ones, each with its dump and image.
    let device = step_lines(&dir, "device");
    assert_eq!(device.len(), 4, "{device:?}");
    for line in &device {
        assert_eq!(line["report"]["api"], line["app"], "{line}");
        assert_eq!(
            line["report"]["frames"].as_array().map(Vec::len),
            Some(1),
            "{line}"
        );
        let image = Path::new(line["image"].as_str().unwrap());
        assert!(image.is_file(), "{line}");
    }
    let dumps: Vec<_> = std::fs::read_dir(dir.join("out/shaders"))
        .unwrap()
        .collect();
    assert_eq!(dumps.len(), 4);
    for d in dumps {
        let d = d.unwrap().path();
        assert!(
            std::fs::read_dir(&d).unwrap().count() > 0,
            "{} is empty",
            d.display()
        );
    }
    // Build b against build a: the same binaries, so the same bytes and reports.
    let images = step_lines(&dir, "images");
    assert_eq!(images.len(), 2, "{images:?}");
    for line in &images {
        assert_eq!(line["build"], "b");
        assert_eq!(line["against"], "build a");
        assert_eq!(line["same_bytes"], true, "{line}");
        assert_eq!(line["same_report"], true, "{line}");
        assert_eq!(line["diff"]["max_abs"], 0, "{line}");
    }
    let md = std::fs::read_to_string(dir.join("out/sweep.md")).unwrap();
    assert!(md.contains("## What the drivers compiled"), "{md}");
    assert!(
        md.contains("| a | opengl | scene=box size=32x24 path=compute |"),
        "{md}"
    );
    assert!(
        md.contains("| b | vulkan | scene=box size=32x24 path=compute | build a | identical | 0 |"),
        "{md}"
    );
}

#[test]
fn images_against_the_reference_render_it_from_the_sets_scene_options() {
    let dir = scratch("sweep-reference");
    two_builds(&dir);
    let plan = r#"rounds = 1
frames = 2
apps = ["vulkan", "opengl"]
images = "reference"

[builds]
a = "a"

[[sets]]
name = "shallow"
options = { scene = "spherelist", size = "24x16", set = ["max_depth=1"] }
"#;
    let o = sweep(&dir, plan);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    let images = step_lines(&dir, "images");
    assert_eq!(images.len(), 2, "{images:?}");
    let reference = Path::new(images[0]["a"].as_str().unwrap());
    let img = image::open(reference).unwrap();
    assert_eq!((img.width(), img.height()), (24, 16));
    for line in &images {
        assert_eq!(line["against"], "reference", "{line}");
        assert!(line["same_report"].is_null(), "{line}");
        // Mesa's f32 is within a few steps of the f64 reference on this scene.
        assert!(line["diff"]["max_abs"].as_u64().unwrap() < 64, "{line}");
    }
    let md = std::fs::read_to_string(dir.join("out/sweep.md")).unwrap();
    assert!(md.contains("| a | opengl | shallow | reference |"), "{md}");
}

#[test]
fn a_bad_environment_value_is_refused_at_its_line() {
    let plan = format!("{PLAN}\n[env]\nTWINRAY_VK_WAIT = \"idel\"\n");
    refused(
        "sweep-env-value",
        &plan,
        16,
        "twinray-vk refuses TWINRAY_VK_WAIT = 'idel', its --vk-wait",
    );
    let plan = format!("{PLAN}\n[env_axes]\nTWINRAY_VK_WIAT = [\"fence\", \"idle\"]\n");
    refused(
        "sweep-env-name",
        &plan,
        16,
        "no app reads TWINRAY_VK_WIAT (the apps read",
    );
    let plan = r#"rounds = 1
apps = ["vulkan"]
[builds]
a = "a"

[[sets]]
options = { scene = "box" }
env = { TWINRAY_VK_SYNC2 = "perhaps" }
"#;
    refused(
        "sweep-env-set",
        plan,
        8,
        "twinray-vk refuses TWINRAY_VK_SYNC2 = 'perhaps'",
    );
}

#[test]
fn a_bad_step_is_refused_at_its_line() {
    let plan = PLAN.replace("rounds = 2", "rounds = 2\nimages = \"mirror\"");
    refused("sweep-images", &plan, 2, "`images` is 'mirror'");
    let plan = PLAN
        .replace("rounds = 2", "rounds = 2\nimages = \"builds\"")
        .replace("b = \"b\"\n", "")
        .replace(", [\"a\", \"b\"]", "");
    refused("sweep-images-one", &plan, 2, "needs two builds at least");
    let plan = PLAN.replace(
        "size = [\"32x24\"]",
        "size = [\"32x24\"]\ndump-shaders = [\"d\"]",
    );
    refused("sweep-dump", &plan, 13, "the plan's top-level `shaders`");
}
