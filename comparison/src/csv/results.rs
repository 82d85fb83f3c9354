//! results.csv: one row per API × path × point, every figure of the run's
//! JSON report that a spreadsheet wants, and why a point failed.

use super::Decimals;
use crate::apps::api_name;
use crate::compare::runs::Outcome;
use serde::Serialize;
use twinray_common::rays::RateClock;
use twinray_common::stats::Summary;

/// One line of results.csv; the field order is the column order that the
/// committed results and the tests read.
#[derive(Serialize, Default)]
struct Row<'a> {
    experiment: &'a str,
    param_name: &'a str,
    param_value: &'a str,
    api: &'a str,
    path: String,
    workgroup: Option<&'a str>,
    /// "ok", or "failed: " and why.
    status: String,
    frames: usize,
    wall_mean_ms: Option<Decimals<6>>,
    wall_median_ms: Option<Decimals<6>>,
    wall_min_ms: Option<Decimals<6>>,
    wall_max_ms: Option<Decimals<6>>,
    gpu_mean_ms: Option<Decimals<6>>,
    gpu_median_ms: Option<Decimals<6>>,
    gpu_min_ms: Option<Decimals<6>>,
    gpu_max_ms: Option<Decimals<6>>,
    setup_ms: Option<Decimals<3>>,
    nonfinite_pixels: Option<u64>,
    variant: &'a str,
    width: u32,
    height: u32,
    device: &'a str,
    driver: &'a str,
    api_version: &'a str,
    os: &'a str,
    cpu: &'a str,
    /// The counting frame's rays and the rate they give (empty where the run
    /// did not count them); after the older columns, which readers rely on.
    rays_primary: Option<u64>,
    rays_shadow: Option<u64>,
    rays_secondary: Option<u64>,
    rays_total: Option<u64>,
    grays_per_s: Option<Decimals<6>>,
    /// "gpu" or "wall": which median frame time `grays_per_s` divides by.
    grays_clock: Option<RateClock>,
    /// The frames the statistics cover (the rest warmed up), and each
    /// median's 95 % interval (empty below 6 timed frames).
    timed_frames: Option<usize>,
    wall_median_lo_ms: Option<Decimals<6>>,
    wall_median_hi_ms: Option<Decimals<6>>,
    gpu_median_lo_ms: Option<Decimals<6>>,
    gpu_median_hi_ms: Option<Decimals<6>>,
}

type Stats = [Option<Decimals<6>>; 4];

/// Mean, median, min and max, or four empty cells.
fn stats(s: Option<Summary>) -> Stats {
    match s {
        Some(s) => [s.mean, s.median, s.min, s.max].map(|v| Some(Decimals(v))),
        None => [None; 4],
    }
}

fn row<'a>(o: &'a Outcome, cpu: &'a str) -> Row<'a> {
    let p = &o.point;
    let mut row = Row {
        experiment: p.experiment,
        param_name: p.param_name,
        param_value: &p.param_value,
        api: api_name(o.api),
        path: o.path.to_string(),
        cpu,
        ..Row::default()
    };
    match &o.result {
        Ok(r) => {
            let [wall_mean_ms, wall_median_ms, wall_min_ms, wall_max_ms] = stats(r.wall_ms);
            let [gpu_mean_ms, gpu_median_ms, gpu_min_ms, gpu_max_ms] = stats(r.gpu_ms);
            Row {
                workgroup: r.workgroup.as_deref(),
                status: "ok".into(),
                frames: r.frames.len(),
                wall_mean_ms,
                wall_median_ms,
                wall_min_ms,
                wall_max_ms,
                gpu_mean_ms,
                gpu_median_ms,
                gpu_min_ms,
                gpu_max_ms,
                setup_ms: Some(Decimals(r.setup_ms)),
                nonfinite_pixels: Some(r.nonfinite_pixels),
                variant: &r.variant,
                width: r.width,
                height: r.height,
                device: &r.device,
                driver: &r.driver,
                api_version: &r.api_version,
                os: &r.os,
                rays_primary: r.rays.map(|c| c.primary),
                rays_shadow: r.rays.map(|c| c.shadow),
                rays_secondary: r.rays.map(|c| c.secondary),
                rays_total: r.rays.map(|c| c.total),
                grays_per_s: r.grays_per_s.map(Decimals),
                grays_clock: r.grays_clock,
                timed_frames: r.wall_ms.map(|s| s.n),
                wall_median_lo_ms: r.wall_ms.and_then(|s| s.median_lo).map(Decimals),
                wall_median_hi_ms: r.wall_ms.and_then(|s| s.median_hi).map(Decimals),
                gpu_median_lo_ms: r.gpu_ms.and_then(|s| s.median_lo).map(Decimals),
                gpu_median_hi_ms: r.gpu_ms.and_then(|s| s.median_hi).map(Decimals),
                ..row
            }
        }
        Err(_) => {
            row.status = super::status(&o.result);
            row.width = p.size.width;
            row.height = p.size.height;
            row
        }
    }
}

/// results.csv's text.
pub fn results(outcomes: &[Outcome], cpu: &str) -> anyhow::Result<String> {
    super::to_string(outcomes.iter().map(|o| row(o, cpu)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::apps::Api;
    use crate::compare::runs::test_outcome;
    use twinray_common::cli::RenderPath;

    #[test]
    fn csv_has_a_path_column_and_a_workgroup_for_compute_rows() {
        let mut failed = test_outcome(Api::Opengl, RenderPath::Compute, 1.0);
        failed.result = Err("twinray-gl exited with 1: \"no\", device".into());
        let mut counted = test_outcome(Api::Vulkan, RenderPath::Compute, 1.0);
        if let Ok(r) = &mut counted.result {
            r.add_rays(twinray_common::rays::RayKinds {
                primary: 64,
                shadow: 10,
                mirror: 5,
                ..Default::default()
            });
        }
        let rows = [
            test_outcome(Api::Vulkan, RenderPath::Fragment, 10.0),
            test_outcome(Api::Opengl, RenderPath::Fragment, 10.0),
            counted,
            failed,
        ];
        let text = results(&rows, "cpu, 2 threads").unwrap();
        let mut lines = text.lines();
        assert_eq!(
            lines.next().unwrap(),
            "experiment,param_name,param_value,api,path,workgroup,status,frames,wall_mean_ms,wall_median_ms,wall_min_ms,wall_max_ms,gpu_mean_ms,gpu_median_ms,gpu_min_ms,gpu_max_ms,setup_ms,nonfinite_pixels,variant,width,height,device,driver,api_version,os,cpu,rays_primary,rays_shadow,rays_secondary,rays_total,grays_per_s,grays_clock,timed_frames,wall_median_lo_ms,wall_median_hi_ms,gpu_median_lo_ms,gpu_median_hi_ms",
            "the committed results and their readers rely on these columns in this order"
        );
        let body: Vec<&str> = lines.collect();
        assert_eq!(
            body,
            [
                "box,resolution,8x8,vulkan,fragment,,ok,1,10.000000,10.000000,10.000000,10.000000,10.000000,10.000000,10.000000,10.000000,1.000,0,v,8,8,d,v,1,o,\"cpu, 2 threads\",,,,,,,1,,,,",
                "box,resolution,8x8,opengl,fragment,,ok,1,10.000000,10.000000,10.000000,10.000000,10.000000,10.000000,10.000000,10.000000,1.000,0,v,8,8,d,v,1,o,\"cpu, 2 threads\",,,,,,,1,,,,",
                "box,resolution,8x8,vulkan,compute,16x8,ok,1,1.000000,1.000000,1.000000,1.000000,1.000000,1.000000,1.000000,1.000000,1.000,0,v,8,8,d,v,1,o,\"cpu, 2 threads\",64,10,5,79,0.000079,gpu,1,,,,",
                "box,resolution,8x8,opengl,compute,,\"failed: twinray-gl exited with 1: \"\"no\"\", device\",0,,,,,,,,,,,,8,8,,,,,\"cpu, 2 threads\",,,,,,,,,,,",
            ]
        );
    }
}
