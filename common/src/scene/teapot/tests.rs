//! The tessellation against the study's counts, the mesh's orientation, and the committed OBJ.

use super::*;

const BPT: &str = include_str!("../../../../scenes/teapot.bpt");

fn reference() -> Vec<[V3; 16]> {
    parse_bpt(BPT).expect("committed scenes/teapot.bpt parses")
}

fn study_mesh() -> TeapotMesh {
    tessellate(&reference(), STUDY_NU, STUDY_NV)
}

fn tri_cross(mesh: &TeapotMesh, t: &[u32; 3]) -> V3 {
    let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
    cross(sub(b, a), sub(c, a))
}

/// Degenerate = (numerically) zero area.
fn is_degenerate(mesh: &TeapotMesh, t: &[u32; 3]) -> bool {
    length(tri_cross(mesh, t)) <= 1e-12
}

#[test]
fn parse_reference_has_32_patches() {
    let patches = reference();
    assert_eq!(patches.len(), 32);
    // First control point of the first (rim) patch, as in the file.
    assert_eq!(patches[0][0], [1.4, 0.0, 2.4]);
    assert_eq!(patches[31][15], [1.5, 0.0, 0.15]);
}

#[test]
fn parse_error_names_line() {
    let good = "1\n3 3\n".to_string() + &"0 0 0\n".repeat(16);
    assert_eq!(parse_bpt(&good).unwrap().len(), 1);

    let cases: Vec<(String, &str)> = vec![
        // Bad patch count.
        ("x\n".to_string(), "line 1:"),
        // Non-bicubic degree line.
        ("1\n2 3\n".to_string() + &"0 0 0\n".repeat(16), "line 2:"),
        // Non-numeric coordinate on line 7 (5th control point).
        (
            "1\n3 3\n".to_string() + &"0 0 0\n".repeat(4) + "0 zero 0\n" + &"0 0 0\n".repeat(11),
            "line 7:",
        ),
        // Too few fields on line 4.
        (
            "1\n3 3\n0 0 0\n0 0\n".to_string() + &"0 0 0\n".repeat(14),
            "line 4:",
        ),
        // Truncated input: 2 patches declared, 1 given (18 lines) -> EOF is line 19.
        ("2\n".to_string() + &good[2..], "line 19:"),
        // Extra content after the declared patches.
        (good.clone() + "1 2 3\n", "line 19:"),
        // Non-finite coordinate.
        (
            "1\n3 3\nNaN 0 0\n".to_string() + &"0 0 0\n".repeat(15),
            "line 3:",
        ),
    ];
    for (text, want) in cases {
        let err = parse_bpt(&text).expect_err("malformed input must be rejected");
        let msg = format!("{err:#}");
        assert!(msg.contains(want), "error {msg:?} should name {want:?}");
    }
    // Blank lines do not shift the reported line numbers.
    let text = "\n1\n\n3 3\n".to_string() + &"0 0 0\n".repeat(3) + "bad\n" + &"0 0 0\n".repeat(12);
    let msg = format!("{:#}", parse_bpt(&text).unwrap_err());
    assert!(msg.contains("line 8:"), "{msg}");
}

#[test]
fn study_tessellation_has_19200_triangles() {
    let mesh = study_mesh();
    assert_eq!(mesh.triangles.len(), 19_200);
    assert_eq!(
        mesh.triangles.len(),
        32 * STUDY_NU as usize * STUDY_NV as usize * 2
    );
    let verts = 32 * (STUDY_NU as usize + 1) * (STUDY_NV as usize + 1);
    assert_eq!(mesh.positions.len(), verts);
    assert_eq!(mesh.normals.len(), verts);
    assert!(mesh
        .triangles
        .iter()
        .flatten()
        .all(|&i| (i as usize) < verts));
    // The only degenerate triangles are those of the collapsed first rows
    // of the 4 lid-knob and 4 bottom patches: one per quad of that row.
    let degenerate = mesh
        .triangles
        .iter()
        .filter(|t| is_degenerate(&mesh, t))
        .count();
    assert_eq!(degenerate, 8 * STUDY_NU as usize);
}

#[test]
fn no_nan_and_unit_normals() {
    for (nu, nv) in [(STUDY_NU, STUDY_NV), (1, 1), (3, 7)] {
        let mesh = tessellate(&reference(), nu, nv);
        assert!(mesh.positions.iter().flatten().all(|x| x.is_finite()));
        assert!(mesh.normals.iter().flatten().all(|x| x.is_finite()));
        for n in &mesh.normals {
            assert!(
                (length(*n) - 1.0).abs() < 1e-9,
                "normal {n:?} is not unit length"
            );
        }
    }
}

#[test]
fn collapsed_rows_get_axial_normals() {
    let mesh = study_mesh();
    let mut top = 0;
    let mut bottom = 0;
    for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
        if p[0].abs() < 1e-12 && p[2].abs() < 1e-12 {
            if (p[1] - 3.15).abs() < 1e-12 {
                top += 1;
                assert!(n[1] > 0.999, "knob-top normal {n:?} should point up");
            } else if p[1].abs() < 1e-12 {
                bottom += 1;
                assert!(
                    n[1] < -0.999,
                    "bottom-centre normal {n:?} should point down"
                );
            }
        }
    }
    assert_eq!(top, 4 * (STUDY_NU as usize + 1));
    assert_eq!(bottom, 4 * (STUDY_NU as usize + 1));
}

#[test]
fn bounding_box_sanity() {
    let mesh = study_mesh();
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in &mesh.positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    // y-up: sits on y = 0, knob top at 3.15; spout tip toward +x (~3.43),
    // handle toward -x (-3.0); radius 2 (bottom of the body) in z.
    let close = |a: f64, b: f64, tol: f64| (a - b).abs() < tol;
    assert!(
        close(lo[1], 0.0, 1e-9) && close(hi[1], 3.15, 1e-9),
        "y range {lo:?} {hi:?}"
    );
    assert!(
        close(lo[0], -3.0, 1e-2) && close(hi[0], 3.434, 2e-2),
        "x range {lo:?} {hi:?}"
    );
    assert!(
        close(lo[2], -2.0, 1e-2) && close(hi[2], 2.0, 1e-2),
        "z range {lo:?} {hi:?}"
    );
    // Symmetric about the x-y plane (the data's x-z plane).
    assert!(close(lo[2], -hi[2], 1e-9));
}

#[test]
fn normals_point_outward_on_body() {
    let mesh = study_mesh();
    // Body: patches 5..=12 (1-based); away from the vertical axis.
    let per = (STUDY_NU as usize + 1) * (STUDY_NV as usize + 1);
    let mut checked = 0;
    for k in 4 * per..12 * per {
        let (p, n) = (mesh.positions[k], mesh.normals[k]);
        let radial = [p[0], 0.0, p[2]];
        assert!(
            dot(n, radial) > 0.0,
            "body vertex {p:?} has inward normal {n:?}"
        );
        checked += 1;
    }
    assert_eq!(checked, 8 * per);
    // Lid top faces up, bottom faces down (centres of lid 25..28 / bottom 29..32).
    let centre = |patch: usize| {
        let b = STUDY_NV as usize / 2;
        let a = STUDY_NU as usize / 2;
        mesh.normals[patch * per + b * (STUDY_NU as usize + 1) + a]
    };
    for patch in 24..28 {
        assert!(
            centre(patch)[1] > 0.5,
            "lid patch {} normal {:?}",
            patch + 1,
            centre(patch)
        );
    }
    for patch in 28..32 {
        assert!(
            centre(patch)[1] < -0.5,
            "bottom patch {} normal {:?}",
            patch + 1,
            centre(patch)
        );
    }
    // Handle (13..16) and spout (17..20): each patch is half a tube split at
    // the symmetry plane; its middle points away from that plane.
    for patch in 12..20 {
        let k =
            patch * per + (STUDY_NV as usize / 2) * (STUDY_NU as usize + 1) + STUDY_NU as usize / 2;
        let (p, n) = (mesh.positions[k], mesh.normals[k]);
        assert!(
            p[2] * n[2] > 0.0,
            "patch {} at {p:?}: normal {n:?} faces the symmetry plane",
            patch + 1
        );
    }
}

#[test]
fn triangle_winding_agrees_with_vertex_normals() {
    let mesh = study_mesh();
    let mut non_degenerate = 0usize;
    let mut agree = 0usize;
    for t in &mesh.triangles {
        if is_degenerate(&mesh, t) {
            continue;
        }
        non_degenerate += 1;
        let g = tri_cross(&mesh, t);
        let avg = t
            .iter()
            .fold([0.0; 3], |acc, &i| add(acc, mesh.normals[i as usize]));
        if dot(g, avg) > 0.0 {
            agree += 1;
        }
    }
    assert!(non_degenerate > 19_000);
    assert!(
        agree as f64 >= 0.99 * non_degenerate as f64,
        "only {agree} of {non_degenerate} triangles wind consistently with their normals"
    );
}

#[test]
fn reference_patches_need_no_flips_and_votes_are_decisive() {
    let patches = reference();
    let votes = escape_votes(&patches);
    for (i, &(out, inn)) in votes.iter().enumerate() {
        assert!(
            out > inn + 8,
            "patch {}: outward side escapes {out}, inward {inn}",
            i + 1
        );
    }
    assert!(inward_facing_patches(&patches).iter().all(|f| !f));
}

#[test]
fn mirrored_patch_is_reoriented() {
    // Reverse the column order of every row of a body, a handle and a spout
    // patch: same surface, inward ∂P/∂u × ∂P/∂v.
    let reference = reference();
    let mut mirrored = reference.clone();
    for patch in [5usize, 13, 18] {
        let cp = reference[patch];
        for i in 0..4 {
            for j in 0..4 {
                mirrored[patch][4 * i + j] = cp[4 * i + (3 - j)];
            }
        }
    }
    let flips = inward_facing_patches(&mirrored);
    for (i, f) in flips.iter().enumerate() {
        assert_eq!(*f, [5, 13, 18].contains(&i), "patch {}", i + 1);
    }
    // The mirrored tessellation has the same normals (u reversed) and a
    // winding consistent with them.
    let (nu, nv) = (4u32, 3u32);
    let a = tessellate(&reference, nu, nv);
    let b = tessellate(&mirrored, nu, nv);
    let per = ((nu + 1) * (nv + 1)) as usize;
    for patch in [5usize, 13, 18] {
        for bb in 0..=nv as usize {
            for aa in 0..=nu as usize {
                let ka = patch * per + bb * (nu as usize + 1) + aa;
                let kb = patch * per + bb * (nu as usize + 1) + (nu as usize - aa);
                let (na, nb) = (a.normals[ka], b.normals[kb]);
                assert!(
                    length(sub(na, nb)) < 1e-9,
                    "patch {}: {na:?} vs {nb:?}",
                    patch + 1
                );
            }
        }
    }
    for t in &b.triangles {
        if length(tri_cross(&b, t)) > 1e-12 {
            let avg = t
                .iter()
                .fold([0.0; 3], |acc, &i| add(acc, b.normals[i as usize]));
            assert!(dot(tri_cross(&b, t), avg) > 0.0);
        }
    }
}

#[test]
fn obj_format() {
    let mesh = TeapotMesh {
        positions: vec![[0.0, -0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, -0.0000001]],
        normals: vec![[0.0, 0.0, 1.0]; 3],
        triangles: vec![[0, 1, 2]],
    };
    let obj = to_obj(&mesh, "line one\n\nline three");
    assert_eq!(
        obj,
        "# line one\n#\n# line three\n# 3 vertices, 3 normals, 1 triangles\n\
         v 0.000000 0.000000 1.000000\nv 1.000000 0.000000 0.000000\nv 0.000000 1.000000 0.000000\n\
         vn 0.000000 0.000000 1.000000\nvn 0.000000 0.000000 1.000000\nvn 0.000000 0.000000 1.000000\n\
         f 1//1 2//2 3//3\n"
    );
}
