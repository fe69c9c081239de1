//! The PLY writer: binary little endian, written record by record.

use std::io::Write;

use crate::mesh::TriMesh;

/// Binary little-endian PLY with double positions, `uint` indices and, when the mesh has
/// texture coordinates, a per-face `texcoord` list of doubles.
pub(crate) fn write(mesh: &TriMesh) -> std::io::Result<Vec<u8>> {
    let uv = mesh
        .uv
        .as_ref()
        .filter(|uv| uv.faces.len() == mesh.triangles.len());
    let face_bytes = 13 + if uv.is_some() { 1 + 48 } else { 0 };
    let mut out =
        Vec::with_capacity(256 + 24 * mesh.positions.len() + face_bytes * mesh.triangles.len());
    write!(
        out,
        "ply\nformat binary_little_endian 1.0\ncomment written by wavg\n\
         element vertex {}\nproperty double x\nproperty double y\nproperty double z\n\
         element face {}\nproperty list uchar uint vertex_indices\n",
        mesh.positions.len(),
        mesh.triangles.len()
    )?;
    if uv.is_some() {
        out.extend_from_slice(b"property list uchar double texcoord\n");
    }
    out.extend_from_slice(b"end_header\n");
    for p in &mesh.positions {
        for c in [p.x, p.y, p.z] {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    for (f, t) in mesh.triangles.iter().enumerate() {
        out.push(3);
        for i in t {
            out.extend_from_slice(&i.to_le_bytes());
        }
        if let Some(uv) = uv {
            out.push(6);
            for &i in &uv.faces[f] {
                let c = uv.coords.get(i as usize).copied().unwrap_or_default();
                out.extend_from_slice(&c.x.to_le_bytes());
                out.extend_from_slice(&c.y.to_le_bytes());
            }
        }
    }
    Ok(out)
}
