//! ASCII OFF: `[ST][C][N]OFF` header, `nv nf ne` counts, `nv` vertex lines, `nf` face lines
//! `n i0 .. i(n-1) [colour]` with 0-based indices; `#` comments and blank lines anywhere.
//!
//! Strict: a missing or malformed line is an error naming the line (a truncated file must
//! not come back as a smaller mesh). Extra values after the coordinates or after a face's
//! indices (colours, normals, texture coordinates) are ignored.

use std::io::Read;

use nalgebra::Vector3;

use super::LoadNotes;
use super::text::{ParseError, Result, TextLines, next_float, strip_comment};
use crate::mesh::TriMesh;

/// The next line with content (comment stripped), numbered from 1.
fn next_content<'a, R: Read>(lines: &'a mut TextLines<'_, R>) -> Result<Option<(usize, &'a str)>> {
    let n = loop {
        let Some((n, raw)) = lines.next_line()? else {
            return Ok(None);
        };
        if !strip_comment(raw).trim().is_empty() {
            break n;
        }
    };
    Ok(Some((n, strip_comment(lines.current()).trim())))
}

/// Parses the count line `nv nf [ne]`.
fn counts(s: &str, line: usize) -> Result<(usize, usize)> {
    let mut it = s.split_ascii_whitespace();
    let mut num = |what: &str| -> Result<usize> {
        let tok = it
            .next()
            .ok_or_else(|| ParseError::new(line, format!("missing {what} count")))?;
        tok.parse::<usize>()
            .map_err(|_| ParseError::new(line, format!("{what} count {tok:?} is not a count")))
    };
    let nv = num("vertex")?;
    let nf = num("face")?;
    if nv > u32::MAX as usize - 1 {
        return Err(ParseError::new(line, format!("{nv} vertices is too many")));
    }
    Ok((nv, nf))
}

/// Reads an OFF file a line at a time; `hint` is about its size in bytes.
pub(crate) fn parse<R: Read>(
    lines: &mut TextLines<'_, R>,
    hint: usize,
) -> Result<(TriMesh, LoadNotes)> {
    let Some((hline, header)) = next_content(lines)? else {
        return Err(ParseError::new(1, "empty file (expected an OFF header)"));
    };
    let mut words = header.split_ascii_whitespace();
    let keyword = words.next().unwrap_or("");
    let Some(prefix) = keyword.strip_suffix("OFF") else {
        return Err(ParseError::new(
            hline,
            format!("expected an OFF header, found {keyword:?}"),
        ));
    };
    // Vertex lines of ST/C/N variants carry extra values (ignored); plain OFF has exactly
    // three, which also catches a face line read as a vertex in a truncated file.
    let exact_xyz = prefix.is_empty();
    if !prefix.chars().all(|c| matches!(c, 'S' | 'T' | 'C' | 'N')) {
        return Err(ParseError::new(
            hline,
            format!("unsupported OFF variant {keyword:?} (only 3-D [ST][C][N]OFF)"),
        ));
    }
    let rest: Vec<&str> = words.collect();
    if rest.first() == Some(&"BINARY") {
        return Err(ParseError::new(hline, "binary OFF is not supported"));
    }
    let (nv, nf) = if rest.is_empty() {
        let Some((l, s)) = next_content(lines)? else {
            return Err(ParseError::new(hline + 1, "missing vertex/face counts"));
        };
        counts(s, l)?
    } else {
        counts(&rest.join(" "), hline)?
    };

    // Never trust the header for allocation: a corrupt count must not exhaust memory.
    let cap = hint / 6 + 1;
    let mut positions = Vec::with_capacity(nv.min(cap));
    for k in 0..nv {
        let Some((line, s)) = next_content(lines)? else {
            return Err(ParseError::new(
                lines.last + 1,
                format!("file ends after {k} of {nv} vertices"),
            ));
        };
        let mut it = s.split_ascii_whitespace();
        let x = next_float(&mut it, line, "vertex x")?;
        let y = next_float(&mut it, line, "vertex y")?;
        let z = next_float(&mut it, line, "vertex z")?;
        if exact_xyz && it.next().is_some() {
            let n = s.split_ascii_whitespace().count();
            return Err(ParseError::new(
                line,
                format!(
                    "vertex {} of {nv}: expected 3 coordinates, found {n} values \
                     (fewer vertices than the header says?)",
                    k + 1
                ),
            ));
        }
        positions.push(Vector3::new(x, y, z));
    }

    let mut notes = LoadNotes::default();
    let mut triangles = Vec::with_capacity(nf.min(cap));
    let mut poly: Vec<u32> = Vec::new();
    for k in 0..nf {
        let Some((line, s)) = next_content(lines)? else {
            return Err(ParseError::new(
                lines.last + 1,
                format!("file ends after {k} of {nf} faces"),
            ));
        };
        let mut it = s.split_ascii_whitespace();
        let n_tok = it.next().unwrap_or("");
        let n: usize = n_tok
            .parse()
            .map_err(|_| ParseError::new(line, format!("face size {n_tok:?} is not a count")))?;
        if n < 3 {
            return Err(ParseError::new(
                line,
                format!("face with {n} vertices (at least 3 needed)"),
            ));
        }
        poly.clear();
        for j in 0..n {
            let tok = it.next().ok_or_else(|| {
                ParseError::new(
                    line,
                    format!("face has {j} of the {n} vertex indices it announces"),
                )
            })?;
            let idx: u32 = tok.parse().ok().filter(|&i| i != u32::MAX).ok_or_else(|| {
                ParseError::new(line, format!("vertex index {tok:?} is not a valid index"))
            })?;
            poly.push(idx);
        }
        notes.polygons += 1;
        if n > 3 {
            notes.non_triangles += 1;
        }
        for j in 1..n - 1 {
            triangles.push([poly[0], poly[j], poly[j + 1]]);
        }
        notes.fan(n - 2);
    }
    Ok((TriMesh::new(positions, triangles), notes))
}

/// `OFF` with triangles; floats in shortest round-trip form (bit-exact when read back).
pub(crate) fn write(mesh: &TriMesh) -> Vec<u8> {
    use std::fmt::Write;
    let mut s = String::with_capacity(mesh.n_vertices() * 40 + mesh.n_faces() * 24);
    let _ = writeln!(s, "OFF\n{} {} 0", mesh.n_vertices(), mesh.n_faces());
    for p in &mesh.positions {
        let _ = writeln!(s, "{:?} {:?} {:?}", p.x, p.y, p.z);
    }
    for t in &mesh.triangles {
        let _ = writeln!(s, "3 {} {} {}", t[0], t[1], t[2]);
    }
    s.into_bytes()
}
