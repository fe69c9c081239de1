//! The applications' results as glTF scenes ([`GltfScene`], written by
//! [`GltfScene::save`]): what each command writes when its output ends in `.glb` or
//! `.gltf`, decided here once for every front end.

use nalgebra::Vector3;
use wavg_mesh::io::gltf::{GltfMesh, GltfPolyline, GltfScene, VertexAttribute};
use wavg_mesh::{NONE, TexCoords, TriMesh};

use crate::correspond::{Correspondence, Validity};
use crate::decal::DecalUv;
use crate::error::AppError;
use crate::render::Image;
use crate::spline::Curve;

/// Largest face id a [`correspondence_scene`] writes: a 32-bit float holds every integer up
/// to 2^24 exactly.
pub const MAX_GLTF_FACE: usize = 1 << 24;

fn one(name: &str, mesh: GltfMesh) -> GltfScene {
    GltfScene {
        meshes: vec![GltfMesh {
            name: name.into(),
            ..mesh
        }],
        polylines: Vec::new(),
    }
}

/// `mesh` (with its texture coordinates) with `texture` embedded as a PNG base colour
/// texture: what `wavg transfer-texture -o OUT.glb` writes (the target and its new texture).
pub fn textured_scene(mesh: &TriMesh, texture: &Image) -> Result<GltfScene, AppError> {
    let mut png = Vec::new();
    texture.encode_png(&mut png)?;
    Ok(one(
        "textured",
        GltfMesh {
            mesh: mesh.clone(),
            texture_png: Some(png),
            ..Default::default()
        },
    ))
}

/// A decal: `mesh` with the decal coordinates `uv` (one per vertex); faces with a marked
/// corner go into a primitive without texture coordinates (as the OBJ writes them
/// untextured). `texture_png`, when given, is embedded as the decal faces' base colour.
pub fn decal_scene(mesh: &TriMesh, uv: &DecalUv, texture_png: Option<Vec<u8>>) -> GltfScene {
    let coords = uv
        .uv
        .iter()
        .map(|p| nalgebra::Vector2::new(p[0], p[1]))
        .collect();
    let faces = mesh
        .triangles
        .iter()
        .map(|t| {
            if t.iter()
                .any(|&v| uv.marked.get(v as usize).copied().unwrap_or(true))
            {
                [NONE; 3]
            } else {
                *t
            }
        })
        .collect();
    let mesh = TriMesh {
        uv: Some(TexCoords { coords, faces }),
        ..mesh.clone()
    };
    one(
        "decal",
        GltfMesh {
            mesh,
            texture_png,
            ..Default::default()
        },
    )
}

/// A polygon mesh (a remeshing's quads or triangles) fan-triangulated, as glTF has no
/// polygons: what `wavg remesh -o OUT.glb` writes.
pub fn polygons_scene(positions: &[Vector3<f64>], faces: &[Vec<u32>]) -> GltfScene {
    let triangles = faces
        .iter()
        .flat_map(|f| (2..f.len()).map(move |k| [f[0], f[k - 1], f[k]]))
        .collect();
    one(
        "remeshed",
        GltfMesh {
            mesh: TriMesh::new(positions.to_vec(), triangles),
            ..Default::default()
        },
    )
}

/// A morph: one mesh (`mesh` at its own positions) with every frame a morph target named
/// `frame_000`, `frame_001`, ... (weights 0: viewers show the first frame until a
/// weight is set; Blender imports them as shape keys).
pub fn morph_scene(mesh: &TriMesh, frames: &[Vec<Vector3<f64>>]) -> GltfScene {
    let morph_targets = frames
        .iter()
        .enumerate()
        .map(|(k, f)| (format!("frame_{k:03}"), f.clone()))
        .collect();
    one(
        "morph",
        GltfMesh {
            mesh: TriMesh {
                uv: None,
                ..mesh.clone()
            },
            morph_targets,
            ..Default::default()
        },
    )
}

/// Curves on a surface as polylines (`LINE_STRIP`, `LINE_LOOP` when closed), one node
/// each, named `curve_0`, `curve_1`, ...; with `mesh`, the surface as well.
pub fn curves_scene(mesh: Option<&TriMesh>, curves: &[(Vec<Vector3<f64>>, bool)]) -> GltfScene {
    GltfScene {
        meshes: mesh
            .map(|m| GltfMesh {
                name: "surface".into(),
                mesh: m.clone(),
                ..Default::default()
            })
            .into_iter()
            .collect(),
        polylines: curves
            .iter()
            .enumerate()
            .map(|(k, (points, closed))| GltfPolyline {
                name: format!("curve_{k}"),
                points: points.clone(),
                closed: *closed,
            })
            .collect(),
    }
}

/// A sampled curve as one polyline (`LINE_STRIP`, or `LINE_LOOP` for a closed curve)
/// through its samples on the surface (failed samples are skipped, as in
/// [`Curve::length`]): what `wavg spline -o OUT.glb` writes, to view over the mesh.
pub fn curve_scene(curve: &Curve) -> GltfScene {
    let points = curve
        .samples
        .iter()
        .filter_map(|r| r.as_ref().ok().map(|r| r.position))
        .collect();
    GltfScene {
        meshes: Vec::new(),
        polylines: vec![GltfPolyline {
            name: "curve".into(),
            points,
            closed: curve.closed,
        }],
    }
}

/// The code [`correspondence_scene`] writes in `_VALIDITY` for a vertex's validity: 0
/// valid, 1 unanswered, 2 no round trip, 3 negative weight, 4 inconsistent.
pub fn validity_code(v: &Validity) -> f32 {
    match v {
        Validity::Valid => 0.0,
        Validity::Unanswered(_) => 1.0,
        Validity::NoRoundTrip => 2.0,
        Validity::NegativeWeight(_) => 3.0,
        Validity::Inconsistent => 4.0,
    }
}

/// A correspondence as the source mesh with custom per-vertex attributes (32-bit floats,
/// as glTF allows for custom attributes): `_TARGET_FACE` (SCALAR: the target face, -1
/// where the vertex has no valid image), `_TARGET_BARY` (VEC3: the barycentric
/// coordinates in that face), `_TARGET_POSITION` (VEC3: the point on the target) and
/// `_VALIDITY` ([`validity_code`]). Without an image the vectors are zero. A target face
/// at or beyond [`MAX_GLTF_FACE`] is refused (a float would round it).
pub fn correspondence_scene(source: &TriMesh, map: &Correspondence) -> Result<GltfScene, AppError> {
    let n = map.mapped.len();
    let (mut face, mut bary, mut pos, mut validity) = (
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    );
    for (m, v) in map.mapped.iter().zip(&map.validity) {
        validity.push(validity_code(v));
        match (v, &m.target) {
            (Validity::Valid, Ok(r)) => {
                let f = r.point.face as usize;
                if f >= MAX_GLTF_FACE {
                    return Err(AppError::Input(format!(
                        "target face {f} is beyond the {MAX_GLTF_FACE} faces a glTF float \
                         attribute holds exactly; write the text map instead"
                    )));
                }
                face.push(f as f32);
                bary.push(r.point.bary.map(|b| b as f32));
                pos.push([0, 1, 2].map(|k| r.position[k] as f32));
            }
            _ => {
                face.push(-1.0);
                bary.push([0.0; 3]);
                pos.push([0.0; 3]);
            }
        }
    }
    Ok(one(
        "correspondence",
        GltfMesh {
            mesh: source.clone(),
            attributes: vec![
                ("TARGET_FACE".into(), VertexAttribute::Scalar(face)),
                ("TARGET_BARY".into(), VertexAttribute::Vec3(bary)),
                ("TARGET_POSITION".into(), VertexAttribute::Vec3(pos)),
                ("VALIDITY".into(), VertexAttribute::Scalar(validity)),
            ],
            ..Default::default()
        },
    ))
}
