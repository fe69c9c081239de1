//! One triangle mesh of the glTF writer: its primitives (textured faces, the rest), their
//! vertices split at UV seams, the texture, morph targets and custom attributes.

use std::collections::BTreeMap;

use gltf_json as json;
use json::accessor::Type;
use json::mesh::{Mode, Semantic};
use json::validation::Checked::Valid;

use super::write::{
    GltfMesh, Split, attribute_values, check_lengths, custom_semantic, positions_f32,
    textured_faces,
};
use super::write_doc::Doc;
use crate::error::MeshError;
use crate::mesh::NONE;

/// Adds `m` to `doc`: `None` when it has no triangle.
pub(super) fn push_mesh(
    doc: &mut Doc,
    m: &GltfMesh,
) -> Result<Option<json::Index<json::Mesh>>, MeshError> {
    check_lengths(m)?;
    if m.mesh.triangles.is_empty() {
        return Ok(None);
    }
    let (textured, plain) = textured_faces(&m.mesh);
    let mut primitives = Vec::new();
    if !textured.is_empty() {
        let material = m
            .texture_png
            .as_ref()
            .map(|png| textured_material(doc, png, &m.name));
        primitives.push(primitive(doc, m, &textured, true, material)?);
    }
    if !plain.is_empty() {
        // Beside a textured part, the rest gets a plain material of its own, so viewers do
        // not give it the texture's.
        let material =
            (m.texture_png.is_some() && !textured.is_empty()).then(|| plain_material(doc));
        primitives.push(primitive(doc, m, &plain, false, material)?);
    }
    let weights = (!m.morph_targets.is_empty()).then(|| vec![0.0; m.morph_targets.len()]);
    let extras = if m.morph_targets.is_empty() {
        Default::default()
    } else {
        let names: Vec<&str> = m.morph_targets.iter().map(|(n, _)| n.as_str()).collect();
        let text = serde_json::json!({ "targetNames": names }).to_string();
        Some(serde_json::value::RawValue::from_string(text).map_err(|e| {
            MeshError::InvalidArgument(format!("{}: morph target names: {e}", m.name))
        })?)
    };
    Ok(Some(doc.root.push(json::Mesh {
        extensions: None,
        extras,
        name: (!m.name.is_empty()).then(|| m.name.clone()),
        primitives,
        weights,
    })))
}

/// The primitive of faces `faces` of `m`, with `TEXCOORD_0` when `with_uv`.
fn primitive(
    doc: &mut Doc,
    m: &GltfMesh,
    faces: &[usize],
    with_uv: bool,
    material: Option<json::Index<json::Material>>,
) -> Result<json::mesh::Primitive, MeshError> {
    let mesh = &m.mesh;
    let uv = mesh.uv.as_ref().filter(|_| with_uv);
    let same = uv.map(|uv| same_coords(&uv.coords)).unwrap_or_default();
    let mut split = Split::default();
    let mut indices = Vec::with_capacity(3 * faces.len());
    for &f in faces {
        for c in 0..3 {
            let t = uv.map_or(NONE, |uv| same[uv.faces[f][c] as usize]);
            indices.push(split.vertex(mesh.triangles[f][c], t));
        }
    }
    let base = |v: u32| mesh.positions[v as usize];
    let xyz = positions_f32(split.from.iter().map(|&(v, _)| base(v)), &m.name)?;
    let mut attributes = BTreeMap::new();
    attributes.insert(
        Valid(Semantic::Positions),
        doc.floats(&xyz, Type::Vec3, true),
    );
    if let Some(uv) = uv {
        let mut st = Vec::with_capacity(2 * split.from.len());
        for &(_, t) in &split.from {
            let p = uv.coords[t as usize];
            let (s, t) = (p.x as f32, (1.0 - p.y) as f32);
            if !(s.is_finite() && t.is_finite()) {
                return Err(MeshError::InvalidArgument(format!(
                    "{}: a texture coordinate is not finite",
                    m.name
                )));
            }
            st.extend([s, t]);
        }
        attributes.insert(
            Valid(Semantic::TexCoords(0)),
            doc.floats(&st, Type::Vec2, false),
        );
    }
    for (name, a) in &m.attributes {
        let (values, type_) = attribute_values(a, &split);
        attributes.insert(
            Valid(custom_semantic(name)),
            doc.floats(&values, type_, false),
        );
    }
    let mut targets = Vec::with_capacity(m.morph_targets.len());
    for (name, frame) in &m.morph_targets {
        let d = split.from.iter().map(|&(v, _)| frame[v as usize] - base(v));
        let delta = positions_f32(d, name)?;
        targets.push(json::mesh::MorphTarget {
            positions: Some(doc.floats(&delta, Type::Vec3, true)),
            normals: None,
            tangents: None,
        });
    }
    Ok(json::mesh::Primitive {
        attributes,
        extensions: None,
        extras: Default::default(),
        indices: Some(doc.indices(&indices)),
        material,
        mode: Valid(Mode::Triangles),
        targets: (!targets.is_empty()).then_some(targets),
    })
}

/// Per texture coordinate, the first one with the same value: a vertex is split only where
/// its coordinates differ, not where they are stored twice (per-corner arrays).
fn same_coords(coords: &[nalgebra::Vector2<f64>]) -> Vec<u32> {
    let mut first = std::collections::HashMap::with_capacity(coords.len());
    coords
        .iter()
        .enumerate()
        .map(|(i, c)| {
            *first
                .entry((c.x.to_bits(), c.y.to_bits()))
                .or_insert(i as u32)
        })
        .collect()
}

/// A material whose base colour is the PNG `png`, embedded in the buffer.
fn textured_material(doc: &mut Doc, png: &[u8], name: &str) -> json::Index<json::Material> {
    let view = doc.view(png, None);
    let image = doc.root.push(json::Image {
        buffer_view: Some(view),
        mime_type: Some(json::image::MimeType("image/png".into())),
        name: None,
        uri: None,
        extensions: None,
        extras: Default::default(),
    });
    let texture = doc.root.push(json::Texture {
        name: None,
        sampler: None,
        source: image,
        extensions: None,
        extras: Default::default(),
    });
    doc.root.push(json::Material {
        name: Some(format!("{name} texture")),
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            base_color_texture: Some(json::texture::Info {
                index: texture,
                tex_coord: 0,
                extensions: None,
                extras: Default::default(),
            }),
            metallic_factor: json::material::StrengthFactor(0.0),
            ..Default::default()
        },
        ..Default::default()
    })
}

/// A plain grey material for faces without texture coordinates.
fn plain_material(doc: &mut Doc) -> json::Index<json::Material> {
    doc.root.push(json::Material {
        name: Some("plain".into()),
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            base_color_factor: json::material::PbrBaseColorFactor([0.8, 0.8, 0.8, 1.0]),
            metallic_factor: json::material::StrengthFactor(0.0),
            ..Default::default()
        },
        ..Default::default()
    })
}
