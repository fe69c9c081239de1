//! Geometric quantities: areas, normals, edge lengths, the cotangent stiffness and lumped
//! mass matrices.
//!
//! These take a `&TriMesh` so that they also serve repairs and diagnostics, but they assume
//! face indices are in range (they index positions directly and panic otherwise): pass a
//! [`crate::ValidMesh`] (it derefs to `TriMesh`) unless the mesh is known to be sound.

use faer::sparse::{SparseColMat, Triplet};
use nalgebra::Vector3;

use crate::error::MeshError;
use crate::mesh::TriMesh;

/// Area of triangle `f`.
pub fn face_area(mesh: &TriMesh, f: usize) -> f64 {
    let [a, b, c] = mesh.corners(f);
    0.5 * (b - a).cross(&(c - a)).norm()
}

/// Areas of all triangles.
pub fn face_areas(mesh: &TriMesh) -> Vec<f64> {
    (0..mesh.n_faces()).map(|f| face_area(mesh, f)).collect()
}

/// Unit normal of triangle `f` (zero for a degenerate face).
pub fn face_normal(mesh: &TriMesh, f: usize) -> Vector3<f64> {
    let [a, b, c] = mesh.corners(f);
    (b - a)
        .cross(&(c - a))
        .try_normalize(0.0)
        .unwrap_or_else(Vector3::zeros)
}

/// Unit normals of all triangles.
pub fn face_normals(mesh: &TriMesh) -> Vec<Vector3<f64>> {
    (0..mesh.n_faces()).map(|f| face_normal(mesh, f)).collect()
}

/// Angle-weighted vertex normals (Thürmer & Wüthrich): insensitive to how the one-ring is
/// triangulated. Vertices with no faces get zero.
///
/// ```
/// use wavg_mesh::{geometry, procedural};
/// let m = procedural::icosphere(3);
/// let n = geometry::vertex_normals(&m);
/// assert!((n[0] - m.positions[0]).norm() < 0.01);
/// ```
pub fn vertex_normals(mesh: &TriMesh) -> Vec<Vector3<f64>> {
    let mut n = vec![Vector3::zeros(); mesh.n_vertices()];
    for (f, t) in mesh.triangles.iter().enumerate() {
        let fnorm = face_normal(mesh, f);
        let p = mesh.corners(f);
        for c in 0..3 {
            let e1 = p[(c + 1) % 3] - p[c];
            let e2 = p[(c + 2) % 3] - p[c];
            let angle = e1.angle(&e2);
            if angle.is_finite() {
                n[t[c] as usize] += fnorm * angle;
            }
        }
    }
    for v in &mut n {
        *v = v.try_normalize(0.0).unwrap_or_else(Vector3::zeros);
    }
    n
}

/// Mean length over all face edges (interior edges counted twice; fine as a scale).
pub fn mean_edge_length(mesh: &TriMesh) -> f64 {
    if mesh.n_faces() == 0 {
        return 0.0;
    }
    let mut sum = 0.0;
    for f in 0..mesh.n_faces() {
        let [a, b, c] = mesh.corners(f);
        sum += (b - a).norm() + (c - b).norm() + (a - c).norm();
    }
    sum / (3 * mesh.n_faces()) as f64
}

/// Cotangent weights of triangle `f`: entry `i` is `cot` of the angle at corner `i`,
/// which weighs the opposite edge `(i+1, i+2)`.
pub fn cotangents(mesh: &TriMesh, f: usize) -> [f64; 3] {
    let p = mesh.corners(f);
    let mut out = [0.0; 3];
    for (i, o) in out.iter_mut().enumerate() {
        let e1 = p[(i + 1) % 3] - p[i];
        let e2 = p[(i + 2) % 3] - p[i];
        let cross = e1.cross(&e2).norm();
        *o = if cross > 0.0 {
            e1.dot(&e2) / cross
        } else {
            0.0
        };
    }
    out
}

/// The cotangent stiffness matrix `L` (n x n, symmetric).
///
/// Sign convention: `L` is **positive semidefinite**: off-diagonal
/// `L_ij = -(cot a_ij + cot b_ij) / 2` and `L_ii = -sum_j L_ij`, so rows sum to zero and
/// `u^T L u = ∫ |∇u|^2` (the Dirichlet energy, doubled halves) for piecewise-linear `u`.
///
/// ```
/// use wavg_mesh::{geometry, procedural};
/// let m = procedural::grid(3, 3, 1.0, 1.0);
/// let l = geometry::cotan_stiffness(&m).unwrap();
/// assert_eq!(l.nrows(), 16);
/// ```
pub fn cotan_stiffness(mesh: &TriMesh) -> Result<SparseColMat<usize, f64>, MeshError> {
    let n = mesh.n_vertices();
    let mut trip = Vec::with_capacity(mesh.n_faces() * 12);
    for (f, t) in mesh.triangles.iter().enumerate() {
        let cot = cotangents(mesh, f);
        for i in 0..3 {
            let (a, b) = (t[(i + 1) % 3] as usize, t[(i + 2) % 3] as usize);
            let w = 0.5 * cot[i];
            trip.push(Triplet::new(a, b, -w));
            trip.push(Triplet::new(b, a, -w));
            trip.push(Triplet::new(a, a, w));
            trip.push(Triplet::new(b, b, w));
        }
    }
    SparseColMat::try_new_from_triplets(n, n, &trip)
        .map_err(|e| MeshError::InvalidArgument(format!("cannot assemble stiffness matrix: {e:?}")))
}

/// Lumped (barycentric) mass: one third of the area of each incident face per vertex.
///
/// ```
/// use wavg_mesh::{geometry, procedural};
/// let m = procedural::grid(4, 4, 2.0, 1.0);
/// let total: f64 = geometry::lumped_mass(&m).iter().sum();
/// assert!((total - 2.0).abs() < 1e-12);
/// ```
pub fn lumped_mass(mesh: &TriMesh) -> Vec<f64> {
    let mut m = vec![0.0; mesh.n_vertices()];
    for (f, t) in mesh.triangles.iter().enumerate() {
        let a = face_area(mesh, f) / 3.0;
        for &v in t {
            m[v as usize] += a;
        }
    }
    m
}

/// The lumped mass as a diagonal sparse matrix.
pub fn lumped_mass_matrix(mesh: &TriMesh) -> Result<SparseColMat<usize, f64>, MeshError> {
    let m = lumped_mass(mesh);
    let trip: Vec<_> = m
        .iter()
        .enumerate()
        .map(|(i, &x)| Triplet::new(i, i, x))
        .collect();
    SparseColMat::try_new_from_triplets(m.len(), m.len(), &trip)
        .map_err(|e| MeshError::InvalidArgument(format!("cannot assemble mass matrix: {e:?}")))
}
