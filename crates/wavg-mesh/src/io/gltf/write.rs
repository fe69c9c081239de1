//! Writing glTF 2.0: `.glb` (one binary file) or `.gltf` (JSON, with its buffer in a
//! `.bin` file of the same stem beside it), chosen by the extension.
//!
//! A [`GltfScene`] holds what a file gets, one node each: triangle meshes (with per-corner
//! texture coordinates, a base colour texture, morph targets, custom per-vertex
//! attributes) and polylines. glTF stores one texture coordinate per vertex, so a mesh
//! vertex with several (a UV seam) is written once per distinct one; faces without
//! texture coordinates (a corner [`NONE`]) go into a second primitive of the same mesh,
//! without `TEXCOORD_0` and without the texture. glTF allows only 32-bit floats: positions
//! and attributes are rounded to `f32`. Texture coordinates are written as glTF wants
//! them, `(u, 1 - v)` (its `v` runs down the image, wavg's and OBJ's up). Positions are
//! written as they are (no change of axes). Vertices no triangle uses are not written.
//!
//! ```
//! use wavg_mesh::io::gltf::GltfScene;
//! use wavg_mesh::procedural;
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("sphere.glb");
//! GltfScene::from_mesh(&procedural::icosphere(1)).save(&path).unwrap();
//! assert_eq!(&std::fs::read(&path).unwrap()[..4], b"glTF");
//! ```

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use gltf_json as json;
use json::accessor::Type;
use json::mesh::{Mode, Semantic};
use json::validation::Checked::Valid;
use nalgebra::Vector3;

use super::write_doc::Doc;
use crate::error::MeshError;
use crate::io::{write_atomic, write_err};
use crate::mesh::{NONE, TriMesh};

/// The two glTF containers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GltfKind {
    /// `.glb`: the JSON and the binary buffer in one file.
    Glb,
    /// `.gltf`: JSON text; the buffer in a `.bin` file beside it.
    Gltf,
}

impl GltfKind {
    /// The container for a path ending in `.glb` or `.gltf` (any case), else `None`.
    ///
    /// ```
    /// use wavg_mesh::io::gltf::GltfKind;
    /// use std::path::Path;
    /// assert_eq!(GltfKind::from_path(Path::new("a/B.GLB")), Some(GltfKind::Glb));
    /// assert_eq!(GltfKind::from_path(Path::new("b.gltf")), Some(GltfKind::Gltf));
    /// assert_eq!(GltfKind::from_path(Path::new("c.obj")), None);
    /// ```
    pub fn from_path(path: &Path) -> Option<GltfKind> {
        let ext = path.extension()?.to_string_lossy().to_ascii_lowercase();
        match ext.as_str() {
            "glb" => Some(GltfKind::Glb),
            "gltf" => Some(GltfKind::Gltf),
            _ => None,
        }
    }
}

/// Whether `path` names a glTF file (`.glb` or `.gltf`): the extension the commands
/// look at to write glTF instead of their text or OBJ output.
pub fn is_gltf_path(path: &Path) -> bool {
    GltfKind::from_path(path).is_some()
}

/// A custom per-vertex attribute: one value per mesh vertex, written as 32-bit floats
/// (glTF forbids unsigned integers for custom attributes; floats hold integers up to
/// 2^24 exactly).
#[derive(Clone, Debug, PartialEq)]
pub enum VertexAttribute {
    /// One number per vertex (`SCALAR`).
    Scalar(Vec<f32>),
    /// Three numbers per vertex (`VEC3`).
    Vec3(Vec<[f32; 3]>),
}

impl VertexAttribute {
    fn len(&self) -> usize {
        match self {
            VertexAttribute::Scalar(v) => v.len(),
            VertexAttribute::Vec3(v) => v.len(),
        }
    }
}

/// One triangle mesh of a [`GltfScene`].
#[derive(Clone, Debug, Default)]
pub struct GltfMesh {
    /// The mesh's (and its node's) name.
    pub name: String,
    /// Positions, triangles and per-corner texture coordinates.
    pub mesh: TriMesh,
    /// A PNG image: the base colour texture of the faces with texture coordinates.
    pub texture_png: Option<Vec<u8>>,
    /// Morph targets: a name and the positions of every mesh vertex (written as
    /// displacements from [`Self::mesh`]'s positions, weights 0, names in the mesh's
    /// `extras.targetNames` as Blender and three.js read them).
    pub morph_targets: Vec<(String, Vec<Vector3<f64>>)>,
    /// Custom attributes, one value per mesh vertex; names without the `_` that glTF
    /// requires in front (added when writing, upper-cased).
    pub attributes: Vec<(String, VertexAttribute)>,
}

/// One polyline of a [`GltfScene`], a `LINE_STRIP` (or `LINE_LOOP` when closed).
#[derive(Clone, Debug, Default)]
pub struct GltfPolyline {
    /// The polyline's mesh and node name.
    pub name: String,
    /// The points in order.
    pub points: Vec<Vector3<f64>>,
    /// Whether the last point joins the first.
    pub closed: bool,
}

/// What a glTF file gets: meshes and polylines, a node each, in one scene.
#[derive(Clone, Debug, Default)]
pub struct GltfScene {
    /// The triangle meshes.
    pub meshes: Vec<GltfMesh>,
    /// The polylines.
    pub polylines: Vec<GltfPolyline>,
}

impl GltfScene {
    /// A scene of one mesh named `mesh` with its texture coordinates, if any.
    pub fn from_mesh(mesh: &TriMesh) -> Self {
        Self {
            meshes: vec![GltfMesh {
                name: "mesh".into(),
                mesh: mesh.clone(),
                ..Default::default()
            }],
            polylines: Vec::new(),
        }
    }

    /// Writes the scene to `path`, `.glb` or `.gltf` by its extension (a `.gltf` gets its
    /// buffer in `STEM.bin` beside it). Each file is written atomically
    /// ([`write_atomic`]); the `.bin` first, so a `.gltf` never names a missing buffer.
    pub fn save(&self, path: &Path) -> Result<(), MeshError> {
        let Some(kind) = GltfKind::from_path(path) else {
            return Err(MeshError::Unsupported {
                path: path.to_path_buf(),
                message: "a glTF file ends in .glb or .gltf".into(),
            });
        };
        let doc = self.document()?;
        match kind {
            GltfKind::Glb => {
                let bytes = doc.into_glb().map_err(|e| write_err(path, e))?;
                write_atomic(path, |w| w.write_all(&bytes)).map_err(|e| write_err(path, e))
            }
            GltfKind::Gltf => {
                let bin_path = bin_path(path);
                let bin_name = bin_path
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default();
                let (text, bin) = doc.into_gltf(&bin_name).map_err(|e| write_err(path, e))?;
                if !bin.is_empty() {
                    write_atomic(&bin_path, |w| w.write_all(&bin))
                        .map_err(|e| write_err(&bin_path, e))?;
                }
                write_atomic(path, |w| w.write_all(&text)).map_err(|e| write_err(path, e))
            }
        }
    }

    /// The scene as the bytes of one `.glb` file.
    pub fn to_glb(&self) -> Result<Vec<u8>, MeshError> {
        self.document()?
            .into_glb()
            .map_err(|e| MeshError::InvalidArgument(e.to_string()))
    }

    fn document(&self) -> Result<Doc, MeshError> {
        if self.meshes.iter().all(|m| m.mesh.triangles.is_empty())
            && self.polylines.iter().all(|p| p.points.len() < 2)
        {
            return Err(MeshError::InvalidArgument(
                "nothing to write: no triangle and no polyline of two points".into(),
            ));
        }
        let mut doc = Doc::new();
        let mut nodes = Vec::new();
        for m in &self.meshes {
            if let Some(mesh) = super::write_mesh::push_mesh(&mut doc, m)? {
                nodes.push(node(&mut doc, &m.name, mesh));
            }
        }
        for p in &self.polylines {
            if p.points.len() >= 2 {
                let mesh = push_polyline(&mut doc, p)?;
                nodes.push(node(&mut doc, &p.name, mesh));
            }
        }
        let scene = doc.root.push(json::Scene {
            extensions: None,
            extras: Default::default(),
            name: None,
            nodes,
        });
        doc.root.scene = Some(scene);
        Ok(doc)
    }
}

/// The `.bin` file of a `.gltf`: the same stem beside it.
pub fn bin_path(gltf: &Path) -> PathBuf {
    gltf.with_extension("bin")
}

fn node(doc: &mut Doc, name: &str, mesh: json::Index<json::Mesh>) -> json::Index<json::Node> {
    doc.root.push(json::Node {
        mesh: Some(mesh),
        name: (!name.is_empty()).then(|| name.to_string()),
        ..Default::default()
    })
}

/// Positions as `f32` triples, refusing values that are not finite (glTF readers and
/// its validator refuse them) or beyond `f32`'s range.
pub(super) fn positions_f32(
    points: impl Iterator<Item = Vector3<f64>>,
    what: &str,
) -> Result<Vec<f32>, MeshError> {
    let mut out = Vec::new();
    for p in points {
        for x in p.iter() {
            let y = *x as f32;
            if !y.is_finite() {
                return Err(MeshError::InvalidArgument(format!(
                    "{what}: coordinate {x} cannot be written as a 32-bit float"
                )));
            }
            out.push(y);
        }
    }
    Ok(out)
}

fn push_polyline(doc: &mut Doc, p: &GltfPolyline) -> Result<json::Index<json::Mesh>, MeshError> {
    let xyz = positions_f32(p.points.iter().copied(), &p.name)?;
    let position = doc.floats(&xyz, Type::Vec3, true);
    let mode = if p.closed && p.points.len() >= 3 {
        Mode::LineLoop
    } else {
        Mode::LineStrip
    };
    let primitive = json::mesh::Primitive {
        attributes: BTreeMap::from([(Valid(Semantic::Positions), position)]),
        extensions: None,
        extras: Default::default(),
        indices: None,
        material: None,
        mode: Valid(mode),
        targets: None,
    };
    Ok(doc.root.push(json::Mesh {
        extensions: None,
        extras: Default::default(),
        name: (!p.name.is_empty()).then(|| p.name.clone()),
        primitives: vec![primitive],
        weights: None,
    }))
}

/// glTF vertices for mesh vertices and texture coordinates: one per distinct pair, in
/// order of first use.
#[derive(Default)]
pub(super) struct Split {
    /// Per glTF vertex: its mesh vertex and texture coordinate index (`NONE` without).
    pub(super) from: Vec<(u32, u32)>,
    index: HashMap<(u32, u32), u32>,
}

impl Split {
    /// The glTF vertex of mesh vertex `v` with texture coordinate `t`.
    pub(super) fn vertex(&mut self, v: u32, t: u32) -> u32 {
        let next = self.from.len() as u32;
        *self.index.entry((v, t)).or_insert_with(|| {
            self.from.push((v, t));
            next
        })
    }
}

/// The length check of per-vertex data.
pub(super) fn check_len(n: usize, mesh: &GltfMesh, what: &str) -> Result<(), MeshError> {
    if n != mesh.mesh.positions.len() {
        return Err(MeshError::InvalidArgument(format!(
            "{}: {what} has {n} values for {} vertices",
            mesh.name,
            mesh.mesh.positions.len()
        )));
    }
    Ok(())
}

/// The attribute's values for the glTF vertices `split` (as float components).
pub(super) fn attribute_values(a: &VertexAttribute, split: &Split) -> (Vec<f32>, Type) {
    match a {
        VertexAttribute::Scalar(v) => (
            split.from.iter().map(|&(i, _)| v[i as usize]).collect(),
            Type::Scalar,
        ),
        VertexAttribute::Vec3(v) => (
            split
                .from
                .iter()
                .flat_map(|&(i, _)| v[i as usize])
                .collect(),
            Type::Vec3,
        ),
    }
}

/// A custom attribute's semantic: `_` and the upper-cased name.
pub(super) fn custom_semantic(name: &str) -> Semantic {
    Semantic::Extras(name.trim_start_matches('_').to_ascii_uppercase())
}

/// Faces whose texture coordinates are all present, and the rest.
pub(super) fn textured_faces(mesh: &TriMesh) -> (Vec<usize>, Vec<usize>) {
    match &mesh.uv {
        Some(uv) if uv.faces.len() == mesh.triangles.len() => {
            (0..mesh.triangles.len()).partition(|&f| !uv.faces[f].contains(&NONE))
        }
        _ => (Vec::new(), (0..mesh.triangles.len()).collect()),
    }
}

/// A vertex attribute's length check against the mesh (used for every list given).
pub(super) fn check_lengths(m: &GltfMesh) -> Result<(), MeshError> {
    for (name, a) in &m.attributes {
        check_len(a.len(), m, name)?;
        if let VertexAttribute::Scalar(v) = a {
            if v.iter().any(|x| !x.is_finite()) {
                return Err(MeshError::InvalidArgument(format!(
                    "{}: attribute {name} has a value that is not finite",
                    m.name
                )));
            }
        } else if let VertexAttribute::Vec3(v) = a {
            if v.iter().flatten().any(|x| !x.is_finite()) {
                return Err(MeshError::InvalidArgument(format!(
                    "{}: attribute {name} has a value that is not finite",
                    m.name
                )));
            }
        }
    }
    for (name, p) in &m.morph_targets {
        check_len(p.len(), m, name)?;
    }
    let n = m.mesh.positions.len();
    if let Some(t) = m
        .mesh
        .triangles
        .iter()
        .flatten()
        .find(|&&v| v as usize >= n)
    {
        return Err(MeshError::InvalidArgument(format!(
            "{}: vertex {t} of a triangle is out of range ({n} vertices)",
            m.name
        )));
    }
    if let Some(uv) = &m.mesh.uv {
        let k = uv.coords.len();
        if uv.faces.len() != m.mesh.triangles.len()
            || uv
                .faces
                .iter()
                .flatten()
                .any(|&t| t != NONE && t as usize >= k)
        {
            return Err(MeshError::InvalidArgument(format!(
                "{}: texture coordinates do not match the triangles",
                m.name
            )));
        }
    }
    Ok(())
}
