//! Fuzzing of the scene and mesh parsers, in-process: structured mutations of
//! the bundled scenes and their meshes (numbers swapped for extreme values,
//! arrays lengthened and shortened, lines dropped, duplicated and cut, keys and
//! names swapped), each parsed and resolved as `--scene` would, then turned into
//! the GPU buffers. Properties: no panic; every refusal is bad input (exit 2)
//! with a message naming the scene; every accepted scene is finite in f32.
//!
//! The choices come from `arbitrary::Unstructured` over pseudo-random bytes, so
//! a failure is reproduced from its seed. In the suite it runs for 30 s;
//! `TWINRAY_FUZZ_SECONDS=3600` runs it for an hour, `TWINRAY_FUZZ_SEED=N` picks
//! the seed (README, "Testing").

use arbitrary::Unstructured;
use std::time::{Duration, Instant};
use twinray_common::error::exit_code_of;
use twinray_common::gpu::layout::binding;
use twinray_common::gpu::upload::GpuScene;
use twinray_common::plan::build_bvh;
use twinray_common::scene::accel::Accel;
use twinray_common::scene::load::BUILTIN_SCENES;
use twinray_common::scene::Scene;
use twinray_tests::repo::{files_under, read, root, text};

/// Values that break parsers and f32 conversions: zero, signed zero, overflow
/// in f32 and f64, underflow, NaN, the edges of u32, and plain ones.
const NUMBERS: &[&str] = &[
    "0",
    "-0.0",
    "1",
    "-1",
    "0.5",
    "17",
    "65536",
    "1e300",
    "-1e300",
    "1e-300",
    "1e39",
    "3.4e38",
    "1e-45",
    "nan",
    "inf",
    "-inf",
    "4294967295",
    "4294967296",
    "4000000000",
    "18446744073709551616",
    "4e18",
    "1e19",
    "2.5",
    "100",
];

/// Text that breaks structure.
const FRAGMENTS: &[&str] = &[
    "[",
    "]",
    "\"",
    "=",
    "\n",
    "{",
    "}",
    ",",
    "[[",
    "]]",
    "#",
    "'",
    "\\",
    " = [1.0, 2.0, 3.0, 4.0]",
    "\n[[spheres]]\n",
    "\n[extra_spheres]\n",
    "\n[[meshes]]\nobj = \"cube.obj\"\n",
];

const KEYS: &[&str] = &[
    "eye",
    "look_at",
    "up",
    "fov_y",
    "background",
    "max_depth",
    "min_weight",
    "epsilon",
    "offset",
    "triangle",
    "sphere",
    "name",
    "ambient",
    "diffuse",
    "specular",
    "shininess",
    "reflectivity",
    "transparency",
    "ior",
    "position",
    "color",
    "center",
    "radius",
    "material",
    "vertices",
    "normals",
    "corners",
    "obj",
    "bpt",
    "tessellation",
    "scale",
    "rotate_y",
    "translate",
    "smooth",
    "count",
    "glow",
];

const OVERRIDES: &[(&str, &str)] = &[
    ("max_depth", "0"),
    ("max_depth", "16"),
    ("epsilon", "1e-300"),
    ("fov_y", "179.9"),
    ("min_weight", "nan"),
    ("extra_spheres", "4000000000"),
    ("extra_spheres", "3"),
    ("tessellation", "401x2"),
    ("tessellation", "2x3"),
    ("offset", "ulp"),
    ("triangle", "watertight"),
];

/// (name, text, folder relative to the scratch root) of every bundled scene.
fn seeds() -> Vec<(String, String, &'static str)> {
    let mut v: Vec<_> = BUILTIN_SCENES
        .iter()
        .map(|(n, t)| (n.to_string(), t.to_string(), "scenes"))
        .collect();
    for p in files_under(&root().join("scenes/hard"), &["toml"]) {
        let name = p.file_stem().unwrap().to_string_lossy().to_string();
        v.push((name, read(&p), "scenes/hard"));
    }
    v
}

/// The meshes the seeds name, by path relative to the scratch root.
fn meshes() -> Vec<(&'static str, String)> {
    [
        "scenes/cube.obj",
        "scenes/teapot.bpt",
        "scenes/hard/icosphere.obj",
    ]
    .iter()
    .map(|p| (*p, text(p)))
    .collect()
}

/// Byte ranges of the number tokens in `text`.
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut v = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts =
            b[i].is_ascii_digit() || (b[i] == b'-' && i + 1 < b.len() && b[i + 1].is_ascii_digit());
        let after_word = i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_');
        if starts && !after_word {
            let s = i;
            i += 1;
            while i < b.len()
                && (b[i].is_ascii_alphanumeric() || b[i] == b'.' || b[i] == b'-' || b[i] == b'+')
            {
                i += 1;
            }
            v.push((s, i));
        } else {
            i += 1;
        }
    }
    v
}

fn lines_of(text: &str) -> Vec<&str> {
    text.split_inclusive('\n').collect()
}

/// One structured mutation of `text`; most keep the TOML parseable, so that
/// resolve and the mesh loaders see the damage, not only the TOML parser.
fn mutate(u: &mut Unstructured, text: &str) -> arbitrary::Result<String> {
    let mut s = text.to_string();
    match u.int_in_range(0..=8)? {
        0 | 1 => {
            let nums = numbers(&s);
            if let Some(&(a, b)) = (!nums.is_empty()).then(|| u.choose(&nums)).transpose()? {
                s.replace_range(a..b, u.choose(NUMBERS)?);
            }
        }
        2 => {
            // An extra element before a closing bracket.
            let closes: Vec<usize> = s.match_indices(']').map(|(i, _)| i).collect();
            if !closes.is_empty() {
                let at = *u.choose(&closes)?;
                let extra = *u.choose(&[", 1.0", ", [1.0, 1.0, 1.0]", ", 0"])?;
                s.insert_str(at, extra);
            }
        }
        3 => {
            // The last element of an array dropped.
            let commas: Vec<usize> = s.match_indices(',').map(|(i, _)| i).collect();
            if !commas.is_empty() {
                let at = *u.choose(&commas)?;
                if let Some(end) = s[at..].find(']') {
                    s.replace_range(at..at + end, "");
                }
            }
        }
        4 => {
            let lines = lines_of(&s);
            if !lines.is_empty() {
                let i = u.choose_index(lines.len())?;
                let mut v: Vec<&str> = lines.clone();
                if u.arbitrary()? {
                    v.remove(i);
                } else {
                    v.insert(i, lines[i]);
                }
                s = v.concat();
            }
        }
        5 => {
            let keys: Vec<(usize, usize)> = s
                .match_indices(" = ")
                .filter_map(|(i, _)| {
                    let start = s[..i].rfind('\n').map_or(0, |n| n + 1);
                    (start < i).then_some((start, i))
                })
                .collect();
            if !keys.is_empty() {
                let (a, b) = *u.choose(&keys)?;
                s.replace_range(a..b, u.choose(KEYS)?);
            }
        }
        6 => {
            let at = u.choose_index(s.len() + 1)?;
            if s.is_char_boundary(at) {
                s.insert_str(at, u.choose(FRAGMENTS)?);
            }
        }
        7 => {
            let at = u.choose_index(s.len() + 1)?;
            if s.is_char_boundary(at) {
                s.truncate(at);
            }
        }
        _ => {
            // A string value swapped: material names, numerics choices, mesh files.
            let quoted: Vec<(usize, usize)> = s
                .match_indices('"')
                .map(|(i, _)| i)
                .collect::<Vec<_>>()
                .chunks_exact(2)
                .map(|p| (p[0] + 1, p[1]))
                .collect();
            if !quoted.is_empty() {
                let (a, b) = *u.choose(&quoted)?;
                let with = *u.choose(&[
                    "",
                    "x",
                    "cube.obj",
                    "teapot.bpt",
                    "../cube.obj",
                    "/dev/zero",
                    "ulp",
                    "m",
                ])?;
                s.replace_range(a..b, with);
            }
        }
    }
    Ok(s)
}

/// Mutates mesh text like scene text, plus face indices out of range.
fn mutate_mesh(u: &mut Unstructured, text: &str) -> arbitrary::Result<String> {
    let mut s = text.to_string();
    for _ in 0..u.int_in_range(1..=3)? {
        s = if u.ratio(1, 4)? {
            let mut out = s.clone();
            let faces: Vec<usize> = s.match_indices("\nf ").map(|(i, _)| i + 3).collect();
            if !faces.is_empty() {
                let at = *u.choose(&faces)?;
                let idx = *u.choose(&[
                    "0",
                    "-1",
                    "-99999",
                    "4294967296",
                    "99999999",
                    "1/1/1",
                    "1/1/1/1",
                    "1//",
                    "/1",
                    "\u{feff}",
                ])?;
                out.insert_str(at, &format!("{idx} "));
            }
            out
        } else {
            mutate(u, &s)?
        };
    }
    Ok(s)
}

/// What the GPU receives must be finite, and positive where zero is refused.
fn check_accepted(scene: &Scene, input: &str) {
    let f = |v: f64| (v as f32).is_finite();
    let v = |x: glam::DVec3| x.as_vec3().is_finite();
    let ok = v(scene.camera.eye)
        && v(scene.background)
        && scene.epsilon as f32 > 0.0
        && scene.materials.iter().all(|m| {
            v(m.ambient) && v(m.diffuse) && v(m.specular) && f(m.shininess) && m.ior as f32 > 0.0
        })
        && scene.lights.iter().all(|l| v(l.position) && v(l.color))
        && scene
            .spheres
            .iter()
            .all(|s| v(s.center) && s.radius as f32 > 0.0)
        && scene
            .triangles
            .iter()
            .all(|t| t.p.iter().chain(&t.n).all(|p| v(*p)));
    assert!(ok, "an accepted scene holds a value that is not finite (or zero where refused) in f32:\n{input}");
}

#[test]
fn mutated_scenes_and_meshes_never_panic() {
    let seconds: u64 = std::env::var("TWINRAY_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(30);
    let seed: u64 = std::env::var("TWINRAY_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0x7715_2026);
    let root = twinray_tests::scratch("fuzz");
    std::fs::create_dir_all(root.join("scenes/hard")).unwrap();
    let seeds = seeds();
    let meshes = meshes();
    let deadline = Instant::now() + Duration::from_secs(seconds);
    let (mut runs, mut accepted) = (0u64, 0u64);
    let mut state = seed | 1;
    let mut bytes = vec![0u8; 4096];
    while Instant::now() < deadline {
        // xorshift64*: the pseudo-random bytes the choices are drawn from.
        for b in bytes.iter_mut() {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            *b = (state.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 56) as u8;
        }
        let mut u = Unstructured::new(&bytes);
        let (name, text, folder) = u.choose(&seeds).unwrap().clone();
        let mut scene_text = text.clone();
        for _ in 0..u.int_in_range(1..=4u8).unwrap_or(1) {
            scene_text = mutate(&mut u, &scene_text).unwrap_or(scene_text);
        }
        // The meshes: untouched, or mutated, for each run.
        let mut mesh_texts = Vec::new();
        for (path, original) in &meshes {
            let t = if u.ratio(1, 3).unwrap_or(false) {
                mutate_mesh(&mut u, original).unwrap_or_else(|_| original.clone())
            } else {
                original.clone()
            };
            std::fs::write(root.join(path), &t).unwrap();
            mesh_texts.push((path, t));
        }
        let overrides: Vec<(String, String)> = if u.ratio(1, 5).unwrap_or(false) {
            let (k, v) = u.choose(OVERRIDES).unwrap();
            vec![(k.to_string(), v.to_string())]
        } else {
            vec![]
        };
        let dir = root.join(folder);
        let result = std::panic::catch_unwind(|| {
            let scene = Scene::from_toml(&name, &scene_text, &dir, &overrides);
            if let Ok(s) = &scene {
                check_accepted(s, &scene_text);
                // As a run with --accel auto prepares it: the BVH where it pays.
                let bvh = Accel::Auto.wants_bvh(s).then(|| build_bvh(s));
                let gpu = GpuScene::new(s, bvh.as_ref(), 8, 8);
                for b in binding::STORAGE {
                    gpu.storage_vec(b);
                }
            }
            scene.map(|_| ())
        });
        runs += 1;
        match result {
            Ok(Ok(())) => accepted += 1,
            Ok(Err(e)) => {
                let msg = format!("{e:#}");
                assert_eq!(
                    exit_code_of(&e),
                    2,
                    "a refusal that is not bad input: {msg}\ninput:\n{scene_text}"
                );
                assert!(
                    msg.contains(&format!("'{name}'")) || msg.contains("--set"),
                    "the message names neither the scene nor --set: {msg}"
                );
                // The OBJ scan checks every line tobj reads, so no fault of a
                // mesh's text reaches tobj's own messages, which name no line.
                let unlined = [
                    "is not a valid OBJ file",
                    "beyond its",
                    "incomplete face",
                    "' triangle ",
                ];
                assert!(
                    !unlined.iter().any(|m| msg.contains(m)),
                    "an OBJ fault without its line: {msg}"
                );
            }
            Err(_) => {
                let keep = root.join("panic");
                let _ = std::fs::create_dir_all(&keep);
                std::fs::write(keep.join("scene.toml"), &scene_text).unwrap();
                for (path, t) in &mesh_texts {
                    std::fs::write(keep.join(path.replace('/', "_")), t).unwrap();
                }
                panic!(
                    "run {runs} (seed {seed}) panicked on a mutation of '{name}' with overrides {overrides:?}; inputs kept in {}",
                    keep.display()
                );
            }
        }
    }
    let _ = std::fs::remove_dir_all(&root);
    eprintln!("fuzz: {runs} runs in {seconds} s, {accepted} accepted, seed {seed}");
    assert!(runs > 100, "only {runs} runs in {seconds} s");
    assert!(accepted > 0 && accepted < runs, "every input was accepted or every input refused ({accepted} of {runs}): the mutations test nothing");
}
