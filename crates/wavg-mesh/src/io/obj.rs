//! Wavefront OBJ: `v`, `vt` and `f` statements (continued over lines that end in `\`);
//! everything else, and `#` comments whatever their bytes, is skipped.
//!
//! Why not tobj: tobj re-indexes vertices per object (`o`/`g`) and drops unreferenced
//! ones, so a file whose objects share vertices (trimesh's `joined_tetrahedra.obj`) would
//! come out as disconnected copies and a scan's unreferenced vertices would vanish from
//! the diagnosis; it also stores f32 and reports errors without a line. Keeping the file's
//! own global indexing (positions are never split at UV seams) needs only this small
//! reader; tobj serves as a cross-check in the tests.

use std::io::Read;

use nalgebra::{Vector2, Vector3};

use super::LoadNotes;
use super::text::{ParseError, Result, TextLines, next_float, strip_comment};
use crate::mesh::{NONE, TexCoords, TriMesh};

/// One face corner: position index and optional texture index, both 0-based.
#[derive(Clone, Copy)]
struct Corner {
    v: u32,
    vt: Option<u32>,
}

/// Resolves a 1-based (or negative, relative to the current count) OBJ index.
fn resolve(tok: &str, count: usize, line: usize, what: &str) -> Result<u32> {
    let i: i64 = tok
        .parse()
        .map_err(|_| ParseError::new(line, format!("{what} index {tok:?} is not an integer")))?;
    let zero_based = if i > 0 {
        i - 1
    } else if i < 0 {
        count as i64 + i
    } else {
        return Err(ParseError::new(
            line,
            format!("{what} index 0 (OBJ is 1-based)"),
        ));
    };
    if zero_based < 0 {
        return Err(ParseError::new(
            line,
            format!("relative {what} index {i} points before the first of {count}"),
        ));
    }
    // Positive indices past the end are kept: validation names them (IndexOutOfRange).
    u32::try_from(zero_based)
        .ok()
        .filter(|&z| z != u32::MAX)
        .ok_or_else(|| ParseError::new(line, format!("{what} index {i} is too large")))
}

fn corner(tok: &str, nv: usize, nvt: usize, line: usize) -> Result<Corner> {
    let mut parts = tok.split('/');
    let v = resolve(parts.next().unwrap_or(""), nv, line, "vertex")?;
    let vt = match parts.next() {
        Some(t) if !t.is_empty() => Some(resolve(t, nvt, line, "texture")?),
        _ => None,
    };
    // The normal index (third part) is ignored; normals are recomputed from geometry.
    Ok(Corner { v, vt })
}

/// Reads an OBJ file a line at a time.
pub(crate) fn parse<R: Read>(lines: &mut TextLines<'_, R>) -> Result<(TriMesh, LoadNotes)> {
    let mut positions: Vec<Vector3<f64>> = Vec::new();
    let mut coords: Vec<Vector2<f64>> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut uv_faces: Vec<[u32; 3]> = Vec::new();
    let mut textured = 0usize;
    let mut notes = LoadNotes::default();
    let mut poly: Vec<Corner> = Vec::new();

    // A statement continued over lines ending in `\`, joined (numbered by its first line).
    let mut joined: Option<(usize, String)> = None;
    while let Some((line, raw)) = lines.next_line()? {
        let text = strip_comment(raw).trim_end();
        if let Some(head) = text.strip_suffix('\\') {
            let (_, j) = joined.get_or_insert_with(|| (line, String::new()));
            j.push_str(head);
            j.push(' ');
            continue;
        }
        let whole: String;
        let (line, text) = match joined.take() {
            None => (line, text),
            Some((first, mut j)) => {
                j.push_str(text);
                whole = j;
                (first, whole.as_str())
            }
        };
        let mut it = text.split_ascii_whitespace();
        let Some(tag) = it.next() else { continue };
        match tag {
            "v" => {
                let x = next_float(&mut it, line, "vertex x")?;
                let y = next_float(&mut it, line, "vertex y")?;
                let z = next_float(&mut it, line, "vertex z")?;
                // Optional w or r g b colour values are ignored (they may be NaN).
                positions.push(Vector3::new(x, y, z));
            }
            "vt" => {
                let u = next_float(&mut it, line, "texture u")?;
                let v = match it.next() {
                    Some(t) => super::text::float(t, line, "texture v")?,
                    None => 0.0,
                };
                coords.push(Vector2::new(u, v));
            }
            "f" => {
                poly.clear();
                for tok in it {
                    poly.push(corner(tok, positions.len(), coords.len(), line)?);
                }
                notes.polygons += 1;
                if poly.len() < 3 {
                    if poly.is_empty() {
                        return Err(ParseError::new(line, "face without vertices"));
                    }
                    notes.skipped_faces += 1;
                    continue;
                }
                if poly.len() > 3 {
                    notes.non_triangles += 1;
                }
                let has_uv = poly.iter().all(|c| c.vt.is_some());
                for k in 1..poly.len() - 1 {
                    let (a, b, c) = (poly[0], poly[k], poly[k + 1]);
                    triangles.push([a.v, b.v, c.v]);
                    if has_uv {
                        uv_faces.push([a.vt.unwrap_or(0), b.vt.unwrap_or(0), c.vt.unwrap_or(0)]);
                        textured += 1;
                    } else {
                        uv_faces.push([NONE; 3]);
                    }
                }
                notes.fan(poly.len() - 2);
            }
            _ => {} // vn, vp, o, g, s, usemtl, mtllib, l, p, curves: not needed.
        }
    }
    let uv = notes.corner_uv(
        TexCoords {
            coords,
            faces: uv_faces,
        },
        textured,
    );
    Ok((
        TriMesh {
            positions,
            triangles,
            uv,
        },
        notes,
    ))
}

/// OBJ text with `v`, optional `vt` and 1-based `f` lines. Floats use Rust's shortest
/// round-trip formatting, so reading gives back the same bits.
pub(crate) fn write(mesh: &TriMesh) -> Vec<u8> {
    use std::fmt::Write;
    let mut s = String::with_capacity(mesh.n_vertices() * 40 + mesh.n_faces() * 30);
    s.push_str("# written by wavg\n");
    for p in &mesh.positions {
        let _ = writeln!(s, "v {:?} {:?} {:?}", p.x, p.y, p.z);
    }
    match &mesh.uv {
        Some(uv) if uv.faces.len() == mesh.triangles.len() => {
            for c in &uv.coords {
                let _ = writeln!(s, "vt {:?} {:?}", c.x, c.y);
            }
            for (t, u) in mesh.triangles.iter().zip(&uv.faces) {
                let _ = writeln!(
                    s,
                    "f {}/{} {}/{} {}/{}",
                    t[0] as u64 + 1,
                    u[0] as u64 + 1,
                    t[1] as u64 + 1,
                    u[1] as u64 + 1,
                    t[2] as u64 + 1,
                    u[2] as u64 + 1
                );
            }
        }
        _ => {
            for t in &mesh.triangles {
                let _ = writeln!(
                    s,
                    "f {} {} {}",
                    t[0] as u64 + 1,
                    t[1] as u64 + 1,
                    t[2] as u64 + 1
                );
            }
        }
    }
    s.into_bytes()
}
