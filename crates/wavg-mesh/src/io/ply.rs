//! PLY (ASCII, binary little and big endian) through `ply-rs-bw`.
//!
//! Reads `vertex` elements with scalar `x y z` (any numeric type) and `face` elements with
//! a `vertex_indices` (or `vertex_index`) list. Texture coordinates are taken from a
//! per-face `texcoord` list (`u0 v0 u1 v1 ...`, the MeshLab convention) or from per-vertex
//! `u v` / `s t` / `texture_u texture_v` properties.

use nalgebra::{Vector2, Vector3};
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{
    Addable, DefaultElement, ElementDef, Encoding, Ply, Property, PropertyAccess,
    PropertyAccessResult, PropertyDef, PropertyType, ScalarType,
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

/// A `vertex` element: its coordinates and texture coordinates, whatever their numeric
/// type (typed elements instead of the parser's maps: no allocation per vertex).
#[derive(Default)]
struct PlyVertex {
    /// `x y z`.
    xyz: [Option<f64>; 3],
    /// `u v`, `s t`, `texture_u texture_v`, in that order of preference.
    uv: [Option<f64>; 6],
}

impl PropertyAccess for PlyVertex {
    fn new() -> Self {
        Self::default()
    }

    fn set_property(&mut self, name: &str, p: Property) -> PropertyAccessResult {
        let slot = match name {
            "x" => &mut self.xyz[0],
            "y" => &mut self.xyz[1],
            "z" => &mut self.xyz[2],
            "u" => &mut self.uv[0],
            "v" => &mut self.uv[1],
            "s" => &mut self.uv[2],
            "t" => &mut self.uv[3],
            "texture_u" => &mut self.uv[4],
            "texture_v" => &mut self.uv[5],
            _ => return PropertyAccessResult::Ignored,
        };
        *slot = scalar(&p);
        PropertyAccessResult::Set
    }
}

/// A `face` element: its vertex index list (integers only) and its `texcoord` list.
#[derive(Default)]
struct PlyFace {
    indices: Option<Vec<i64>>,
    /// Whether `vertex_indices` was there (then `vertex_index` does not count).
    named: bool,
    texcoord: Option<Vec<f64>>,
}

impl PropertyAccess for PlyFace {
    fn new() -> Self {
        Self::default()
    }

    fn set_property(&mut self, name: &str, p: Property) -> PropertyAccessResult {
        match name {
            "vertex_indices" => (self.indices, self.named) = (index_list(&p), true),
            // The older name counts only when the usual one is absent.
            "vertex_index" if !self.named => self.indices = index_list(&p),
            "texcoord" => self.texcoord = float_list(&p),
            _ => return PropertyAccessResult::Ignored,
        }
        PropertyAccessResult::Set
    }
}

/// The `vertex` and `face` elements of a PLY file (others are read past and dropped).
fn read(bytes: &[u8]) -> Result<(Vec<PlyVertex>, Vec<PlyFace>)> {
    // The third-party parser is guarded so that no input can panic through `load`.
    let res = std::panic::catch_unwind(|| {
        let mut reader = Reader::new(bytes);
        let header = Parser::<PlyVertex>::new().read_header(&mut reader)?;
        let (mut verts, mut faces) = (Vec::new(), Vec::new());
        // An element without properties takes no bytes per record in binary files, so no
        // end of data stops its count: bound it by the file's length instead.
        if let Some(def) =
            (header.elements.values()).find(|d| d.properties.is_empty() && d.count > bytes.len())
        {
            return Ok(Err(format!(
                "element '{}' has no properties but declares {} records",
                def.name, def.count
            )));
        }
        for (name, def) in &header.elements {
            match name.as_str() {
                "vertex" => {
                    verts = Parser::<PlyVertex>::new().read_payload_for_element(
                        &mut reader,
                        def,
                        &header,
                    )?;
                }
                "face" => {
                    faces = Parser::<PlyFace>::new().read_payload_for_element(
                        &mut reader,
                        def,
                        &header,
                    )?;
                }
                _ => {
                    Parser::<DefaultElement>::new().read_payload_for_element(
                        &mut reader,
                        def,
                        &header,
                    )?;
                }
            }
        }
        Ok::<_, ply_rs_bw::parser::ParseError>(Ok((verts, faces)))
    });
    match res {
        Ok(Ok(Ok(elements))) => Ok(elements),
        Ok(Ok(Err(message))) => Err(ParseError::new(0, format!("PLY: {message}"))),
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
    let (verts, faces) = read(bytes)?;
    let err = |m: String| ParseError::new(0, format!("PLY: {m}"));
    let mut positions = Vec::with_capacity(verts.len());
    // The first pair of texture coordinates the first vertex has decides.
    let pair = verts
        .first()
        .and_then(|v| (0..3).find(|&k| v.uv[2 * k].is_some() && v.uv[2 * k + 1].is_some()));
    let mut vertex_uv: Option<Vec<Vector2<f64>>> = pair.map(|_| Vec::with_capacity(verts.len()));
    for (i, v) in verts.iter().enumerate() {
        let coord = |k: usize| {
            v.xyz[k].ok_or_else(|| err(format!("vertex {i} has no numeric {}", ["x", "y", "z"][k])))
        };
        positions.push(Vector3::new(coord(0)?, coord(1)?, coord(2)?));
        if let Some(uvs) = vertex_uv.as_mut() {
            let pair = (0..3).find_map(|k| Some((v.uv[2 * k]?, v.uv[2 * k + 1]?)));
            match pair {
                Some((u, w)) => uvs.push(Vector2::new(u, w)),
                None => return Err(err(format!("vertex {i} lacks texture coordinates"))),
            }
        }
    }
    let mut notes = LoadNotes::default();
    let mut triangles = Vec::with_capacity(faces.len());
    let mut corner_uv: Vec<Vector2<f64>> = Vec::new();
    let mut corner_uv_ok = faces.first().is_some_and(|f| f.texcoord.is_some());
    for (i, f) in faces.iter().enumerate() {
        let list = f
            .indices
            .as_ref()
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
            f.texcoord.as_ref()
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
        notes.fan(idx.len() - 2);
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

#[cfg(test)]
mod tests {
    use super::*;

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
