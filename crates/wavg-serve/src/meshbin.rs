//! The binary body of `GET /api/mesh`, little-endian throughout:
//!
//! | offset | type | content |
//! |---|---|---|
//! | 0 | `u32` | vertex count `n` |
//! | 4 | `u32` | triangle count `m` |
//! | 8 | `f32 × 3n` | positions `x y z` per vertex |
//! | 8 + 12n | `u32 × 3m` | triangles (0-based vertex ids, counter-clockwise) |
//! | 8 + 12n + 12m | `f32 × 3n` | unit vertex normals (area-weighted) |
//!
//! Every section starts at a multiple of 4 bytes, so a page can view it as typed arrays
//! without copying.

use wavg::ValidMesh;

/// Encodes the mesh as the layout above.
pub fn encode_mesh(mesh: &ValidMesh) -> Vec<u8> {
    let (n, m) = (mesh.n_vertices(), mesh.n_faces());
    let mut out = Vec::with_capacity(8 + 24 * n + 12 * m);
    out.extend_from_slice(&(n as u32).to_le_bytes());
    out.extend_from_slice(&(m as u32).to_le_bytes());
    for p in &mesh.positions {
        for x in p.iter() {
            out.extend_from_slice(&(*x as f32).to_le_bytes());
        }
    }
    for t in &mesh.triangles {
        for v in t {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    for nrm in wavg::mesh::geometry::vertex_normals(mesh) {
        for x in nrm.iter() {
            let x = if x.is_finite() { *x as f32 } else { 0.0 };
            out.extend_from_slice(&x.to_le_bytes());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_round_trips() {
        let mesh = ValidMesh::new(wavg::mesh::procedural::icosphere(1)).unwrap();
        let b = encode_mesh(&mesh);
        let u32_at = |o: usize| u32::from_le_bytes(b[o..o + 4].try_into().unwrap());
        let f32_at = |o: usize| f32::from_le_bytes(b[o..o + 4].try_into().unwrap());
        let (n, m) = (u32_at(0) as usize, u32_at(4) as usize);
        assert_eq!((n, m), (mesh.n_vertices(), mesh.n_faces()));
        assert_eq!(b.len(), 8 + 24 * n + 12 * m);
        assert_eq!(f32_at(8 + 12 * 5 + 4), mesh.positions[5].y as f32);
        assert_eq!(u32_at(8 + 12 * n + 12 * 7 + 8), mesh.triangles[7][2]);
        // The icosphere's normals point away from its centre.
        let o = 8 + 12 * n + 12 * m;
        for v in 0..n {
            let nrm = [0, 1, 2].map(|k| f32_at(o + 12 * v + 4 * k));
            let p = mesh.positions[v];
            let dot: f64 = (0..3).map(|k| f64::from(nrm[k]) * p[k]).sum();
            assert!(dot > 0.9, "vertex {v}: {dot}");
        }
    }
}
