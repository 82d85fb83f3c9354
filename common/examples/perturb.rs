//! Which f32 operations flip pixels (issue 26, B2): renders each scene with the
//! f64 reference and its own numerics, once unperturbed and once per
//! operation and ULP count with that operation rounded to f32 and moved by up
//! to k ULPs (common/src/reference/perturb.rs), and prints a Markdown table of
//! the pixels off by more than 8/255 against the f64 truth and against the
//! unperturbed render. Needs the cargo feature `perturb`:
//!
//! cargo run --release -p twinray-common --features perturb --example perturb -- \
//!     SCENE:WxH[,SCENE:WxH...] [OPS|all|every] [K,K...]
//!
//! OPS is a comma-separated list of the names in `Op::name` (`every` perturbs
//! every operation at once, `all` each one alone); K defaults to 0,4,64.

use twinray_common::reference::metrics::compare;
use twinray_common::reference::perturb::{clear, set, Op};
use twinray_common::reference::{render, render_truth};
use twinray_common::scene::Scene;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scenes = args.first().map_or("box:200x200", |s| s.as_str());
    let ops = args.get(1).map_or("all", |s| s.as_str());
    let ks: Vec<i64> = args
        .get(2)
        .map_or("0,4,64", |s| s.as_str())
        .split(',')
        .map(|k| k.parse())
        .collect::<Result<_, _>>()?;
    let mut list: Vec<Option<Op>> = Vec::new();
    for n in ops.split(',') {
        match n {
            "all" => list.extend(Op::ALL.iter().copied().map(Some)),
            "every" => list.push(None),
            _ => list.push(Some(
                Op::ALL
                    .iter()
                    .find(|o| o.name() == n)
                    .copied()
                    .ok_or_else(|| anyhow::anyhow!("no operation named {n}"))?,
            )),
        }
    }
    let ops = list;
    println!("| scene | size | operation | k (ULPs) | pixels > 8/255 vs f64 truth | > 8/255 vs unperturbed | largest vs truth |");
    println!("|---|---|---|---:|---:|---:|---:|");
    for spec in scenes.split(',') {
        let (name, size) = spec.rsplit_once(':').unwrap_or((spec, "200x200"));
        let (w, h) = size
            .split_once('x')
            .ok_or_else(|| anyhow::anyhow!("size {size} is not WxH"))?;
        let (w, h): (u32, u32) = (w.parse()?, h.parse()?);
        let scene = Scene::load(name, &[])?;
        let short = name
            .rsplit('/')
            .next()
            .unwrap_or(name)
            .trim_end_matches(".toml");
        clear();
        let truth = render_truth(&scene, w, h).to_rgb8();
        let base = render(&scene, w, h).to_rgb8();
        let pixels = (w * h) as f64;
        let row = |label: &str, k: &str, img: &image::RgbImage| -> anyhow::Result<()> {
            let t = compare(&truth, img)?;
            let b = compare(&base, img)?;
            println!(
                "| {short} | {size} | {label} | {k} | {} ({:.3} %) | {} | {}/255 |",
                (t.above_8 * pixels).round(),
                t.above_8 * 100.0,
                (b.above_8 * pixels).round(),
                t.max_abs
            );
            Ok(())
        };
        row("none", "-", &base)?;
        if let Some(dir) = std::env::var_os("PERTURB_PNG") {
            truth.save(std::path::Path::new(&dir).join(format!("{short}-truth.png")))?;
        }
        for &op in &ops {
            for &k in &ks {
                set(op, k);
                let img = render(&scene, w, h).to_rgb8();
                clear();
                let label = op.map_or("every", |o| o.name());
                row(label, &k.to_string(), &img)?;
                if let Some(dir) = std::env::var_os("PERTURB_PNG") {
                    let file = format!("{short}-{label}-{k}.png");
                    img.save(std::path::Path::new(&dir).join(file))?;
                    // The truth with the pixels off by more than 8/255 in magenta.
                    let mut mask = truth.clone();
                    for (m, (a, b)) in mask.pixels_mut().zip(truth.pixels().zip(img.pixels())) {
                        if (0..3).any(|c| a.0[c].abs_diff(b.0[c]) > 8) {
                            m.0 = [255, 0, 255];
                        }
                    }
                    mask.save(
                        std::path::Path::new(&dir).join(format!("{short}-{label}-{k}-mask.png")),
                    )?;
                }
            }
        }
    }
    Ok(())
}
