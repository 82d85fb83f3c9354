//! twinray-gen-teapot: tessellates Newell's teapot (scenes/teapot.bpt, embedded
//! at compile time) and writes it as OBJ.
//!
//! Usage: `twinray-gen-teapot [--nu N --nv M] [--out FILE]`
//!
//! Defaults: the study resolution (20 × 15 quads per patch, 19,200 triangles)
//! written to `teapot.obj` in the current folder. The built-in scenes do not
//! read it (they tessellate the patches at load); it is for other tools.

use std::path::PathBuf;
use std::process::ExitCode;

use twinray_common::scene::teapot::{parse_bpt, tessellate, to_obj, HEADER, STUDY_NU, STUDY_NV};

const BPT: &str = include_str!("../../../scenes/teapot.bpt");

const USAGE: &str = concat!(
    "usage: twinray-gen-teapot [--nu N --nv M] [--out FILE]\n",
    "  --nu N      quads per patch along u (integer 1..=1000, default 20)\n",
    "  --nv M      quads per patch along v (integer 1..=1000, default 15)\n",
    "  --out FILE  output OBJ path (default: teapot.obj in the current folder)",
);

struct Args {
    nu: u32,
    nv: u32,
    out: PathBuf,
}

enum Parsed {
    Run(Args),
    Help,
}

fn parse_count(flag: &str, value: &str) -> Result<u32, String> {
    match value.parse::<u32>() {
        Ok(n) if (1..=1000).contains(&n) => Ok(n),
        _ => Err(format!(
            "{flag} expects an integer from 1 to 1000, got {value:?}."
        )),
    }
}

fn parse_args(mut it: impl Iterator<Item = String>) -> Result<Parsed, String> {
    let mut nu = None;
    let mut nv = None;
    let mut out = None;
    while let Some(arg) = it.next() {
        let (flag, inline) = match arg.split_once('=') {
            Some((f, v)) if f.starts_with("--") => (f.to_string(), Some(v.to_string())),
            _ => (arg.clone(), None),
        };
        match flag.as_str() {
            "-h" | "--help" if inline.is_none() => return Ok(Parsed::Help),
            "--nu" | "--nv" | "--out" => {
                let value = match inline {
                    Some(v) => v,
                    None => it.next().ok_or_else(|| format!("{flag} needs a value."))?,
                };
                let slot_taken = match flag.as_str() {
                    "--nu" => nu.replace(parse_count("--nu", &value)?).is_some(),
                    "--nv" => nv.replace(parse_count("--nv", &value)?).is_some(),
                    _ => {
                        if value.is_empty() {
                            return Err("--out needs a non-empty file name.".to_string());
                        }
                        out.replace(PathBuf::from(value)).is_some()
                    }
                };
                if slot_taken {
                    return Err(format!("{flag} was given more than once."));
                }
            }
            _ => return Err(format!("unknown argument {arg:?}.")),
        }
    }
    let out = out.unwrap_or_else(|| PathBuf::from("teapot.obj"));
    Ok(Parsed::Run(Args {
        nu: nu.unwrap_or(STUDY_NU),
        nv: nv.unwrap_or(STUDY_NV),
        out,
    }))
}

fn main() -> ExitCode {
    let args = match parse_args(std::env::args().skip(1)) {
        Ok(Parsed::Run(args)) => args,
        Ok(Parsed::Help) => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        Err(sentence) => {
            eprintln!("twinray-gen-teapot: {sentence}\n{USAGE}");
            return ExitCode::from(2);
        }
    };

    let patches = match parse_bpt(BPT) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("twinray-gen-teapot: embedded scenes/teapot.bpt is malformed: {e:#}");
            return ExitCode::FAILURE;
        }
    };
    let mesh = tessellate(&patches, args.nu, args.nv);
    let header = if (args.nu, args.nv) == (STUDY_NU, STUDY_NV) {
        HEADER.to_string()
    } else {
        // Keep the header truthful for non-study resolutions.
        HEADER.replacen(
            &format!("tessellated {STUDY_NU} x {STUDY_NV} quads per patch"),
            &format!(
                "tessellated {} x {} quads per patch (NOT the study resolution)",
                args.nu, args.nv
            ),
            1,
        )
    };
    let obj = to_obj(&mesh, &header);
    if let Err(e) = std::fs::write(&args.out, &obj) {
        eprintln!(
            "twinray-gen-teapot: cannot write {}: {e}",
            args.out.display()
        );
        return ExitCode::FAILURE;
    }
    let shown = args.out.canonicalize().unwrap_or(args.out.clone());
    println!(
        "wrote {} ({} patches, {} x {} quads/patch, {} vertices, {} triangles, {} bytes)",
        shown.display(),
        patches.len(),
        args.nu,
        args.nv,
        mesh.positions.len(),
        mesh.triangles.len(),
        obj.len()
    );
    ExitCode::SUCCESS
}
