//! The files a scene names: the built-in ones embedded in the binary, any file
//! read within its size limit, OBJ meshes (every element that becomes a
//! triangle counted in one streamed pass before the text is read, each line
//! checked, then read by tobj) and Bezier-patch (.bpt) meshes
//! tessellated by `teapot` — both counted against the limits before they are made.

use crate::error::bad_input;
use crate::gpu::layout::GpuTriangle;
use crate::limits::{self, StorageLimit};
use crate::scene::check::{coord3, coord_ok, unit_normal};
use crate::scene::teapot;
use glam::DVec3;
use std::collections::HashSet;
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

/// A mesh's faces as its loader gives them: an OBJ's triangles one by one, or
/// a tessellation's shared vertices and index triples, which take a quarter of
/// the memory and are expanded only as the scene's triangles are made.
pub(super) enum Faces {
    Soup(Vec<ObjTriangle>),
    Indexed(teapot::TeapotMesh),
}

impl Faces {
    pub(super) fn len(&self) -> usize {
        match self {
            Faces::Soup(t) => t.len(),
            Faces::Indexed(m) => m.triangles.len(),
        }
    }

    /// Face `f`'s vertices and normals (None: the file gave none).
    pub(super) fn get(&self, f: usize) -> ObjTriangle {
        match self {
            Faces::Soup(t) => t[f],
            Faces::Indexed(m) => {
                let t = m.triangles[f];
                let v = |k: usize| DVec3::from_array(m.positions[t[k] as usize]);
                let n = |k: usize| DVec3::from_array(m.normals[t[k] as usize]);
                ([v(0), v(1), v(2)], Some([n(0), n(1), n(2)]))
            }
        }
    }
}

fn too_big(what: &str, max: u64) -> anyhow::Error {
    bad_input(format!(
        "{what} is larger than the limit of {max} bytes ({})",
        limits::gib(max)
    ))
}

/// A file opened for reading and its length, refused as `read_file` says when
/// it is not a regular file or is larger than `max` bytes.
fn open_file(what: &str, path: &Path, max: u64) -> anyhow::Result<(std::fs::File, u64)> {
    let cannot = |e: std::io::Error| bad_input(format!("{what} cannot be read: {}", io_reason(&e)));
    let meta = std::fs::metadata(path).map_err(cannot)?;
    if !meta.is_file() {
        return Err(bad_input(format!(
            "{what} is not a regular file (a folder, device or pipe)"
        )));
    }
    if meta.len() > max {
        return Err(too_big(what, max));
    }
    let file = std::fs::File::open(path).map_err(cannot)?;
    Ok((file, meta.len()))
}

/// A file's text, refused with a message naming `what` when it is not a regular
/// file (`/dev/zero`, a pipe, a folder), is larger than `max` bytes, or is not
/// UTF-8 (with the line and column of the first bad byte).
pub fn read_file(what: &str, path: &Path, max: u64) -> anyhow::Result<String> {
    use std::io::Read;
    let (file, len) = open_file(what, path, max)?;
    let cannot = |e: std::io::Error| bad_input(format!("{what} cannot be read: {}", io_reason(&e)));
    let too_big = || too_big(what, max);
    // Read at most max + 1 bytes: the file may grow between the check and the read.
    let mut bytes = Vec::with_capacity(len as usize);
    file.take(max + 1).read_to_end(&mut bytes).map_err(cannot)?;
    if bytes.len() as u64 > max {
        return Err(too_big());
    }
    let mut text = String::from_utf8(bytes).map_err(|e| {
        let bad = e.utf8_error().valid_up_to();
        let good = std::str::from_utf8(&e.as_bytes()[..bad]).unwrap_or("");
        let (line, col) = line_col(good, good.len());
        bad_input(format!(
            "{what}, line {line}, column {col}: not UTF-8 text (byte 0x{:02x})",
            e.as_bytes()[bad]
        ))
    })?;
    // Editors on Windows start UTF-8 files with a byte-order mark; kept, it
    // would glue itself to the first keyword (`\u{feff}v`) and hide that line.
    if text.starts_with('\u{feff}') {
        text.drain(..'\u{feff}'.len_utf8());
    }
    Ok(text)
}

/// Linux's ELOOP: std has no stable `ErrorKind` for it.
const ELOOP: i32 = 40;

/// Why a file could not be opened, in words: a loop of symbolic links is said
/// as one, not as the "does not exist" that a plain existence test reports.
pub fn io_reason(e: &std::io::Error) -> String {
    if cfg!(target_os = "linux") && e.raw_os_error() == Some(ELOOP) {
        return "it is a loop of symbolic links (ELOOP)".to_string();
    }
    if e.kind() == std::io::ErrorKind::NotFound {
        return "it does not exist".to_string();
    }
    e.to_string()
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
/// `t_at` names the tessellation's source; `before` is how many triangles the
/// scene holds already. The triangles are counted, against the triangle limit
/// and `limit`, before any is made.
pub(super) fn load_bpt(
    at: &str,
    t_at: &str,
    file: &str,
    [nu, nv]: [u32; 2],
    (before, limit): (usize, &StorageLimit),
    files: &FileSource,
) -> anyhow::Result<Faces> {
    let max = limits::MAX_TESSELLATION;
    if !(1..=max).contains(&nu) || !(1..=max).contains(&nv) {
        return Err(bad_input(format!(
            "{t_at} = {nu}x{nv}: each must be from 1 to {max}"
        )));
    }
    let text = read_text(&format!("{at}.bpt"), file, files)?;
    let patches = teapot::parse_bpt(&text)
        .map_err(|e| bad_input(format!("{at}.bpt '{file}' is not a valid patch file: {e}")))?;
    // A large patch count times a fine tessellation must be refused, not allocated.
    let n = patches
        .len()
        .saturating_mul(nu as usize * nv as usize * 2)
        .saturating_add(before);
    let what = format!(
        "{t_at} = {nu}x{nv} ({} patches of '{file}', with the triangles before them)",
        patches.len()
    );
    limits::check_count(&format!("{what}: triangles"), n, limits::MAX_TRIANGLES)?;
    limit.check(&what, "triangles", n, size_of::<GpuTriangle>())?;
    Ok(Faces::Indexed(teapot::tessellate(&patches, nu, nv)))
}

/// An OBJ mesh's triangles. The file is first streamed once (`count_obj`),
/// so that every element that becomes a triangle is counted before the text is
/// even read whole; the text is then checked line by line (`scan_obj`), so that
/// an error names its line, and tobj reads what both passed.
pub(super) fn load_obj(
    at: &str,
    file: &str,
    (before, limit): (usize, &StorageLimit),
    files: &FileSource,
) -> anyhow::Result<Faces> {
    let what = format!("{at}.obj '{file}'");
    let (total, text) = match files {
        FileSource::Builtin => {
            let text = read_text(&format!("{at}.obj"), file, files)?;
            (count_obj(&what, text.as_bytes(), before, limit)?, text)
        }
        FileSource::Dir(dir) => {
            let path = dir.join(file);
            let (f, _) = open_file(
                &format!("{at}.obj '{}'", path.display()),
                &path,
                limits::MAX_MESH_FILE_BYTES,
            )?;
            let total = count_obj(&what, std::io::BufReader::new(f), before, limit)?;
            (total, read_text(&format!("{at}.obj"), file, files)?)
        }
    };
    scan_obj(&what, &text, total)?;
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj_buf(&mut text.as_bytes(), &opts, |_| {
        // Materials come from the scene file, never from an OBJ's mtllib.
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| bad_input(format!("{what} is not a valid OBJ file: {e}")))?;
    drop(text);
    let mut out = Vec::new();
    for model in &models {
        let mesh = &model.mesh;
        // The scan has checked every index and coordinate; these guard tobj's output.
        let at3 = |list: &[f32], i: u32, kind: &str| -> anyhow::Result<DVec3> {
            let i = i as usize * 3;
            let v = list.get(i..i + 3).ok_or_else(|| {
                bad_input(format!("{what} has a face index beyond its {kind} list"))
            })?;
            Ok(DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64))
        };
        let has_normals = !mesh.normals.is_empty();
        for (f, tri) in mesh.indices.chunks(3).enumerate() {
            if tri.len() != 3 {
                return Err(bad_input(format!("{what} has an incomplete face")));
            }
            let mut p = [DVec3::ZERO; 3];
            for k in 0..3 {
                p[k] = at3(&mesh.positions, tri[k], "vertex")?;
                if !coord_ok(p[k]) {
                    coord3(
                        &format!("{what} triangle {} vertex {k}", f + 1),
                        p[k].to_array(),
                    )?;
                }
            }
            let n = if has_normals {
                let mut n = [DVec3::ZERO; 3];
                for k in 0..3 {
                    let raw = at3(&mesh.normals, tri[k], "normal")?;
                    n[k] = unit_normal(
                        &format!("{what} triangle {} normal {k}", f + 1),
                        raw.to_array(),
                    )?;
                }
                Some(n)
            } else {
                None
            };
            out.push((p, n));
        }
    }
    Ok(Faces::Soup(out))
}

/// The one pass that counts what an OBJ will become, streamed from `reader`
/// a line at a time, so that memory stays within its longest line: its `v`,
/// `vt` and `vn` elements (returned, for `scan_obj`'s index checks) and the
/// triangles of its faces (a polygon of k vertices gives k - 2), against the
/// triangle limit and `limit` as it goes. Every element tobj would turn into a
/// triangle is counted or refused here: tobj makes a face of one or two
/// vertices, and every line element (`l`), into a zero-area triangle, so 50
/// million `f 1` lines would otherwise be gigabytes before any limit saw them.
fn count_obj(
    what: &str,
    mut reader: impl std::io::BufRead,
    before: usize,
    limit: &StorageLimit,
) -> anyhow::Result<[usize; 3]> {
    let at = |line: usize, msg: &str| bad_input(format!("{what}, line {line}: {msg}"));
    let mut total = [0usize; 3];
    let mut triangles = before;
    let mut bytes = Vec::new();
    for n in 1.. {
        bytes.clear();
        let read = reader
            .read_until(b'\n', &mut bytes)
            .map_err(|e| bad_input(format!("{what} cannot be read: {}", io_reason(&e))))?;
        if read == 0 {
            break;
        }
        // A line that is not UTF-8 is `read_file`'s to refuse, with its column.
        let Ok(line) = std::str::from_utf8(&bytes) else {
            continue;
        };
        let line = if n == 1 {
            line.trim_start_matches('\u{feff}')
        } else {
            line
        };
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => total[0] += 1,
            Some("vt") => total[1] += 1,
            Some("vn") => total[2] += 1,
            Some("l") => {
                return Err(at(
                    n,
                    "a line element (`l`) is not a surface: it would become a zero-area \
                     triangle; the tracer draws faces (`f`) of three or more vertices",
                ))
            }
            Some("f") => {
                // Counted before a single index is parsed: this line may hold millions.
                let vertices = words.count();
                match vertices {
                    // tobj takes a bare `f` for a polygon and refuses it without a line number.
                    0 => return Err(at(n, "not a valid OBJ file: `f` names no vertex")),
                    1 | 2 => {
                        let named = ["", "one vertex", "two vertices"][vertices];
                        return Err(at(
                            n,
                            &format!(
                                "a face of {named} is not a surface: it would become a \
                                 zero-area triangle; a face needs three or more vertices"
                            ),
                        ));
                    }
                    _ => {}
                }
                triangles = triangles.saturating_add(vertices - 2);
                let what =
                    format!("{what}, line {n}: triangles of its faces with those before them");
                limits::check_count(&what, triangles, limits::MAX_TRIANGLES)?;
                limit.check(&what, "triangles", triangles, size_of::<GpuTriangle>())?;
            }
            _ => {}
        }
    }
    Ok(total)
}

/// Checks an OBJ text the way tobj reads it (`v`, `vt`, `vn` and `f` lines;
/// others are ignored, `l` lines are `count_obj`'s to refuse), naming the line
/// of the first fault; `total` is `count_obj`'s count of each kind of element.
fn scan_obj(what: &str, text: &str, total: [usize; 3]) -> anyhow::Result<()> {
    let at = |line: usize, msg: &str| bad_input(format!("{what}, line {line}: {msg}"));
    // tobj resolves a positive index at the end of its object, so it may name
    // a vertex further down; relative (negative) ones count back from the line.
    let mut seen = [0usize; 3];
    let mut zero_normals = HashSet::new();
    for (i, line) in text.lines().enumerate() {
        let n = i + 1;
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let p = vertex(&mut words).map_err(|e| at(n, e))?;
                if !coord_ok(p) {
                    coord3(
                        &format!("{what}, line {n}: vertex {}", seen[0] + 1),
                        p.to_array(),
                    )?;
                }
                seen[0] += 1;
            }
            Some("vt") => {
                floats::<2>(&mut words)
                    .ok_or_else(|| at(n, "not a valid OBJ file: `vt` needs two numbers"))?;
                seen[1] += 1;
            }
            Some("vn") => {
                let v = floats::<3>(&mut words)
                    .ok_or_else(|| at(n, "not a valid OBJ file: `vn` needs three numbers"))?;
                let len = DVec3::from_array(v.map(|c| c as f64)).length();
                if !(len > 1e-12 && len.is_finite()) {
                    zero_normals.insert(seen[2]);
                }
                seen[2] += 1;
            }
            Some("f") => {
                for word in words {
                    face_vertex(word, &total, &seen, &zero_normals)
                        .map_err(|e| at(n, &format!("'{word}': {e}")))?;
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// The first `N` words as f32, as tobj parses them.
fn floats<'a, const N: usize>(words: &mut impl Iterator<Item = &'a str>) -> Option<[f32; N]> {
    let mut v = [0.0; N];
    for x in &mut v {
        *x = words.next()?.parse().ok()?;
    }
    Some(v)
}

/// A `v` line's position: x y z, then nothing, a w to divide by, or an RGB colour.
fn vertex<'a>(words: &mut impl Iterator<Item = &'a str>) -> Result<DVec3, &'static str> {
    let p = floats::<3>(words).ok_or("not a valid OBJ file: `v` needs three numbers")?;
    let rest: Vec<&str> = words.take(4).collect();
    let w: f32 = match rest.len() {
        0 | 3 => 1.0,
        1 => rest[0]
            .parse()
            .ok()
            .filter(|w| *w != 0.0)
            .ok_or("not a valid OBJ file: a vertex's w must be a non-zero number")?,
        _ => {
            return Err(
                "not a valid OBJ file: `v` takes 3, 4 (with w) or 6 (with a colour) numbers",
            )
        }
    };
    Ok(DVec3::from_array(p.map(|c| (c / w) as f64)))
}

/// One `v`, `v/vt`, `v//vn` or `v/vt/vn` of a face: every index a whole number
/// that names an element the file has (1-based, or negative counting back).
fn face_vertex(
    word: &str,
    total: &[usize; 3],
    seen: &[usize; 3],
    zero_normals: &HashSet<usize>,
) -> Result<(), String> {
    const KINDS: [&str; 3] = ["vertex", "texture coordinate", "normal"];
    const PLURAL: [&str; 3] = ["vertices", "texture coordinates", "normals"];
    let parts: Vec<&str> = word.split('/').collect();
    if parts.len() > 3 || parts[0].is_empty() {
        return Err("not a valid OBJ file: give v, v/vt, v//vn or v/vt/vn".to_string());
    }
    for (k, part) in parts.iter().enumerate().filter(|(_, p)| !p.is_empty()) {
        let x: isize = part
            .parse()
            .map_err(|_| format!("not a valid OBJ file: '{part}' is not a whole number"))?;
        let index = match x {
            0 => return Err("index 0: OBJ indices start at 1".to_string()),
            x if x > 0 => x as usize - 1,
            x => seen[k].checked_sub(x.unsigned_abs()).ok_or_else(|| {
                format!("{} {x} counts back past the first {}", KINDS[k], KINDS[k])
            })?,
        };
        // tobj ignores a texture or normal index when the file has none of them.
        if index >= total[k] && (k == 0 || total[k] > 0) {
            return Err(format!(
                "{} {} is beyond the file's {} {}",
                KINDS[k],
                index + 1,
                total[k],
                PLURAL[k]
            ));
        }
        if k == 2 && zero_normals.contains(&index) {
            return Err(format!("normal {} has zero length", index + 1));
        }
    }
    Ok(())
}
