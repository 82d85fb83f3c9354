//! vk/src/barrier.rs is the one source of twinray-vk's barriers, for three
//! readers. The code: no stage mask, access mask or image layout is written
//! anywhere else in vk/src. The page: docs/vulkan-walkthrough.md's barrier table and access
//! table are the module's. `--explain`: on both paths, headless and in the
//! window, with both recordings, each barrier line is what its named accesses
//! mean, and the runs are clean under synchronisation validation with images
//! byte-identical between the two recordings.

use twinray_tests::repo::{assert_scan, root, WALKTHROUGH};
use twinray_tests::{assert_none, box_window, SYNC_VALIDATION};
use twinray_vk::barrier::{self, Access, Barrier, Guards, Recording};

fn sync2_env(recording: Recording) -> (&'static str, &'static str) {
    let on = match recording {
        Recording::Vulkan10 => "0",
        Recording::Synchronization2 => "1",
    };
    ("TWINRAY_VK_SYNC2", on)
}

const RECORDINGS: [Recording; 2] = [Recording::Vulkan10, Recording::Synchronization2];

#[test]
fn no_stage_access_or_layout_outside_the_barrier_module() {
    let dir = root().join("vk/src");
    let (mut outside, mut inside) = (Vec::new(), 0);
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let text = std::fs::read_to_string(&path).unwrap();
        for (n, line) in text.lines().enumerate() {
            // Code only: a comment may name a mask.
            let code = line.split("//").next().unwrap();
            let masks = ["PipelineStageFlags", "AccessFlags", "ImageLayout::"];
            if !masks.iter().any(|m| code.contains(m)) {
                continue;
            }
            if name == "barrier.rs" {
                inside += 1;
            } else {
                outside.push(format!("vk/src/{name}:{}: {}", n + 1, line.trim()));
            }
        }
    }
    assert_scan(
        "stage masks, access masks or layouts outside vk/src/barrier.rs: name the accesses instead",
        &outside,
        inside,
        10,
        "mask lines in barrier.rs",
    );
}

/// Flags in a table cell: a `|` in them would end the cell.
fn cell(flags: impl std::fmt::Debug + PartialEq + Default) -> String {
    barrier::show(flags).replace(" | ", " \\| ")
}

fn guards(g: Guards) -> &'static str {
    match g {
        Guards::Buffers => "buffers",
        Guards::Image => "an image",
        Guards::ImageDiscarded => "an image, contents dropped",
        Guards::Execution => "nothing: execution only",
        Guards::Subpass => "subpass dependency",
    }
}

/// The page's barrier table as the module holds it.
fn barrier_table() -> String {
    let mut s = String::from("| barrier | step | before → after | guards |\n|---|---|---|---|\n");
    for b in barrier::ALL {
        s += &format!(
            "| {} | {} | `{}` | {} |\n",
            b.name,
            b.step,
            b.words().replace(" | ", " \\| "),
            guards(b.guards)
        );
    }
    s
}

/// The page's access table: what each name records, in each recording.
fn access_table() -> String {
    let mut s = String::from(
        "| access | Vulkan 1.0: stage, access | synchronization2: stage, access | image layout |\n|---|---|---|---|\n",
    );
    for a in Access::EVERY {
        let (v10, v2) = (
            a.masks(Recording::Vulkan10),
            a.masks(Recording::Synchronization2),
        );
        let (stages_1_0, access_1_0) = v10.narrowed();
        let (columns_1_0, columns_2) = if a == Access::Acquire {
            let next = "the next access's stage";
            (
                format!("{next}, {}", cell(access_1_0)),
                format!("{next}, {}", cell(v2.access)),
            )
        } else {
            (
                format!("{}, {}", cell(stages_1_0), cell(access_1_0)),
                format!("{}, {}", cell(v2.stages), cell(v2.access)),
            )
        };
        let layout = v10
            .layout
            .map_or("— (buffers only)".to_string(), |l| format!("{l:?}"));
        s += &format!("| `{a:?}` | {columns_1_0} | {columns_2} | {layout} |\n");
    }
    s
}

/// The page between `<!-- name:begin -->` and `<!-- name:end -->` must be
/// `expected`; `TWINRAY_UPDATE_DOCS=1` rewrites it instead.
fn page_holds(name: &str, expected: &str) {
    // The two table tests run at once; a rewrite must not undo the other's.
    static PAGE: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _only_one = PAGE.lock().unwrap_or_else(|e| e.into_inner());
    let path = root().join(WALKTHROUGH);
    let doc = std::fs::read_to_string(&path).unwrap();
    let (begin, end) = (
        format!("<!-- {name}:begin -->\n"),
        format!("<!-- {name}:end -->"),
    );
    let start = doc
        .find(&begin)
        .unwrap_or_else(|| panic!("no {begin} marker"))
        + begin.len();
    let stop = doc.find(&end).unwrap_or_else(|| panic!("no {end} marker"));
    if doc[start..stop] == *expected {
        return;
    }
    if std::env::var("TWINRAY_UPDATE_DOCS").is_ok_and(|v| v == "1") {
        std::fs::write(
            &path,
            format!("{}{expected}{}", &doc[..start], &doc[stop..]),
        )
        .unwrap();
        return;
    }
    panic!(
        "the walkthrough's {name} table is not vk/src/barrier.rs's; change the page, or run\n  TWINRAY_UPDATE_DOCS=1 cargo test --release -p twinray-tests --test barriers\nexpected:\n{expected}"
    );
}

#[test]
fn the_pages_barrier_table_is_the_module() {
    page_holds("barriers", &barrier_table());
}

#[test]
fn the_pages_access_table_is_the_module() {
    page_holds("accesses", &access_table());
}

/// One barrier call or subpass dependency as `--explain` printed it.
struct Printed {
    call: String,
    names: Vec<String>,
    details: Vec<String>,
}

fn printed_barriers(stderr: &str) -> Vec<Printed> {
    let mut found: Vec<Printed> = Vec::new();
    let mut open = false;
    for line in stderr.lines() {
        if line.starts_with('[') {
            let title = line.split_once(" ms  ").map_or("", |(_, t)| t);
            open = false;
            if let Some((call, names)) = title.split_once(": ") {
                if call.starts_with("vkCmdPipelineBarrier") || call == "VkSubpassDependency" {
                    found.push(Printed {
                        call: call.to_string(),
                        names: names.split(" + ").map(str::to_string).collect(),
                        details: Vec::new(),
                    });
                    open = true;
                }
            }
        } else if open && line.starts_with("    ") {
            found
                .last_mut()
                .unwrap()
                .details
                .push(line.trim().to_string());
        } else {
            open = false;
        }
    }
    found
}

/// What a call of `barriers` records, line by line, as barrier.rs prints it:
/// worked out here from the names, for the printed lines to be held to.
fn expected_details(p: &Printed, barriers: &[Barrier], recording: Recording) -> Vec<String> {
    use barrier::show;
    // One call, one pair of stage masks: every barrier's together.
    let [(mut src, _), (mut dst, _)] = barriers[0].masks_1_0();
    for b in barriers {
        let [(s, _), (d, _)] = b.masks_1_0();
        src |= s;
        dst |= d;
    }
    let mut lines = Vec::new();
    if p.call == "VkSubpassDependency" {
        let [(ss, sa), (ds, da)] = barriers[0].masks_1_0();
        lines.push(barriers[0].words());
        lines.push(format!(
            "stages {} -> {}; access {} -> {}",
            show(ss),
            show(ds),
            show(sa),
            show(da)
        ));
        return lines;
    }
    // The words, with how many buffers each guarded (read from the words line).
    let mut counts = Vec::new();
    for b in barriers {
        let prefix = format!("{}: {} (", b.name, b.words());
        let line = p.details.iter().find(|l| l.starts_with(&prefix));
        let count: usize = line
            .and_then(|l| l[prefix.len()..].split(' ').next()?.parse().ok())
            .unwrap_or(1);
        counts.push(count);
        lines.push(line.cloned().unwrap_or(prefix));
    }
    let many = |n: usize, line: String| if n > 1 { format!("{n} x {line}") } else { line };
    let layouts = |b: &Barrier| {
        let (old, new) = b.layouts();
        format!("layout {old:?} -> {new:?}")
    };
    match recording {
        Recording::Vulkan10 => {
            lines.push(format!("stages {} -> {}", show(src), show(dst)));
            for (b, n) in barriers.iter().zip(&counts) {
                let [(_, s), (_, d)] = b.masks_1_0();
                match b.guards {
                    Guards::Buffers => lines.push(many(
                        *n,
                        format!("buffer access {} -> {}", show(s), show(d)),
                    )),
                    Guards::Image | Guards::ImageDiscarded => lines.push(format!(
                        "image access {} -> {}, {}",
                        show(s),
                        show(d),
                        layouts(b)
                    )),
                    Guards::Execution | Guards::Subpass => {}
                }
            }
        }
        Recording::Synchronization2 => {
            for (b, n) in barriers.iter().zip(&counts) {
                let ((ss, sa), (ds, da)) = (b.source(recording), b.destination(recording));
                let masks = format!("{}/{} -> {}/{}", show(ss), show(sa), show(ds), show(da));
                lines.push(match b.guards {
                    Guards::Buffers => many(*n, format!("buffer {masks}")),
                    Guards::Image | Guards::ImageDiscarded => {
                        format!("image {masks}, {}", layouts(b))
                    }
                    Guards::Execution | Guards::Subpass => {
                        format!("memory {}/NONE -> {}/NONE", show(ss), show(ds))
                    }
                });
            }
        }
    }
    lines
}

/// Holds each printed barrier to its names; returns the names printed.
fn check_printed(stderr: &str, recording: Recording, wrong: &mut Vec<String>) -> Vec<String> {
    let call = match recording {
        Recording::Vulkan10 => "vkCmdPipelineBarrier",
        Recording::Synchronization2 => "vkCmdPipelineBarrier2",
    };
    let mut names = Vec::new();
    for p in printed_barriers(stderr) {
        let barriers: Vec<Barrier> = p
            .names
            .iter()
            .filter_map(|n| barrier::ALL.iter().find(|b| b.name == n).copied())
            .collect();
        if barriers.len() != p.names.len() {
            wrong.push(format!(
                "{}: {:?} names a barrier barrier.rs does not hold",
                p.call, p.names
            ));
            continue;
        }
        if p.call != call && p.call != "VkSubpassDependency" {
            wrong.push(format!("{recording:?} recorded through {}", p.call));
        }
        let expected = expected_details(&p, &barriers, recording);
        if p.details != expected {
            wrong.push(format!(
                "{recording:?}, {}: {}\n  printed  {:?}\n  expected {expected:?}",
                p.call,
                p.names.join(" + "),
                p.details
            ));
        }
        names.extend(p.names);
    }
    names
}

#[test]
fn explain_prints_each_headless_barrier_as_recorded() {
    let program = twinray_tests::bin("twinray-vk");
    let expected = [
        (
            "fragment",
            vec![
                "scene upload",
                "offscreen render pass in",
                "offscreen render pass out",
                "readback",
            ],
        ),
        (
            "compute",
            vec![
                "scene upload",
                "storage image setup",
                "frame after frame",
                "storage image to copy",
                "readback",
            ],
        ),
    ];
    let mut wrong = Vec::new();
    for recording in RECORDINGS {
        for (path, names) in &expected {
            let args = [
                "--headless",
                "--validate",
                "--explain",
                "--path",
                path,
                "--size",
                "32x24",
            ];
            let out = twinray_tests::run(&program, &args, &[SYNC_VALIDATION, sync2_env(recording)]);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert!(
                out.status.success(),
                "twinray-vk {args:?} ({recording:?}) failed:\n{stderr}"
            );
            let printed = check_printed(&stderr, recording, &mut wrong);
            // The compute path's pool holds the storage image too (the pool's
            // line is printed from the sizes it was made with).
            let pool = stderr
                .lines()
                .skip_while(|l| !l.ends_with("VkDescriptorPool"))
                .nth(1);
            if *path == "compute" && !pool.is_some_and(|l| l.contains("1 STORAGE_IMAGE")) {
                wrong.push(format!(
                    "compute: the descriptor pool's line {pool:?} leaves out the storage image"
                ));
            }
            if printed != *names {
                wrong.push(format!(
                    "{path}, {recording:?}: printed {printed:?}, expected {names:?}"
                ));
            }
        }
    }
    assert_none("--explain's barriers", &wrong);
}

/// twinray-vk's box window at 64x48 for `frames` frames with `args`,
/// validated and explained, in `recording`, under synchronisation validation
/// and with `env`: its stderr, the run having succeeded.
fn in_window(
    xvfb: &twinray_tests::Xvfb,
    recording: Recording,
    (frames, args): (&str, &[&str]),
    env: (&str, &str),
    name: &str,
) -> String {
    let dir = twinray_tests::scratch(&format!("barriers-{name}-{recording:?}"));
    let args = box_window(
        "64x48",
        frames,
        &[args, &["--validate", "--explain"]].concat(),
    );
    let env = [SYNC_VALIDATION, sync2_env(recording), env];
    let app = twinray_tests::bin("twinray-vk");
    let out = xvfb.run(&app, &args, &env, &dir);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(
        out.status.success(),
        "the window {args:?} failed ({recording:?}):\n{stderr}"
    );
    stderr
}

#[test]
fn explain_prints_each_window_barrier_as_recorded() {
    let xvfb = twinray_tests::Xvfb::start();
    let mut wrong = Vec::new();
    for recording in RECORDINGS {
        // Two frames on the fragment path (`R` changes nothing), then `C`: the compute path.
        let keys = ("TWINRAY_TEST_KEYS", "r,r,c");
        let stderr = in_window(&xvfb, recording, ("5", &[]), keys, "window");
        let mut printed = check_printed(&stderr, recording, &mut wrong);
        printed.sort();
        printed.dedup();
        let mut names = vec![
            "scene upload",
            "window render pass in",
            "uniform write after reads",
            "uniform to fragment shader",
            "storage image setup",
            "uniform to compute shader",
            "storage image after blit",
            "storage image to blit",
            "swapchain image to blit",
            "swapchain image to present",
        ];
        names.sort();
        if printed != names {
            wrong.push(format!(
                "window, {recording:?}: printed {printed:?}, expected {names:?}"
            ));
        }
    }
    assert_none("--explain's barriers in the window", &wrong);
}

#[test]
fn both_recordings_make_the_same_image_under_sync_validation() {
    let program = twinray_tests::bin("twinray-vk");
    let dir = twinray_tests::scratch("barriers-images");
    for path in ["fragment", "compute"] {
        let images: Vec<Vec<u8>> = RECORDINGS
            .iter()
            .map(|&recording| {
                let out = dir.join(format!("{path}-{recording:?}.png"));
                let out_arg = out.to_str().unwrap();
                let args = [
                    "--headless",
                    "--validate",
                    "--path",
                    path,
                    "--size",
                    "48x32",
                    "--frames",
                    "2",
                    "--out",
                    out_arg,
                ];
                let o =
                    twinray_tests::run(&program, &args, &[SYNC_VALIDATION, sync2_env(recording)]);
                let stderr = String::from_utf8_lossy(&o.stderr);
                assert!(o.status.success(), "{path}, {recording:?}:\n{stderr}");
                assert!(!stderr.contains("twinray-vk: validation"), "{stderr}");
                std::fs::read(&out).unwrap()
            })
            .collect();
        assert!(
            images[0] == images[1],
            "{path}: the synchronization2 recording's image differs from the Vulkan 1.0 one's"
        );
    }
}

/// The window, both paths, both recordings, 100 frames with the resize hook
/// (a new size every few frames, a minimize every 20th): no message from
/// synchronisation validation, and at least 20 swapchains made anew.
#[test]
fn both_recordings_survive_resizes_under_sync_validation() {
    let xvfb = twinray_tests::Xvfb::start();
    for recording in RECORDINGS {
        for path in ["fragment", "compute"] {
            let resize = ("TWINRAY_TEST_RESIZE", "1");
            let run = ("100", &["--path", path][..]);
            let stderr = in_window(&xvfb, recording, run, resize, &format!("resize-{path}"));
            assert!(
                !stderr.contains("twinray-vk: validation"),
                "{path}, {recording:?}:\n{stderr}"
            );
            let swapchains = stderr
                .lines()
                .filter(|l| l.ends_with("VkSwapchainKHR"))
                .count();
            assert!(
                swapchains > 20,
                "{path}, {recording:?}: only {swapchains} swapchains: the resizes did not happen"
            );
        }
    }
}
