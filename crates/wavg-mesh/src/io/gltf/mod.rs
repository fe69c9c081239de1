//! glTF 2.0: `.gltf` (JSON, with its buffers and images as files beside it or as `data:`
//! URIs) and `.glb` (the binary container), read and written.
//!
//! The `gltf` crate parses and validates the JSON (every index it holds refers to
//! something that exists); buffers, accessors and images are read here, every declared
//! size and offset checked against the bytes really present before anything is
//! allocated, so memory stays proportional to the file (see [`read_limits`]).
//!
//! What is read: the triangles of every mesh primitive of the default scene (or the first
//! scene; with no scene, every mesh once), with the node transforms applied, strips and
//! fans triangulated; `TEXCOORD_0` as per-corner texture coordinates; the base colour
//! texture of the first textured primitive. The primitives are welded into one surface by
//! exactly equal positions (glTF splits a vertex wherever its UV or normal changes).
//! A path `scene.glb#Body` reads only the mesh named `Body` (or, when no mesh has that
//! name, the meshes of the nodes named so).

mod read;
mod read_accessor;
mod read_buffers;
pub mod read_limits;
mod read_texture;
mod weld;
mod write;
mod write_doc;
mod write_mesh;

use std::path::{Path, PathBuf};

pub(crate) use read::parse;
pub use read_texture::TextureSource;
pub use write::{
    GltfKind, GltfMesh, GltfPolyline, GltfScene, VertexAttribute, bin_path, is_gltf_path,
};

/// Splits `scene.glb#Name` (or `scene.gltf#Name`) into the file and the mesh name; any
/// other path is returned whole with no name. The suffix is recognised after the first
/// `.glb#` or `.gltf#` of the file name (any case), so mesh names may hold `#`.
pub fn split_mesh_name(path: &Path) -> (PathBuf, Option<String>) {
    let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
        return (path.to_path_buf(), None);
    };
    let lower = name.to_ascii_lowercase();
    let cut = [".glb#", ".gltf#"]
        .iter()
        .filter_map(|ext| lower.find(ext).map(|i| i + ext.len()))
        .min();
    match cut {
        Some(end) => (
            path.with_file_name(&name[..end - 1]),
            Some(name[end..].to_string()),
        ),
        None => (path.to_path_buf(), None),
    }
}

/// glTF's texture coordinates have v running down the image; wavg's (like OBJ's `vt`)
/// run up: `v_wavg = 1 - v_gltf`, and back the same way.
pub(crate) fn flip_v(v: f64) -> f64 {
    1.0 - v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_hash_suffix_names_a_mesh_only_after_a_gltf_extension() {
        let s = |p: &str| split_mesh_name(Path::new(p));
        assert_eq!(
            s("a/scene.glb#Body"),
            (PathBuf::from("a/scene.glb"), Some("Body".into()))
        );
        assert_eq!(
            s("scene.GLTF#a#b"),
            (PathBuf::from("scene.GLTF"), Some("a#b".into()))
        );
        assert_eq!(
            s("scene.glb#"),
            (PathBuf::from("scene.glb"), Some("".into()))
        );
        assert_eq!(s("dir#x/m.obj"), (PathBuf::from("dir#x/m.obj"), None));
        assert_eq!(s("m#1.obj"), (PathBuf::from("m#1.obj"), None));
        assert_eq!(s("m.glb"), (PathBuf::from("m.glb"), None));
    }
}
