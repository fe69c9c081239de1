//! The mesh file formats and what a reader noticed about a file.

use std::path::Path;

use crate::error::MeshError;

/// Facts about a file that the [`TriMesh`](crate::TriMesh) does not keep, for diagnostics (`wavg info`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LoadNotes {
    /// The format that was read.
    pub format: Option<Format>,
    /// Polygons read from the file, before fan triangulation.
    pub polygons: usize,
    /// Polygons with more than three corners (they were fan-triangulated).
    pub non_triangles: usize,
    /// Faces with fewer than three corners (OBJ 1- and 2-index faces), skipped.
    pub skipped_faces: usize,
    /// Texture coordinates were present on some but not all faces and were dropped.
    pub uv_dropped: bool,
    /// The file's polygon (0-based, in file order) each triangle came from, so that the
    /// diagonals fan triangulation added can be told from the file's own edges (a
    /// wireframe of a quad mesh draws quads). Empty when every polygon was a triangle.
    pub polygon_of: Vec<u32>,
    /// When texture coordinates were dropped ([`Self::uv_dropped`], OBJ): the ones the file
    /// had, the corners of the triangles without them being [`NONE`](crate::NONE), for
    /// a renderer that draws those faces untextured.
    pub partial_uv: Option<crate::TexCoords>,
    /// Vertices merged into others by welding exactly equal positions (glTF, whose files
    /// split a vertex wherever its texture coordinate or normal changes); 0 for the other
    /// formats, which keep the file's vertices.
    pub welded_vertices: usize,
    /// glTF primitives of points or lines, skipped (they make no surface).
    pub skipped_primitives: usize,
    /// The glTF material's base colour texture, when the file has one on its textured
    /// primitives (the first such primitive's).
    pub texture: Option<super::gltf::TextureSource>,
}

impl LoadNotes {
    /// The per-corner texture coordinates of a mesh whose `uv.faces` has one entry per
    /// triangle, `textured` of them with coordinates (the others [`NONE`](crate::NONE)):
    /// all of them when every triangle has some; otherwise none, and when only some do,
    /// [`Self::uv_dropped`] set and the coordinates kept in [`Self::partial_uv`].
    pub(crate) fn corner_uv(
        &mut self,
        uv: crate::TexCoords,
        textured: usize,
    ) -> Option<crate::TexCoords> {
        if textured == 0 {
            return None;
        }
        if textured == uv.faces.len() {
            return Some(uv);
        }
        self.uv_dropped = true;
        self.partial_uv = Some(uv);
        None
    }

    /// Records that the polygon just counted in `polygons` became `triangles` triangles.
    pub(crate) fn fan(&mut self, triangles: usize) {
        let id = u32::try_from(self.polygons.saturating_sub(1)).unwrap_or(u32::MAX);
        self.polygon_of.extend(std::iter::repeat_n(id, triangles));
    }
}

/// The mesh file formats wavg reads and writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Wavefront OBJ (positions, texture coordinates, polygons).
    Obj,
    /// Object File Format (ASCII).
    Off,
    /// Stanford PLY (ASCII or binary).
    Ply,
    /// glTF 2.0 as JSON (`.gltf`), its buffers and images beside it or as `data:` URIs.
    Gltf,
    /// glTF 2.0 binary (`.glb`).
    Glb,
}

impl Format {
    /// The format for a path from its extension (a trailing `.gz` is looked through; so
    /// is a glTF mesh name, `scene.glb#Body`), and whether the file is gzip-compressed.
    ///
    /// ```
    /// use wavg_mesh::Format;
    /// use std::path::Path;
    /// assert_eq!(Format::from_path(Path::new("a/b.off.gz")).unwrap(), (Format::Off, true));
    /// assert_eq!(Format::from_path(Path::new("s.glb#Body")).unwrap(), (Format::Glb, false));
    /// assert!(Format::from_path(Path::new("b.stl")).is_err());
    /// ```
    pub fn from_path(path: &Path) -> Result<(Format, bool), MeshError> {
        let (file, _) = super::gltf::split_mesh_name(path);
        let name = file
            .file_name()
            .map(|n| n.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        let (stem, gz) = match name.strip_suffix(".gz") {
            Some(s) => (s.to_string(), true),
            None => (name.clone(), false),
        };
        let ext = Path::new(&stem)
            .extension()
            .map(|e| e.to_string_lossy().into_owned())
            .unwrap_or_default();
        let format = match ext.as_str() {
            "obj" => Format::Obj,
            "off" => Format::Off,
            "ply" => Format::Ply,
            "gltf" => Format::Gltf,
            "glb" => Format::Glb,
            _ => {
                let what = match ext.as_str() {
                    "" => "no extension".to_string(),
                    _ => format!("unknown extension {:?}", format!(".{ext}")),
                };
                return Err(MeshError::Unsupported {
                    path: path.to_path_buf(),
                    message: format!(
                        "{what} (expected .obj, .off, .ply, optionally .gz, or .gltf, .glb)"
                    ),
                });
            }
        };
        Ok((format, gz))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{NONE, TexCoords};
    use nalgebra::Vector2;

    #[test]
    fn corner_uv_keeps_all_drops_some_and_ignores_none() {
        let uv = TexCoords {
            coords: vec![Vector2::new(0.5, 0.5)],
            faces: vec![[0; 3], [NONE; 3]],
        };
        let mut n = LoadNotes::default();
        assert_eq!(n.corner_uv(uv.clone(), 0), None);
        assert!(!n.uv_dropped && n.partial_uv.is_none());
        assert_eq!(n.corner_uv(uv.clone(), 1), None);
        assert!(n.uv_dropped && n.partial_uv == Some(uv.clone()));
        let mut n = LoadNotes::default();
        assert_eq!(n.corner_uv(uv.clone(), 2), Some(uv));
        assert!(!n.uv_dropped && n.partial_uv.is_none());
    }
}
