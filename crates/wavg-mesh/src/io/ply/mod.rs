//! PLY (ASCII, binary little and big endian), read by its declared layout.
//!
//! Reads `vertex` elements with scalar `x y z` (any numeric type) and `face` elements with
//! a `vertex_indices` (or `vertex_index`) list. Texture coordinates are taken from a
//! per-face `texcoord` list (`u0 v0 u1 v1 ...`, the MeshLab convention) or from per-vertex
//! `u v` / `s t` / `texture_u texture_v` properties. Other elements and properties are
//! read past. Binary records are decoded in place from large blocks (`fast.rs` for
//! vertices of scalars and triangle faces, `records.rs` for any layout), ASCII records
//! a line at a time, so neither holds the file beside the mesh.

mod fast;
mod header;
mod records;
mod write;

use std::io::Read;

use nalgebra::{Vector2, Vector3};

use super::LoadNotes;
use super::source::Source;
use super::text::{ParseError, Result};
use crate::mesh::{TexCoords, TriMesh};
use header::{Element, Encoding, Kind};
use records::{Num, Records};

pub(crate) use write::write;

/// What the `vertex` and `face` elements gave, as it is gathered.
#[derive(Default)]
struct Gathered {
    positions: Vec<Vector3<f64>>,
    vertex_uv: Option<Vec<Vector2<f64>>>,
    triangles: Vec<[u32; 3]>,
    corner_uv: Vec<Vector2<f64>>,
    /// Whether every face so far had a `texcoord` list matching its corners.
    corner_uv_ok: bool,
    notes: LoadNotes,
}

impl Gathered {
    /// Records polygon `i` (`poly`'s indices, `tc` its texture coordinates if the file has
    /// them), fan-triangulated.
    fn polygon(&mut self, i: usize, poly: &[i64], tc: Option<&[f64]>) -> Result<()> {
        let bad = || {
            ParseError::new(
                0,
                format!("PLY: face {i} has a negative or too large index"),
            )
        };
        let index = |x: i64| {
            u32::try_from(x)
                .ok()
                .filter(|&x| x != u32::MAX)
                .ok_or_else(bad)
        };
        self.notes.polygons += 1;
        if poly.len() < 3 {
            // Checked like the others, then skipped.
            for &x in poly {
                index(x)?;
            }
            self.notes.skipped_faces += 1;
            return Ok(());
        }
        if poly.len() > 3 {
            self.notes.non_triangles += 1;
        }
        let tc = tc.filter(|t| t.len() == 2 * poly.len());
        if self.corner_uv_ok && tc.is_none() {
            self.corner_uv_ok = false;
            self.notes.uv_dropped = true;
            self.corner_uv = Vec::new();
        }
        let first = index(poly[0])?;
        for j in 1..poly.len() - 1 {
            self.triangles
                .push([first, index(poly[j])?, index(poly[j + 1])?]);
            if let (true, Some(t)) = (self.corner_uv_ok, tc) {
                for c in [0, j, j + 1] {
                    self.corner_uv.push(Vector2::new(t[2 * c], t[2 * c + 1]));
                }
            }
        }
        self.notes.fan(poly.len() - 2);
        Ok(())
    }

    fn finish(self) -> (TriMesh, LoadNotes) {
        let Gathered {
            positions,
            vertex_uv,
            triangles,
            corner_uv,
            corner_uv_ok,
            notes,
        } = self;
        let uv = if corner_uv_ok && !triangles.is_empty() {
            let faces = (0..triangles.len() as u32)
                .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
                .collect();
            Some(TexCoords {
                coords: corner_uv,
                faces,
            })
        } else {
            vertex_uv.map(|coords| TexCoords {
                coords,
                faces: triangles.clone(),
            })
        };
        let mesh = TriMesh {
            positions,
            triangles,
            uv,
        };
        (mesh, notes)
    }
}

/// Reads a PLY file from `src`; `hint` is about the data's size in bytes (capacities
/// are never taken from the header alone, whose counts may lie).
pub(crate) fn parse<R: Read>(src: &mut Source<R>, hint: usize) -> Result<(TriMesh, LoadNotes)> {
    let header = header::read(src)?;
    // An element without properties takes no bytes per record in binary files, so no
    // end of data stops its count: bound it by the file's length instead.
    if let Some(def) = (header.elements.iter()).find(|d| d.props.is_empty() && d.count > hint) {
        return Err(ParseError::new(
            0,
            format!(
                "PLY: element '{}' has no properties but declares {} records",
                def.name, def.count
            ),
        ));
    }
    let mut out = Gathered::default();
    let mut rd = Records::new(src, header.encoding, header.lines);
    for el in &header.elements {
        match el.name.as_str() {
            "vertex" => vertices(&mut rd, el, hint, &mut out)?,
            "face" => faces(&mut rd, el, hint, &mut out)?,
            _ => rd.skip(el)?,
        }
    }
    Ok(out.finish())
}

/// Capacity for `count` records of at least `min_bytes` each in `hint` bytes.
fn capacity(count: usize, hint: usize, min_bytes: usize) -> usize {
    count.min(hint / min_bytes.max(1) + 1)
}

/// What each of a vertex's properties is for.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Role {
    Coord(usize),
    Uv(usize),
    Unused,
}

fn vertices<R: Read>(
    rd: &mut Records<'_, R>,
    el: &Element,
    hint: usize,
    out: &mut Gathered,
) -> Result<()> {
    let mut roles = vec![Role::Unused; el.props.len()];
    for (k, name) in ["x", "y", "z"].into_iter().enumerate() {
        match el.scalar(name) {
            Some(p) => roles[p] = Role::Coord(k),
            None if el.count > 0 => {
                return Err(rd.err(format!("vertex 0 has no numeric {name}")));
            }
            None => {}
        }
    }
    // The first complete pair of texture coordinates decides.
    let pair = [("u", "v"), ("s", "t"), ("texture_u", "texture_v")]
        .into_iter()
        .find_map(|(u, v)| Some((el.scalar(u)?, el.scalar(v)?)));
    if let Some((u, v)) = pair {
        (roles[u], roles[v]) = (Role::Uv(0), Role::Uv(1));
    }
    let n = capacity(el.count, hint, el.fixed_size().unwrap_or(1));
    out.positions.reserve_exact(n);
    if pair.is_some() {
        out.vertex_uv = Some(Vec::with_capacity(n));
    }
    if rd.encoding != Encoding::Ascii && el.fixed_size().is_some() {
        return fast::vertices(rd, el, &roles, out);
    }
    let (mut xyz, mut uv) = ([0.0; 3], [0.0; 2]);
    for i in 0..el.count {
        rd.record(el, i, |k, v: Num| {
            match roles[k] {
                Role::Coord(c) => xyz[c] = v.as_f64(),
                Role::Uv(c) => uv[c] = v.as_f64(),
                Role::Unused => {}
            }
            Ok(())
        })?;
        out.positions.push(Vector3::from(xyz));
        if let Some(uvs) = out.vertex_uv.as_mut() {
            uvs.push(Vector2::from(uv));
        }
    }
    Ok(())
}

fn faces<R: Read>(
    rd: &mut Records<'_, R>,
    el: &Element,
    hint: usize,
    out: &mut Gathered,
) -> Result<()> {
    let list_named = |name: &str| {
        (el.props.iter()).rposition(|p| p.name == name && matches!(p.kind, Kind::List { .. }))
    };
    let named = (el.props.iter()).rposition(|p| p.name == "vertex_indices");
    let named = named.or_else(|| (el.props.iter()).rposition(|p| p.name == "vertex_index"));
    let indices =
        named.filter(|&k| matches!(el.props[k].kind, Kind::List { item, .. } if !item.is_float()));
    let Some(indices) = indices else {
        if el.count > 0 {
            return Err(rd.err("face 0 has no integer vertex_indices list".into()));
        }
        return Ok(());
    };
    let texcoord = list_named("texcoord")
        .filter(|&k| matches!(el.props[k].kind, Kind::List { item, .. } if item.is_float()));
    out.corner_uv_ok = texcoord.is_some() && el.count > 0;
    let n = capacity(el.count, hint, 1 + 3);
    out.triangles.reserve_exact(n);
    out.notes.polygon_of.reserve_exact(n);
    let mut start = 0;
    if rd.encoding != Encoding::Ascii {
        start = fast::triangles(rd, el, out)?;
    }
    let (mut poly, mut tc) = (Vec::<i64>::new(), Vec::<f64>::new());
    for i in start..el.count {
        poly.clear();
        tc.clear();
        rd.record(el, i, |k, v| {
            if k == indices {
                // The header check above made the items integers.
                if let Num::Int(x) = v {
                    poly.push(x);
                }
            } else if Some(k) == texcoord {
                tc.push(v.as_f64());
            }
            Ok(())
        })?;
        let tc = texcoord.map(|_| tc.as_slice());
        out.polygon(i, &poly, tc)?;
    }
    Ok(())
}
#[cfg(test)]
mod tests {
    use super::*;

    fn parse(bytes: &[u8]) -> Result<(TriMesh, LoadNotes)> {
        super::parse(&mut Source::new(bytes), bytes.len())
    }

    /// Big-endian binary with mixed coordinate types, an ignored colour, the older
    /// `vertex_index` name with `uchar` counts, a quad, and an element after the faces.
    #[test]
    fn binary_big_endian_with_mixed_types_and_extra_elements() {
        let mut b = b"ply\nformat binary_big_endian 1.0\nelement vertex 4\nproperty float x\n\
property uchar red\nproperty double y\nproperty int z\nelement face 1\n\
property list uchar int vertex_index\nelement edge 1\nproperty int vertex1\n\
property int vertex2\nend_header\n"
            .to_vec();
        for (x, y, z) in [
            (0.5f32, 0.0f64, 0i32),
            (1.0, 0.0, 1),
            (1.0, 1.0, 2),
            (0.0, 1.0, 3),
        ] {
            b.extend(x.to_be_bytes());
            b.push(200);
            b.extend(y.to_be_bytes());
            b.extend(z.to_be_bytes());
        }
        b.push(4);
        for i in [0i32, 1, 2, 3] {
            b.extend(i.to_be_bytes());
        }
        b.extend(0i32.to_be_bytes());
        b.extend(2i32.to_be_bytes());
        let (m, notes) = parse(&b).unwrap();
        assert_eq!(m.positions[0], Vector3::new(0.5, 0.0, 0.0));
        assert_eq!(m.positions[3], Vector3::new(0.0, 1.0, 3.0));
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!((notes.polygons, notes.non_triangles), (1, 1));
        assert_eq!(notes.polygon_of, vec![0, 0]);
        assert!(m.uv.is_none());
        // Cut inside the faces: a parse error, not a mesh.
        assert!(parse(&b[..b.len() - 12]).is_err());
    }

    #[test]
    fn an_element_without_properties_cannot_declare_more_records_than_bytes() {
        // Found by the fuzzer: no property, so no record consumes data and only the count
        // bounded the work (an out-of-memory).
        let mut file = b"ply\nformat binary_little_endian 1.0\nelement vertex 888888888880\n\
                         end_header\n"
            .to_vec();
        file.extend_from_slice(&[0u8; 64]);
        let err = parse(&file).unwrap_err();
        assert!(err.message.contains("no properties"), "{}", err.message);
        // A handful of such records is fine (they are skipped).
        let ok = b"ply\nformat ascii 1.0\nelement extra 2\nelement vertex 3\nproperty float x\n\
                   property float y\nproperty float z\nelement face 1\n\
                   property list uchar int vertex_indices\nend_header\n\n\n0 0 0\n1 0 0\n0 1 0\n\
                   3 0 1 2\n";
        assert_eq!(parse(ok).unwrap().0.n_faces(), 1);
    }

    /// What `write` produces reads back the same, texture coordinates included.
    #[test]
    fn written_binary_reads_back() {
        let positions = vec![
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1.0, 0.0, 0.25),
            Vector3::new(0.0, 1.0, -0.5),
            Vector3::new(1.0, 1.0, 1e-9),
        ];
        let triangles = vec![[0, 1, 2], [2, 1, 3]];
        let uv = TexCoords {
            coords: (0..6).map(|i| Vector2::new(i as f64 / 8.0, 0.5)).collect(),
            faces: vec![[0, 1, 2], [3, 4, 5]],
        };
        let mesh = TriMesh {
            positions,
            triangles,
            uv: Some(uv),
        };
        let (back, _) = parse(&write(&mesh).unwrap()).unwrap();
        assert_eq!(back.positions, mesh.positions);
        assert_eq!(back.triangles, mesh.triangles);
        let (a, b) = (back.uv.unwrap(), mesh.uv.unwrap());
        for (fa, fb) in a.faces.iter().zip(&b.faces) {
            for k in 0..3 {
                assert_eq!(a.coords[fa[k] as usize], b.coords[fb[k] as usize]);
            }
        }
    }

    /// `vertex_indices` wins over `vertex_index` in whichever order they come; vertex
    /// texture coordinates named `s t` are read.
    #[test]
    fn index_list_names_and_vertex_st() {
        for (first, second) in [
            ("vertex_indices", "vertex_index"),
            ("vertex_index", "vertex_indices"),
        ] {
            let text = format!(
                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
property float z\nproperty float s\nproperty float t\nelement face 1\n\
property list uchar int {first}\nproperty list uchar int {second}\nend_header\n\
0 0 0 0 0\n1 0 0 1 0\n0 1 0 0 1\n"
            );
            let (a, b) = if first == "vertex_indices" {
                ("0 1 2", "2 1 0")
            } else {
                ("2 1 0", "0 1 2")
            };
            let text = format!("{text}3 {a} 3 {b}\n");
            let (m, _) = parse(text.as_bytes()).unwrap();
            assert_eq!(m.triangles, vec![[0, 1, 2]], "{first} then {second}");
            let uv = m.uv.unwrap();
            assert_eq!(uv.coords[uv.faces[0][2] as usize], Vector2::new(0.0, 1.0));
        }
    }
}
