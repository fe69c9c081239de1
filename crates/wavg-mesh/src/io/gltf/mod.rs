//! glTF 2.0 (`.glb`, `.gltf` + `.bin`).

mod write;
mod write_doc;
mod write_mesh;

pub use write::{
    GltfKind, GltfMesh, GltfPolyline, GltfScene, VertexAttribute, bin_path, is_gltf_path,
};
