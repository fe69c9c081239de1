//! A glTF file read into one triangle mesh: the scene's mesh instances with their node
//! transforms, each primitive's triangles, welded by position, with per-corner UVs.

use std::ops::Range;
use std::path::Path;

use gltf::mesh::Mode;
use nalgebra::{Matrix4, Vector2, Vector3};

use super::read_accessor::{self, Source};
use super::read_limits::{Budget, MAX_DEPTH};
use super::read_texture::{self, TextureSource};
use super::{read_buffers, split_mesh_name, weld};
use crate::io::format::LoadNotes;
use crate::mesh::{NONE, TexCoords, TriMesh};

/// One placement of a mesh: the mesh and its node's world transform.
type Instance<'d> = (gltf::Mesh<'d>, Matrix4<f64>);

/// A node and its world transform.
type Placed<'d> = (gltf::Node<'d>, Matrix4<f64>);

/// Reads a `.gltf` or `.glb` held in `bytes`; `path` (with an optional `#Name` suffix
/// choosing one mesh) locates the files beside it. Errors are messages for
/// `MeshError::Parse`.
pub(crate) fn parse(bytes: &[u8], path: &Path) -> Result<(TriMesh, LoadNotes), String> {
    let (file, name) = split_mesh_name(path);
    let container = read_buffers::container(bytes)?;
    let doc = document(container.json)?;
    let buffers = read_buffers::load(&doc, container.bin, &file)?;
    let external: usize = match container.bin {
        Some(_) => 0,
        None => buffers.iter().map(|b| b.len()).sum(),
    };
    let budget = Budget::for_bytes(bytes.len().saturating_add(external) as u64);
    let instances = match &name {
        Some(n) => named(&doc, n)?,
        None => scene_instances(&doc)?,
    };
    let mut src = Source { buffers, budget };
    let mut acc = Assembly::default();
    for (mesh, world) in &instances {
        for prim in mesh.primitives() {
            acc.primitive(&mut src, mesh, &prim, world, &file)?;
        }
    }
    acc.finish()
}

/// The validated document of a glTF JSON text. The `gltf` crate's checks run, less one:
/// POSITION accessors without `min` and `max` are read (many writers omit them; they are
/// not needed here). A POSITION index past the accessors is refused first: the crate's
/// own check of `min` and `max` would index with it unchecked.
fn document(json: &[u8]) -> Result<gltf::Document, String> {
    use gltf::json::validation::{Checked, Error, Validate};
    let root: gltf::json::Root =
        gltf::json::deserialize::from_slice(json).map_err(|e| format!("glTF JSON: {e}"))?;
    let n = root.accessors.len();
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let pos = prim
                .attributes
                .get(&Checked::Valid(gltf::json::mesh::Semantic::Positions));
            if let Some(i) = pos.filter(|i| i.value() >= n) {
                return Err(format!(
                    "invalid glTF: meshes[{m}].primitives[{p}] POSITION accessor {} does \
                     not exist ({n} accessors)",
                    i.value()
                ));
            }
        }
    }
    let mut errors = Vec::new();
    root.validate(&root, gltf::json::Path::new, &mut |path, e| {
        errors.push((path(), e))
    });
    errors.retain(|(path, e)| {
        let p = path.as_str();
        !(*e == Error::Missing && (p.ends_with("].min") || p.ends_with("].max")))
    });
    if !errors.is_empty() {
        return Err(validation_error(&errors));
    }
    Ok(gltf::Document::from_json_without_validation(root))
}

/// The `gltf` crate's validation errors spelled out (the first five).
fn validation_error(list: &[(gltf::json::Path, gltf::json::validation::Error)]) -> String {
    {
        {
            let shown: Vec<String> = list
                .iter()
                .take(5)
                .map(|(path, err)| format!("{path}: {err}"))
                .collect();
            let more = list.len().saturating_sub(shown.len());
            let tail = if more > 0 {
                format!(" (and {more} more)")
            } else {
                String::new()
            };
            let required = if list
                .iter()
                .any(|(p, _)| p.as_str().contains("extensionsRequired"))
            {
                " (a required extension this reader does not read, e.g. Draco or meshopt \
                 compression)"
            } else {
                ""
            };
            format!("invalid glTF{required}: {}{tail}", shown.join("; "))
        }
    }
}

fn matrix(t: gltf::scene::Transform) -> Matrix4<f64> {
    let m = t.matrix(); // column-major
    Matrix4::from_fn(|r, c| m[c][r] as f64)
}

/// Every node of the default scene (or the first) with its world transform, or `None`
/// when the file has no scene.
fn scene_nodes(doc: &gltf::Document) -> Result<Option<Vec<Placed<'_>>>, String> {
    let Some(scene) = doc.default_scene().or_else(|| doc.scenes().next()) else {
        return Ok(None);
    };
    let mut seen = vec![false; doc.nodes().len()];
    let mut out = Vec::new();
    let mut stack: Vec<(gltf::Node, Matrix4<f64>, usize)> =
        scene.nodes().map(|n| (n, Matrix4::identity(), 0)).collect();
    stack.reverse();
    while let Some((node, parent, depth)) = stack.pop() {
        if std::mem::replace(&mut seen[node.index()], true) {
            return Err(format!(
                "node {} is reached twice in scene {} (glTF nodes form disjoint trees)",
                node.index(),
                scene.index()
            ));
        }
        if depth > MAX_DEPTH {
            return Err(format!("nodes nested deeper than {MAX_DEPTH}"));
        }
        let world = parent * matrix(node.transform());
        let mut children: Vec<_> = node.children().map(|c| (c, world, depth + 1)).collect();
        children.reverse();
        stack.extend(children);
        out.push((node, world));
    }
    Ok(Some(out))
}

/// The mesh instances of the default scene; every mesh once, untransformed, without a
/// scene.
fn scene_instances(doc: &gltf::Document) -> Result<Vec<Instance<'_>>, String> {
    Ok(match scene_nodes(doc)? {
        Some(nodes) => nodes
            .into_iter()
            .filter_map(|(n, w)| n.mesh().map(|m| (m, w)))
            .collect(),
        None => doc.meshes().map(|m| (m, Matrix4::identity())).collect(),
    })
}

/// The instances of the mesh named `name` (where the scene places it, or once
/// untransformed), else of the nodes named `name`.
fn named<'d>(doc: &'d gltf::Document, name: &str) -> Result<Vec<Instance<'d>>, String> {
    let meshes: Vec<_> = doc.meshes().filter(|m| m.name() == Some(name)).collect();
    let nodes = scene_nodes(doc)?.unwrap_or_default();
    if !meshes.is_empty() {
        let ids: Vec<usize> = meshes.iter().map(|m| m.index()).collect();
        let placed: Vec<_> = nodes
            .iter()
            .filter_map(|(n, w)| {
                n.mesh()
                    .filter(|m| ids.contains(&m.index()))
                    .map(|m| (m, *w))
            })
            .collect();
        return Ok(if placed.is_empty() {
            meshes
                .into_iter()
                .map(|m| (m, Matrix4::identity()))
                .collect()
        } else {
            placed
        });
    }
    let by_node: Vec<_> = nodes
        .into_iter()
        .filter(|(n, _)| n.name() == Some(name))
        .filter_map(|(n, w)| n.mesh().map(|m| (m, w)))
        .collect();
    if by_node.is_empty() {
        let mut names: Vec<String> = doc
            .meshes()
            .map(|m| format!("{:?}", m.name().unwrap_or("")))
            .take(20)
            .collect();
        if doc.meshes().len() > names.len() {
            names.push("...".into());
        }
        return Err(format!(
            "no mesh or node named {name:?} (the meshes: {})",
            if names.is_empty() {
                "none".to_string()
            } else {
                names.join(", ")
            }
        ));
    }
    Ok(by_node)
}

/// The triangles of one primitive as corner indices into its vertices, following glTF's
/// rules for strips and fans; `None` for points and lines.
fn triangles(mode: Mode, idx: &[u32]) -> Option<Vec<[u32; 3]>> {
    let n = idx.len();
    Some(match mode {
        Mode::Triangles => idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        Mode::TriangleStrip => (0..n.saturating_sub(2))
            .map(|i| {
                if i % 2 == 0 {
                    [idx[i], idx[i + 1], idx[i + 2]]
                } else {
                    [idx[i + 1], idx[i], idx[i + 2]]
                }
            })
            .collect(),
        Mode::TriangleFan => (1..n.saturating_sub(1))
            .map(|i| [idx[i], idx[i + 1], idx[0]])
            .collect(),
        Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip => return None,
    })
}

/// The instances' primitives gathered before welding: positions in world space, corner
/// indices into them, per-vertex UVs once a primitive has them.
#[derive(Default)]
struct Assembly {
    positions: Vec<Vector3<f64>>,
    triangles: Vec<[u32; 3]>,
    /// wavg's (u, v) per gathered vertex (NaN where the primitive has none); empty until
    /// a primitive has `TEXCOORD_0`.
    uv: Vec<Vector2<f64>>,
    /// Triangles whose primitive has `TEXCOORD_0`.
    textured: usize,
    /// The ranges of `triangles` whose primitive has no `TEXCOORD_0`.
    untextured: Vec<Range<usize>>,
    skipped_primitives: usize,
    texture: Option<TextureSource>,
}

impl Assembly {
    /// Appends one primitive; the arrays are read straight into the gathered ones.
    fn primitive(
        &mut self,
        src: &mut Source,
        mesh: &gltf::Mesh,
        prim: &gltf::Primitive,
        world: &Matrix4<f64>,
        file: &Path,
    ) -> Result<(), String> {
        let what = format!("mesh {} primitive {}", mesh.index(), prim.index());
        let positions = prim
            .get(&gltf::Semantic::Positions)
            .ok_or_else(|| format!("{what} has no POSITION attribute"))?;
        let count = positions.count();
        let start = self.positions.len();
        // Positions first: their accessor's count is then known to be backed by bytes.
        read_accessor::vec3(src, &positions, &mut self.positions)
            .map_err(|e| format!("{what}: {e}"))?;
        let first = self.triangles.len();
        let too_many = || format!("{what}: too many vertices");
        match (prim.indices(), prim.mode()) {
            (Some(a), Mode::Triangles) => {
                read_accessor::triangle_list(src, &a, &mut self.triangles)
                    .map_err(|e| format!("{what}: {e}"))?;
            }
            (None, Mode::Triangles) => {
                let n = u32::try_from(count).map_err(|_| too_many())? / 3;
                self.triangles
                    .extend((0..n).map(|k| [3 * k, 3 * k + 1, 3 * k + 2]));
            }
            (indices, mode) => {
                let idx = match indices {
                    Some(a) => {
                        read_accessor::indices(src, &a).map_err(|e| format!("{what}: {e}"))?
                    }
                    None => (0..u32::try_from(count).map_err(|_| too_many())?).collect(),
                };
                match triangles(mode, &idx) {
                    Some(tris) => self.triangles.extend(tris),
                    None => {
                        self.positions.truncate(start);
                        self.skipped_primitives += 1;
                        return Ok(());
                    }
                }
            }
        }
        let linear = world.fixed_view::<3, 3>(0, 0).into_owned();
        let shift = world.fixed_view::<3, 1>(0, 3).into_owned();
        // A mirroring transform turns counter-clockwise triangles clockwise.
        let mirror = linear.determinant() < 0.0;
        // Out-of-range indices are refused below, before `base` is known to fit; until
        // then the sums may wrap.
        let base = start as u32;
        for t in &mut self.triangles[first..] {
            if let Some(bad) = t.iter().find(|&&i| i as usize >= count) {
                return Err(format!(
                    "{what}: index {bad} is out of range ({count} vertices)"
                ));
            }
            if mirror {
                t.swap(1, 2);
            }
            *t = t.map(|i| i.wrapping_add(base));
        }
        let tris = self.triangles.len() - first;
        let uv = match prim.get(&gltf::Semantic::TexCoords(0)) {
            Some(a) if a.count() != count => {
                return Err(format!(
                    "{what}: TEXCOORD_0 has {} elements, POSITION {count}",
                    a.count()
                ));
            }
            Some(a) => {
                self.uv.resize(start, Vector2::new(f64::NAN, f64::NAN));
                read_accessor::vec2(src, &a, &mut self.uv).map_err(|e| format!("{what}: {e}"))?;
                for c in &mut self.uv[start..] {
                    c.y = super::flip_v(c.y);
                }
                true
            }
            None => false,
        };
        u32::try_from(start)
            .ok()
            .filter(|b| b.checked_add(count as u32).is_some_and(|e| e < NONE))
            .ok_or_else(|| format!("{what}: more than 2^32 - 1 vertices in all"))?;
        if *world != Matrix4::identity() {
            for q in &mut self.positions[start..] {
                *q = linear * *q + shift;
            }
        }
        if uv {
            self.textured += tris;
            if self.texture.is_none() {
                self.texture = read_texture::base_colour(&prim.material(), &src.buffers, file)?;
            }
        } else {
            if !self.uv.is_empty() {
                self.uv
                    .resize(start + count, Vector2::new(f64::NAN, f64::NAN));
            }
            self.untextured.push(first..first + tris);
        }
        Ok(())
    }

    fn finish(mut self) -> Result<(TriMesh, LoadNotes), String> {
        if self.triangles.is_empty() && self.skipped_primitives > 0 {
            return Err(format!(
                "no triangles: the {} primitives read are points or lines (mode POINTS, \
                 LINES, LINE_LOOP or LINE_STRIP), which make no surface",
                self.skipped_primitives
            ));
        }
        let gathered = self.positions.len();
        let map = weld::weld(&mut self.positions);
        let mut notes = LoadNotes {
            polygons: self.triangles.len(),
            welded_vertices: gathered - self.positions.len(),
            skipped_primitives: self.skipped_primitives,
            ..LoadNotes::default()
        };
        // Without a merge every index already is its welded one.
        let welded = |t: &[[u32; 3]]| -> Vec<[u32; 3]> {
            match &map {
                Some(map) => t.iter().map(|t| t.map(|i| map[i as usize])).collect(),
                None => t.to_vec(),
            }
        };
        let mut uv = None;
        let triangles = if self.textured == 0 {
            match &map {
                Some(_) => welded(&self.triangles),
                None => self.triangles,
            }
        } else {
            let triangles = welded(&self.triangles);
            let mut faces = self.triangles;
            for r in self.untextured {
                faces[r].fill([NONE; 3]);
            }
            let coords = std::mem::take(&mut self.uv);
            uv = notes.corner_uv(TexCoords { coords, faces }, self.textured);
            triangles
        };
        notes.texture = self.texture.filter(|_| uv.is_some() || notes.uv_dropped);
        Ok((
            TriMesh {
                positions: self.positions,
                triangles,
                uv,
            },
            notes,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strips_and_fans_follow_the_specification() {
        let idx = [0, 1, 2, 3, 4];
        assert_eq!(
            triangles(Mode::TriangleStrip, &idx).unwrap(),
            [[0, 1, 2], [2, 1, 3], [2, 3, 4]]
        );
        assert_eq!(
            triangles(Mode::TriangleFan, &idx).unwrap(),
            [[1, 2, 0], [2, 3, 0], [3, 4, 0]]
        );
        assert_eq!(triangles(Mode::Triangles, &idx).unwrap(), [[0, 1, 2]]);
        assert!(triangles(Mode::TriangleStrip, &[0, 1]).unwrap().is_empty());
        assert!(triangles(Mode::Lines, &idx).is_none());
    }
}
