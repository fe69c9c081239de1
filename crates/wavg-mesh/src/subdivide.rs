//! Loop subdivision: each level splits every triangle into four and smooths the result
//! (Loop 1987, with the standard boundary rules), so large test meshes can be made
//! reproducibly from smaller ones.

use nalgebra::Vector3;

use crate::error::MeshError;
use crate::mesh::{NONE, TexCoords, TriMesh, VertexId};
use crate::valid::ValidMesh;

/// Largest vertex count [`loop_subdivide`] will produce (vertex ids are `u32`).
pub const MAX_VERTICES: usize = u32::MAX as usize / 2;

/// One level of Loop subdivision of a valid mesh: old vertices first (same ids, smoothed
/// positions), then one new vertex per edge; four triangles per triangle, in face order
/// (children of face `f` are faces `4f..4f+4`, the corner children first, the middle last).
/// Texture coordinates are subdivided linearly (each child corner gets its parent's corner
/// or the midpoint of its parent's edge, so seams stay seams). Boundaries keep their cubic
/// B-spline rules, so the boundary curve only depends on boundary vertices.
///
/// ```
/// use wavg_mesh::{ValidMesh, procedural, subdivide::loop_subdivide};
/// let m = ValidMesh::new(procedural::icosphere(1)).unwrap();
/// let s = loop_subdivide(&m).unwrap();
/// assert_eq!(s.n_faces(), 4 * m.n_faces());
/// assert_eq!(s.n_vertices(), m.n_vertices() + m.n_faces() * 3 / 2);
/// ```
pub fn loop_subdivide(mesh: &ValidMesh) -> Result<TriMesh, MeshError> {
    let topo = mesh.topology();
    let nv = mesh.n_vertices();
    let nf = mesh.n_faces();
    let tris = &mesh.triangles;
    let pos = &mesh.positions;

    // One id per edge, shared by the two faces across it.
    let mut edge_vertex = vec![NONE; 3 * nf];
    let mut next = nv;
    for f in 0..nf {
        let nb = topo.face_neighbors(f as u32);
        for i in 0..3 {
            if edge_vertex[3 * f + i] != NONE {
                continue;
            }
            if next >= MAX_VERTICES {
                return Err(MeshError::InvalidArgument(format!(
                    "subdividing {nv} vertices would exceed {MAX_VERTICES} vertices"
                )));
            }
            edge_vertex[3 * f + i] = next as VertexId;
            let g = nb[i];
            if g != NONE {
                let (s, e) = (tris[f][i], tris[f][(i + 1) % 3]);
                let t = tris[g as usize];
                if let Some(j) = (0..3).find(|&j| t[j] == e && t[(j + 1) % 3] == s) {
                    edge_vertex[3 * g as usize + j] = next as VertexId;
                }
            }
            next += 1;
        }
    }

    let mut out = vec![Vector3::zeros(); next];
    // Old vertices: Loop's (Warren's original) weights inside, 1/8-3/4-1/8 on boundaries.
    for (v, p) in out.iter_mut().enumerate().take(nv) {
        let ring = topo.ring(v as VertexId);
        let here = pos[v];
        *p = if topo.is_boundary_vertex(v as VertexId) {
            let (a, b) = (ring[0], ring[ring.len() - 1]);
            here * 0.75 + (pos[a as usize] + pos[b as usize]) * 0.125
        } else {
            let k = ring.len() as f64;
            let c = 0.375 + 0.25 * (2.0 * std::f64::consts::PI / k).cos();
            let beta = (0.625 - c * c) / k;
            let sum: Vector3<f64> = ring.iter().map(|&u| pos[u as usize]).sum();
            here * (1.0 - k * beta) + sum * beta
        };
    }
    // Edge vertices: 3/8 of each end and 1/8 of each opposite corner; midpoints on
    // boundaries.
    for f in 0..nf {
        let nb = topo.face_neighbors(f as u32);
        for i in 0..3 {
            let id = edge_vertex[3 * f + i] as usize;
            let (a, b, c) = (tris[f][i], tris[f][(i + 1) % 3], tris[f][(i + 2) % 3]);
            let (pa, pb) = (pos[a as usize], pos[b as usize]);
            out[id] = match nb[i] {
                NONE => (pa + pb) * 0.5,
                g => {
                    let t = tris[g as usize];
                    let d = t.iter().copied().find(|&x| x != a && x != b).unwrap_or(c);
                    (pa + pb) * 0.375 + (pos[c as usize] + pos[d as usize]) * 0.125
                }
            };
        }
    }

    let mut faces = Vec::with_capacity(4 * nf);
    for (f, t) in tris.iter().enumerate() {
        let [ab, bc, ca] = [0, 1, 2].map(|i| edge_vertex[3 * f + i]);
        let [a, b, c] = *t;
        faces.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
    }
    let mut result = TriMesh::new(out, faces);
    result.uv = mesh.uv.as_ref().map(subdivide_uv);
    Ok(result)
}

/// Linear subdivision of per-corner texture coordinates, children in the order of
/// [`loop_subdivide`]'s faces; a midpoint is shared by the faces that share both ends.
fn subdivide_uv(uv: &TexCoords) -> TexCoords {
    let mut coords = uv.coords.clone();
    let mut mid = std::collections::HashMap::new();
    let mut midpoint = |a: u32, b: u32| -> u32 {
        *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
            coords.push((uv.coords[a as usize] + uv.coords[b as usize]) * 0.5);
            (coords.len() - 1) as u32
        })
    };
    let mut faces = Vec::with_capacity(4 * uv.faces.len());
    for &[a, b, c] in &uv.faces {
        let (ab, bc, ca) = (midpoint(a, b), midpoint(b, c), midpoint(c, a));
        faces.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
    }
    TexCoords { coords, faces }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::procedural;

    /// Every child corner's (u, v) is its parent's corner or the midpoint of its parent's
    /// edge, and faces that share an edge share its midpoint.
    #[test]
    fn texture_coordinates_are_subdivided_linearly() {
        let mut mesh = procedural::grid(4, 3, 2.0, 1.0);
        let coords = mesh.positions.iter().map(|p| p.xy() * 0.5).collect();
        let faces = mesh.triangles.clone();
        mesh.uv = Some(TexCoords { coords, faces });
        let m = ValidMesh::new(mesh.clone()).unwrap();
        let s = loop_subdivide(&m).unwrap();
        let (uv, parent) = (s.uv.as_ref().unwrap(), mesh.uv.as_ref().unwrap());
        assert_eq!(uv.faces.len(), 4 * parent.faces.len());
        // One midpoint per edge: (3 F + boundary edges) / 2.
        let boundary = m.topology().boundary_loops().iter().flatten().count();
        let edges = (3 * m.n_faces() + boundary) / 2;
        assert_eq!(uv.coords.len(), parent.coords.len() + edges);
        for (f, t) in parent.faces.iter().enumerate() {
            let [a, b, c] = t.map(|i| parent.coords[i as usize]);
            let want = [
                [a, (a + b) / 2.0, (c + a) / 2.0],
                [(a + b) / 2.0, b, (b + c) / 2.0],
            ];
            for (k, w) in want.iter().enumerate() {
                let got = uv.faces[4 * f + k].map(|i| uv.coords[i as usize]);
                for j in 0..3 {
                    assert!((got[j] - w[j]).norm() < 1e-15, "face {f} child {k}");
                }
            }
        }
    }

    #[test]
    fn counts_and_topology_are_preserved() {
        for mesh in [
            procedural::icosphere(2),
            procedural::torus(12, 8, 1.0, 0.3),
            procedural::grid(5, 4, 1.0, 1.0),
        ] {
            let m = ValidMesh::new(mesh).unwrap();
            let edges = (3 * m.n_faces()
                + m.topology()
                    .boundary_loops()
                    .iter()
                    .map(Vec::len)
                    .sum::<usize>())
                / 2;
            let s = ValidMesh::new(loop_subdivide(&m).unwrap()).unwrap();
            assert_eq!(s.n_vertices(), m.n_vertices() + edges);
            assert_eq!(s.n_faces(), 4 * m.n_faces());
            assert_eq!(s.topology().genus(), m.topology().genus());
            assert_eq!(
                s.topology().boundary_loops().len(),
                m.topology().boundary_loops().len()
            );
            assert_eq!(s.topology().n_components(), 1);
        }
    }

    #[test]
    fn flat_grid_stays_flat_and_boundary_stays_on_its_lines() {
        let m = ValidMesh::new(procedural::grid(6, 5, 2.0, 1.0)).unwrap();
        let s = loop_subdivide(&m).unwrap();
        let (lo, hi) = m.bounding_box().unwrap();
        for p in &s.positions {
            assert!(p.z.abs() < 1e-12);
            assert!(p.x >= lo.x - 1e-12 && p.x <= hi.x + 1e-12);
            assert!(p.y >= lo.y - 1e-12 && p.y <= hi.y + 1e-12);
        }
        // Corners are kept (boundary rule at a corner of the rectangle: its two
        // neighbours lie on different sides, so the bounding box shrinks only if they
        // pull it inward; they do not, being inside the box).
        let (slo, shi) = s.bounding_box().unwrap();
        assert!((slo - lo).norm() < 1e-12 && (shi - hi).norm() < 1e-12);
    }

    #[test]
    fn sphere_converges_towards_a_smooth_surface() {
        // The limit surface of an icosphere is smooth and close to the sphere: radii after
        // two levels stay within a few percent of each other.
        let m = ValidMesh::new(procedural::icosphere(1)).unwrap();
        let s1 = ValidMesh::new(loop_subdivide(&m).unwrap()).unwrap();
        let s2 = loop_subdivide(&s1).unwrap();
        let r: Vec<f64> = s2.positions.iter().map(|p| p.norm()).collect();
        let (min, max) = r
            .iter()
            .fold((f64::MAX, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
        assert!(max / min < 1.05, "radii {min}..{max}");
        assert!(min > 0.85 && max <= 1.0 + 1e-12);
    }
}
