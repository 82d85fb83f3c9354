//! The files a scene names: the built-in ones embedded in the binary, any file
//! read within its size limit, OBJ meshes through tobj and Bezier-patch (.bpt)
//! meshes tessellated by `teapot`.

use crate::error::bad_input;
use crate::limits;
use crate::scene::check::{coord3, coord_ok, unit_normal};
use crate::scene::teapot;
use glam::DVec3;
use std::path::{Path, PathBuf};

/// Files the built-in scenes name, embedded in the binary.
const BUILTIN_FILES: &[(&str, &str)] = &[
    ("cube.obj", include_str!("../../../scenes/cube.obj")),
    ("teapot.bpt", include_str!("../../../scenes/teapot.bpt")),
];

/// Where OBJ files named by a scene are found.
pub enum FileSource {
    Builtin,
    Dir(PathBuf),
}

/// The 1-based line and column of byte `offset`, for error messages.
pub(super) fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before
        .rsplit('\n')
        .next()
        .map(|l| l.chars().count())
        .unwrap_or(0)
        + 1;
    (line, col)
}

pub(super) type ObjTriangle = ([DVec3; 3], Option<[DVec3; 3]>);

/// A file's text, refused with a message naming `what` when it is not a regular
/// file (`/dev/zero`, a pipe, a folder), is larger than `max` bytes, or is not
/// UTF-8 (with the line and column of the first bad byte).
pub fn read_file(what: &str, path: &Path, max: u64) -> anyhow::Result<String> {
    use std::io::Read;
    let cannot = |e: std::io::Error| bad_input(format!("{what} cannot be read: {e}"));
    let meta = std::fs::metadata(path).map_err(cannot)?;
    if !meta.is_file() {
        return Err(bad_input(format!(
            "{what} is not a regular file (a folder, device or pipe)"
        )));
    }
    let too_big = || {
        bad_input(format!(
            "{what} is larger than the limit of {max} bytes ({})",
            limits::gib(max)
        ))
    };
    if meta.len() > max {
        return Err(too_big());
    }
    // Read at most max + 1 bytes: the file may grow between the check and the read.
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    std::fs::File::open(path)
        .and_then(|f| f.take(max + 1).read_to_end(&mut bytes))
        .map_err(cannot)?;
    if bytes.len() as u64 > max {
        return Err(too_big());
    }
    String::from_utf8(bytes).map_err(|e| {
        let bad = e.utf8_error().valid_up_to();
        let good = std::str::from_utf8(&e.as_bytes()[..bad]).unwrap_or("");
        let (line, col) = line_col(good, good.len());
        bad_input(format!(
            "{what}, line {line}, column {col}: not UTF-8 text (byte 0x{:02x})",
            e.as_bytes()[bad]
        ))
    })
}

/// The text of a file a scene names: built in, or next to the scene file.
fn read_text(what: &str, file: &str, files: &FileSource) -> anyhow::Result<String> {
    match files {
        FileSource::Builtin => BUILTIN_FILES
            .iter()
            .find(|(n, _)| *n == file)
            .map(|(_, t)| t.to_string())
            .ok_or_else(|| bad_input(format!("{what} '{file}' is not a built-in file"))),
        FileSource::Dir(dir) => {
            let path = dir.join(file);
            read_file(
                &format!("{what} '{}'", path.display()),
                &path,
                limits::MAX_MESH_FILE_BYTES,
            )
        }
    }
}

/// Newell-style Bezier patches, tessellated as twinray-gen-teapot does.
/// `t_at` names the tessellation's source; `room` is how many triangles may still be added.
pub(super) fn load_bpt(
    at: &str,
    t_at: &str,
    file: &str,
    [nu, nv]: [u32; 2],
    room: usize,
    files: &FileSource,
) -> anyhow::Result<Vec<ObjTriangle>> {
    let max = limits::MAX_TESSELLATION;
    if !(1..=max).contains(&nu) || !(1..=max).contains(&nv) {
        return Err(bad_input(format!(
            "{t_at} = {nu}x{nv}: each must be from 1 to {max}"
        )));
    }
    let text = read_text(&format!("{at}.bpt"), file, files)?;
    let patches = teapot::parse_bpt(&text)
        .map_err(|e| bad_input(format!("{at}.bpt '{file}' is not a valid patch file: {e}")))?;
    // Counted before tessellating: a large patch count times a fine
    // tessellation must be refused, not allocated.
    let n = patches.len().saturating_mul(nu as usize * nv as usize * 2);
    limits::check_count(
        &format!(
            "{at}: triangles of '{file}' ({} patches at {t_at} = {nu}x{nv}) with those before it",
            patches.len()
        ),
        n,
        room,
    )?;
    let mesh = teapot::tessellate(&patches, nu, nv);
    let v = |i: u32| DVec3::from_array(mesh.positions[i as usize]);
    let n = |i: u32| DVec3::from_array(mesh.normals[i as usize]);
    Ok(mesh
        .triangles
        .iter()
        .map(|t| {
            (
                [v(t[0]), v(t[1]), v(t[2])],
                Some([n(t[0]), n(t[1]), n(t[2])]),
            )
        })
        .collect())
}

pub(super) fn load_obj(
    at: &str,
    file: &str,
    files: &FileSource,
) -> anyhow::Result<Vec<ObjTriangle>> {
    let text = read_text(&format!("{at}.obj"), file, files)?;
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj_buf(&mut text.as_bytes(), &opts, |_| {
        // Materials come from the scene file, never from an OBJ's mtllib.
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| bad_input(format!("{at}.obj '{file}' is not a valid OBJ file: {e}")))?;
    let mut out = Vec::new();
    for model in &models {
        let mesh = &model.mesh;
        let pos = |i: u32| -> anyhow::Result<DVec3> {
            let i = i as usize * 3;
            let v = mesh.positions.get(i..i + 3).ok_or_else(|| {
                bad_input(format!(
                    "{at}.obj '{file}' has a face index beyond its vertex list"
                ))
            })?;
            let p = DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
            if coord_ok(p) {
                return Ok(p);
            }
            coord3(
                &format!("{at}.obj '{file}' vertex {}", i / 3 + 1),
                p.to_array(),
            )
        };
        let has_normals = !mesh.normals.is_empty();
        for (f, tri) in mesh.indices.chunks(3).enumerate() {
            if tri.len() != 3 {
                return Err(bad_input(format!(
                    "{at}.obj '{file}' has an incomplete face"
                )));
            }
            let p = [pos(tri[0])?, pos(tri[1])?, pos(tri[2])?];
            let n = if has_normals {
                let mut n = [DVec3::ZERO; 3];
                for k in 0..3 {
                    let i = tri[k] as usize * 3;
                    let v = mesh.normals.get(i..i + 3).ok_or_else(|| {
                        bad_input(format!(
                            "{at}.obj '{file}' has a normal index beyond its normal list"
                        ))
                    })?;
                    let raw = DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
                    let len = raw.length();
                    n[k] = if len > 1e-12 && len.is_finite() {
                        raw / len
                    } else {
                        unit_normal(
                            &format!("{at}.obj '{file}' face {} normal {k}", f + 1),
                            raw.to_array(),
                        )?
                    };
                }
                Some(n)
            } else {
                None
            };
            out.push((p, n));
        }
    }
    Ok(out)
}
