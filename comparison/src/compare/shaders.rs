//! The compare report's "What the drivers compiled" section: each scene's
//! tracer, as the comparison runs it (brute force) and through the BVH, on
//! both paths, dumped by each app with `--dump-shaders` (under
//! `<out>/shaders/`), and the figures each driver gives for it: registers and
//! local memory from Vulkan's pipeline executable statistics, local memory
//! from OpenGL's program binary. Where a driver offers neither (Mesa's
//! software drivers), the table says so.

use crate::apps::api_name;
use crate::apps::{run_json, Api};
use std::fmt::Write as _;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use twinray_common::cli::{RenderArgs, RenderPath, Size};
use twinray_common::report::ShaderStats;
use twinray_common::scene::accel::Accel;
use twinray_common::value_name::ValueName;

pub struct ShaderRow {
    pub scene: &'static str,
    pub accel: Accel,
    pub api: Api,
    pub path: RenderPath,
    pub result: Result<(String, Vec<ShaderStats>), String>,
}

const SCENES: [(&str, Accel); 4] = [
    ("box", Accel::None),
    ("spherelist", Accel::None),
    ("teapot", Accel::None),
    ("teapot", Accel::Bvh),
];

/// One tiny frame per scene, accel, API and path, with its shaders dumped.
pub fn collect(out: &Path, paths: &[RenderPath], stop: &AtomicBool) -> Vec<ShaderRow> {
    let mut rows = Vec::new();
    eprintln!("twinray compare: dumping each tracer and reading the drivers' statistics");
    for (scene, accel) in SCENES {
        for &path in paths {
            for api in [Api::Vulkan, Api::Opengl] {
                if stop.load(Ordering::SeqCst) {
                    return rows;
                }
                let dir = out.join("shaders").join(format!(
                    "{scene}-{}-{}-{path}",
                    accel.name(),
                    api_name(api)
                ));
                let args = RenderArgs {
                    frames: Some(1),
                    accel,
                    path,
                    dump_shaders: Some(dir),
                    ..RenderArgs::headless(
                        scene,
                        Size {
                            width: 16,
                            height: 16,
                        },
                    )
                };
                let result = run_json(api, &args)
                    .map(|r| (r.variant, r.shader_stats))
                    .map_err(|e| format!("{e:#}"));
                if stop.load(Ordering::SeqCst) && result.is_err() {
                    // Stopped by the signal, not failed: not a row of the table.
                    return rows;
                }
                rows.push(ShaderRow {
                    scene,
                    accel,
                    api,
                    path,
                    result,
                });
            }
        }
    }
    rows
}

/// The figures worth a column: registers and local memory, whatever the
/// driver calls them. NVIDIA's Vulkan driver sets bit 36 of its local-memory
/// figure; the bytes are the low 32 bits.
pub(crate) fn figures(stats: &[ShaderStats]) -> String {
    let mut parts = Vec::new();
    for s in stats {
        if s.stage == "VS" || s.stage.to_ascii_lowercase().contains("vertex") {
            continue;
        }
        for (name, value) in &s.statistics {
            let lower = name.to_ascii_lowercase();
            let shown = if lower.contains("local memory size") {
                value
                    .parse::<u64>()
                    .map(|v| format!("{} B", v & 0xffff_ffff))
                    .unwrap_or_else(|_| value.clone())
            } else if lower.contains("register")
                || lower.contains("lmem0")
                || lower.contains("local memory bytes")
                || lower.contains("shared memory")
            {
                value.clone()
            } else {
                continue;
            };
            parts.push(format!("{name}: {shown}"));
        }
    }
    if parts.is_empty() {
        "not offered by this driver".into()
    } else {
        parts.join("; ")
    }
}

/// Adds the section at the end of the written report: it stands alone, and
/// keeps report.rs's long writer out of it.
pub fn append_to_report(report: &Path, rows: &[ShaderRow]) -> anyhow::Result<()> {
    use anyhow::Context;
    let mut text = std::fs::read_to_string(report)
        .with_context(|| format!("reading '{}' back", report.display()))?;
    text.push_str(&markdown(rows));
    std::fs::write(report, text).with_context(|| format!("writing '{}'", report.display()))
}

fn markdown(rows: &[ShaderRow]) -> String {
    let mut s = String::new();
    if rows.is_empty() {
        return s;
    }
    let _ = writeln!(
        s,
        "## What the drivers compiled\n\nEach tracer dumped by its app (`--dump-shaders`, files in `shaders/`): \
         Vulkan's pipeline executable statistics (VK_KHR_pipeline_executable_properties) and the local memory \
         in OpenGL's program binary (NVIDIA's NV assembly declares it as `TEMP lmem0[N]`, 16-byte slots).\n"
    );
    let _ = writeln!(
        s,
        "| scene | accel | path | API | variant | driver's figures |\n|---|---|---|---|---|---|"
    );
    for r in rows {
        let (variant, figs) = match &r.result {
            Ok((v, stats)) => (v.clone(), figures(stats)),
            Err(e) => ("–".into(), format!("failed: {}", e.replace('|', "/"))),
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {variant} | {figs} |",
            r.scene,
            r.accel.name(),
            r.path,
            api_name(r.api)
        );
    }
    let _ = writeln!(s);
    s
}
