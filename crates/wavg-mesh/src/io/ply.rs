//! PLY (ASCII, binary little and big endian) through `ply-rs-bw`.
//!
//! Reads `vertex` elements with scalar `x y z` (any numeric type) and `face` elements with
//! a `vertex_indices` (or `vertex_index`) list. Texture coordinates are taken from a
//! per-face `texcoord` list (`u0 v0 u1 v1 ...`, the MeshLab convention) or from per-vertex
//! `u v` / `s t` / `texture_u texture_v` properties.

use nalgebra::{Vector2, Vector3};
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{
    Addable, DefaultElement, ElementDef, Encoding, Ply, Property, PropertyDef, PropertyType,
    ScalarType,
};

use super::LoadNotes;
use super::text::{ParseError, Result};
use crate::mesh::{TexCoords, TriMesh};

fn scalar(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(v) => v as f64,
        Property::UChar(v) => v as f64,
        Property::Short(v) => v as f64,
        Property::UShort(v) => v as f64,
        Property::Int(v) => v as f64,
        Property::UInt(v) => v as f64,
        Property::Float(v) => v as f64,
        Property::Double(v) => v,
        _ => return None,
    })
}

/// An integer list as i64 values (floats are rejected: indices must be integers).
fn index_list(p: &Property) -> Option<Vec<i64>> {
    Some(match p {
        Property::ListChar(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUChar(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListShort(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUShort(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListInt(v) => v.iter().map(|&x| x as i64).collect(),
        Property::ListUInt(v) => v.iter().map(|&x| x as i64).collect(),
        _ => return None,
    })
}

fn float_list(p: &Property) -> Option<Vec<f64>> {
    Some(match p {
        Property::ListFloat(v) => v.iter().map(|&x| x as f64).collect(),
        Property::ListDouble(v) => v.clone(),
        _ => return None,
    })
}

fn read(bytes: &[u8]) -> Result<Ply<DefaultElement>> {
    let parser = Parser::<DefaultElement>::new();
    let mut src = bytes;
    // The third-party parser is guarded so that no input can panic through `load`.
    let res = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| parser.read_ply(&mut src)));
    match res {
        Ok(Ok(ply)) => Ok(ply),
        Ok(Err(e)) => Err(ParseError::new(
            e.line().unwrap_or(0),
            format!(
                "PLY: {}",
                strip_line_prefix(&e.to_string())
                    .split_whitespace()
                    .collect::<Vec<_>>()
                    .join(" ")
            ),
        )),
        Err(_) => Err(ParseError::new(
            0,
            "PLY: the parser failed on malformed data",
        )),
    }
}

/// `ply-rs-bw` prefixes messages with "Line N: "; the line is reported separately.
fn strip_line_prefix(msg: &str) -> &str {
    match msg.strip_prefix("Line ") {
        Some(rest) => rest.split_once(": ").map_or(msg, |(_, m)| m),
        None => msg,
    }
}

pub(crate) fn parse(bytes: &[u8]) -> Result<(TriMesh, LoadNotes)> {
    let ply = read(bytes)?;
    let err = |m: String| ParseError::new(0, format!("PLY: {m}"));
    let empty = Vec::new();
    let verts = ply.payload.get("vertex").unwrap_or(&empty);
    let faces = ply.payload.get("face").unwrap_or(&empty);
    let mut positions = Vec::with_capacity(verts.len());
    let mut vertex_uv: Option<Vec<Vector2<f64>>> = verts.first().and_then(|v| {
        [("u", "v"), ("s", "t"), ("texture_u", "texture_v")]
            .iter()
            .find(|(a, b)| v.contains_key(*a) && v.contains_key(*b))
            .map(|_| Vec::with_capacity(verts.len()))
    });
    for (i, v) in verts.iter().enumerate() {
        let coord = |k: &str| {
            v.get(k)
                .and_then(scalar)
                .ok_or_else(|| err(format!("vertex {i} has no numeric {k}")))
        };
        positions.push(Vector3::new(coord("x")?, coord("y")?, coord("z")?));
        if let Some(uvs) = vertex_uv.as_mut() {
            let pair = [("u", "v"), ("s", "t"), ("texture_u", "texture_v")]
                .iter()
                .find_map(|(a, b)| {
                    Some((v.get(*a).and_then(scalar)?, v.get(*b).and_then(scalar)?))
                });
            match pair {
                Some((u, w)) => uvs.push(Vector2::new(u, w)),
                None => return Err(err(format!("vertex {i} lacks texture coordinates"))),
            }
        }
    }
    let mut notes = LoadNotes::default();
    let mut triangles = Vec::with_capacity(faces.len());
    let mut corner_uv: Vec<Vector2<f64>> = Vec::new();
    let mut corner_uv_ok = faces.first().is_some_and(|f| f.contains_key("texcoord"));
    for (i, f) in faces.iter().enumerate() {
        let list = f
            .get("vertex_indices")
            .or_else(|| f.get("vertex_index"))
            .and_then(index_list)
            .ok_or_else(|| err(format!("face {i} has no integer vertex_indices list")))?;
        let idx: Vec<u32> = list
            .iter()
            .map(|&x| u32::try_from(x).ok().filter(|&x| x != u32::MAX))
            .collect::<Option<_>>()
            .ok_or_else(|| err(format!("face {i} has a negative or too large index")))?;
        notes.polygons += 1;
        if idx.len() < 3 {
            notes.skipped_faces += 1;
            continue;
        }
        if idx.len() > 3 {
            notes.non_triangles += 1;
        }
        let tc = if corner_uv_ok {
            f.get("texcoord").and_then(float_list)
        } else {
            None
        };
        let tc = tc.filter(|t| t.len() == 2 * idx.len());
        if corner_uv_ok && tc.is_none() {
            corner_uv_ok = false;
            notes.uv_dropped = true;
        }
        for j in 1..idx.len() - 1 {
            triangles.push([idx[0], idx[j], idx[j + 1]]);
            if let Some(t) = &tc {
                for c in [0, j, j + 1] {
                    corner_uv.push(Vector2::new(t[2 * c], t[2 * c + 1]));
                }
            }
        }
    }
    let uv = if corner_uv_ok && !triangles.is_empty() {
        let faces = (0..triangles.len() as u32)
            .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
            .collect();
        Some(TexCoords {
            coords: corner_uv,
            faces,
        })
    } else {
        vertex_uv.take().map(|coords| TexCoords {
            coords,
            faces: triangles.clone(),
        })
    };
    Ok((
        TriMesh {
            positions,
            triangles,
            uv,
        },
        notes,
    ))
}

/// Binary little-endian PLY with double positions, `uint` indices and, when the mesh has
/// texture coordinates, a per-face `texcoord` list of doubles.
pub(crate) fn write(mesh: &TriMesh) -> std::io::Result<Vec<u8>> {
    let mut ply = Ply::<DefaultElement>::new();
    ply.header.encoding = Encoding::BinaryLittleEndian;
    ply.header.comments.push("written by wavg".to_string());
    let mut vdef = ElementDef::new("vertex".to_string());
    for k in ["x", "y", "z"] {
        vdef.properties.add(PropertyDef::new(
            k.to_string(),
            PropertyType::Scalar(ScalarType::Double),
        ));
    }
    ply.header.elements.add(vdef);
    let uv = mesh
        .uv
        .as_ref()
        .filter(|uv| uv.faces.len() == mesh.triangles.len());
    let mut fdef = ElementDef::new("face".to_string());
    fdef.properties.add(PropertyDef::new(
        "vertex_indices".to_string(),
        PropertyType::List(ScalarType::UChar, ScalarType::UInt),
    ));
    if uv.is_some() {
        fdef.properties.add(PropertyDef::new(
            "texcoord".to_string(),
            PropertyType::List(ScalarType::UChar, ScalarType::Double),
        ));
    }
    ply.header.elements.add(fdef);
    let verts = mesh
        .positions
        .iter()
        .map(|p| {
            let mut e = DefaultElement::new();
            e.insert("x".to_string(), Property::Double(p.x));
            e.insert("y".to_string(), Property::Double(p.y));
            e.insert("z".to_string(), Property::Double(p.z));
            e
        })
        .collect();
    ply.payload.insert("vertex".to_string(), verts);
    let faces = mesh
        .triangles
        .iter()
        .enumerate()
        .map(|(f, t)| {
            let mut e = DefaultElement::new();
            e.insert("vertex_indices".to_string(), Property::ListUInt(t.to_vec()));
            if let Some(uv) = uv {
                let tc = uv.faces[f]
                    .iter()
                    .flat_map(|&i| {
                        let c = uv.coords.get(i as usize).copied().unwrap_or_default();
                        [c.x, c.y]
                    })
                    .collect();
                e.insert("texcoord".to_string(), Property::ListDouble(tc));
            }
            e
        })
        .collect();
    ply.payload.insert("face".to_string(), faces);
    let mut out = Vec::new();
    ply_rs_bw::writer::Writer::new().write_ply(&mut out, &mut ply)?;
    Ok(out)
}
