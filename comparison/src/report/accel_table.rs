//! report.md's "Model only what a scene needs": the scenes with the
//! all-features shader, their own variant, specialization constants and a
//! BVH, and where `--accel auto` switches to the BVH.

use super::cells::{f, ratio};
use crate::apps::api_name;
use crate::apps::Api;
use crate::compare::runs::AccelRun;
use std::fmt::Write as _;

/// The section, or nothing when the acceleration runs were not made.
pub fn section(accel: &[AccelRun], plots: &[String]) -> String {
    let mut s = String::new();
    if !accel.is_empty() {
        let _ = writeln!(
            s,
            "## Model only what a scene needs\n\nThe same scenes with the all-features shader (`--generic`, brute force, as the study's \
             tracer), with the scene's own shader variant (features it lacks compiled out), with the one all-features source \
             specialised to the scene through specialization constants (`--specialize`: constant_id overrides fixed by naga's \
             process_overrides, so the driver sees constant branches and the deepest ray stack), and with the variant tracing through \
             a BVH (`--accel bvh`; binned SAH over spheres and triangles, built on the CPU). Median GPU ms (wall ms where the driver \
             has no GPU timer); speed-up against the generic brute-force shader of the same API.\n"
        );
        let _ = writeln!(s, "| scene | size | configuration | VK (ms) | GL (ms) | VK speed-up | GL speed-up | BVH nodes / bytes / build ms |\n|---|---|---|---|---|---|---|---|");
        let time = |r: &AccelRun| {
            r.result
                .as_ref()
                .ok()
                .and_then(|r| r.gpu_ms.or(r.wall_ms))
                .map(|x| x.median)
        };
        let mut keys: Vec<(&str, String, String, &str)> = Vec::new();
        for r in accel {
            let k = (r.scene, r.size.to_string(), r.set.join(" "), r.config);
            if !keys.contains(&k) {
                keys.push(k);
            }
        }
        for (scene, size, set, config) in &keys {
            let find = |api: Api, cfg: &str| {
                accel.iter().find(|r| {
                    r.scene == *scene
                        && r.size.to_string() == *size
                        && r.set.join(" ") == *set
                        && r.config == cfg
                        && r.api == api
                })
            };
            let vk = find(Api::Vulkan, config).and_then(time);
            let gl = find(Api::Opengl, config).and_then(time);
            let base = |api: Api| find(api, "generic, brute force").and_then(time);
            let bvh = find(Api::Vulkan, config)
                .and_then(|r| r.bvh)
                .map(|b| {
                    format!(
                        "{} / {:.1} KiB / {:.1}",
                        b.nodes,
                        b.bytes as f64 / 1024.0,
                        b.build_ms
                    )
                })
                .unwrap_or_else(|| "–".into());
            let label = if set.is_empty() {
                scene.to_string()
            } else {
                format!("{scene} ({set})")
            };
            let _ = writeln!(
                s,
                "| {label} | {size} | {config} | {} | {} | {} | {} | {bvh} |",
                f(vk, 3),
                f(gl, 3),
                ratio(base(Api::Vulkan), vk)
                    .map(|x| format!("{x:.1}×"))
                    .unwrap_or_else(|| "–".into()),
                ratio(base(Api::Opengl), gl)
                    .map(|x| format!("{x:.1}×"))
                    .unwrap_or_else(|| "–".into()),
            );
        }
        if plots.iter().any(|p| p == "scaling.svg") {
            let _ = writeln!(s, "\n![frame time against primitive count](scaling.svg)\n");
        }
        let _ = writeln!(
            s,
            "\n**Where `--accel auto` switches.** `auto` traces through a BVH from {} primitives on \
             (`AUTO_BVH_MIN_PRIMITIVES`, common/src/scene/accel.rs), one threshold for both APIs so that both always run the \
             same shader. It was set from auto's 4-wide tree against brute force on the box and the sphere list, \
             measured on an NVIDIA H200 and on Mesa llvmpipe (docs/findings/bvh.md). The rows above trace the binary \
             tree. Here:",
            twinray_common::scene::accel::AUTO_BVH_MIN_PRIMITIVES
        );
        for api in [Api::Vulkan, Api::Opengl] {
            let _ = writeln!(
                s,
                "- {}: {}",
                api_name(api),
                crossover_sentence(&crossover(accel, api))
            );
        }
        let _ = writeln!(s);
        let failed: Vec<&AccelRun> = accel.iter().filter(|r| r.result.is_err()).collect();
        for r in failed {
            let _ = writeln!(
                s,
                "\n- {} {} {} {}: {}",
                r.scene,
                r.config,
                api_name(r.api),
                r.size,
                r.result.as_ref().err().map(String::as_str).unwrap_or("")
            );
        }
        let _ = writeln!(s);
    }
    s
}

/// BVH ms), fewest primitives first: every count measured both ways.
pub fn crossover(accel: &[AccelRun], api: Api) -> Vec<(usize, f64, f64)> {
    let ms = |r: &AccelRun| {
        r.result.as_ref().ok().and_then(|rep| {
            let t = rep.gpu_ms.or(rep.wall_ms)?.median;
            Some((rep.scene.spheres + rep.scene.triangles, t))
        })
    };
    let mut v: Vec<(usize, f64, f64)> = accel
        .iter()
        .filter(|r| r.api == api && r.scene == "spherelist" && r.config == "variant, brute force")
        .filter_map(|brute| {
            let bvh = accel.iter().find(|o| {
                o.api == api
                    && o.scene == brute.scene
                    && o.size == brute.size
                    && o.set == brute.set
                    && o.config == "variant, BVH"
            })?;
            let ((n, b), (_, t)) = (ms(brute)?, ms(bvh)?);
            Some((n, b, t))
        })
        .collect();
    v.sort_by_key(|x| x.0);
    v
}

/// "brute force faster up to N primitives, the BVH from M on" for `crossover` rows.
pub fn crossover_sentence(rows: &[(usize, f64, f64)]) -> String {
    if rows.is_empty() {
        return "no crossover runs".into();
    }
    let last_brute = rows.iter().filter(|r| r.1 <= r.2).map(|r| r.0).max();
    // The BVH counts as ahead from the smallest count after which it never loses.
    let first_bvh = rows
        .iter()
        .map(|r| r.0)
        .filter(|&n| rows.iter().filter(|r| r.0 >= n).all(|r| r.2 < r.1))
        .min();
    let counts = rows
        .iter()
        .map(|r| format!("{} ({:.3} / {:.3} ms)", r.0, r.1, r.2))
        .collect::<Vec<_>>()
        .join(", ");
    let verdict = match (last_brute, first_bvh) {
        (Some(b), Some(v)) => {
            format!("brute force is faster up to {b} primitives, the BVH from {v} on")
        }
        (None, Some(v)) => format!("the BVH is faster from the smallest count measured, {v}"),
        (Some(b), None) => format!("brute force is faster at every count measured, up to {b}"),
        (None, None) => "no count was measured both ways".into(),
    };
    format!("{verdict} (primitives (brute force / BVH): {counts}).")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_crossover_is_where_the_bvh_stops_losing() {
        let rows = [
            (8, 0.2, 0.4),
            (32, 0.4, 0.5),
            (57, 0.6, 0.5),
            (107, 1.0, 1.1),
            (207, 2.0, 1.5),
            (507, 5.0, 1.6),
        ];
        let s = crossover_sentence(&rows);
        assert!(
            s.starts_with("brute force is faster up to 107 primitives, the BVH from 207 on"),
            "{s}"
        );
        assert!(crossover_sentence(&[]).contains("no crossover"));
        assert!(
            crossover_sentence(&[(8, 0.5, 0.1)]).contains("from the smallest count measured, 8")
        );
    }
}
