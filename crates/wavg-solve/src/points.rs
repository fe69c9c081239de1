//! Surface locations given by users (a vertex, or a face with barycentrics): validation
//! against a mesh and conversion to a [`SurfacePoint`].

use wavg_mesh::{SurfacePoint, TriMesh, ValidMesh, VertexId};

use crate::error::SolveError;

/// Accepted deviation of barycentric coordinates: each may be as low as `-BARY_TOLERANCE`
/// and their sum may differ from 1 by this much (they are then clamped and renormalised).
pub const BARY_TOLERANCE: f64 = 1e-6;

/// A location on the surface: a mesh vertex or a point inside a face.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Anchor {
    /// A mesh vertex (0-based).
    Vertex(VertexId),
    /// A face and barycentric coordinates.
    Point(SurfacePoint),
}

impl From<VertexId> for Anchor {
    fn from(v: VertexId) -> Self {
        Anchor::Vertex(v)
    }
}

impl From<SurfacePoint> for Anchor {
    fn from(p: SurfacePoint) -> Self {
        Anchor::Point(p)
    }
}

/// The barycentric rule of [`check_point`], which needs no mesh: finite, none below
/// `-BARY_TOLERANCE` (outside the face), summing to 1 within [`BARY_TOLERANCE`].
pub fn check_barycentrics(p: &SurfacePoint) -> Result<(), SolveError> {
    let bad = |reason| SolveError::BadBarycentrics {
        face: p.face,
        bary: p.bary,
        reason,
    };
    if !p.bary.iter().all(|b| b.is_finite()) {
        return Err(bad("not finite"));
    }
    if p.bary.iter().any(|&b| b < -BARY_TOLERANCE) {
        return Err(bad("negative (the point is outside the face)"));
    }
    let sum: f64 = p.bary.iter().sum();
    if (sum - 1.0).abs() > BARY_TOLERANCE {
        return Err(bad("they do not sum to 1"));
    }
    Ok(())
}

/// Checks a surface point: face in range, barycentrics finite, none below
/// `-BARY_TOLERANCE`, summing to 1 within `BARY_TOLERANCE`. Returns it with negatives
/// clamped to zero and the sum renormalised to 1.
///
/// ```
/// use wavg_mesh::{SurfacePoint, procedural};
/// use wavg_solve::check_point;
/// let m = procedural::icosphere(1);
/// assert!(check_point(&m, &SurfacePoint::new(3, [0.2, 0.3, 0.5])).is_ok());
/// assert!(check_point(&m, &SurfacePoint::new(3, [0.2, 0.3, 0.6])).is_err());
/// assert!(check_point(&m, &SurfacePoint::new(9999, [1.0, 0.0, 0.0])).is_err());
/// ```
pub fn check_point(mesh: &TriMesh, p: &SurfacePoint) -> Result<SurfacePoint, SolveError> {
    if p.face as usize >= mesh.n_faces() {
        return Err(SolveError::FaceOutOfRange {
            face: p.face as u64,
            count: mesh.n_faces(),
        });
    }
    check_barycentrics(p)?;
    let c = p.bary.map(|b| b.max(0.0));
    let s: f64 = c.iter().sum();
    Ok(SurfacePoint::new(p.face, c.map(|b| b / s)))
}

/// The surface point at vertex `v` (a corner of one of its faces).
pub fn vertex_point(mesh: &ValidMesh, v: VertexId) -> Result<SurfacePoint, SolveError> {
    if v as usize >= mesh.n_vertices() {
        return Err(SolveError::VertexOutOfRange {
            vertex: v as u64,
            count: mesh.n_vertices(),
        });
    }
    // A valid mesh has no unreferenced vertex, so every vertex has a face.
    let f = mesh.topology().ring_faces(v)[0];
    let corner = mesh.triangles[f as usize]
        .iter()
        .position(|&c| c == v)
        .unwrap_or(0);
    Ok(SurfacePoint::at_corner(f, corner))
}

/// Validates `a` against `mesh` and returns it as a surface point.
pub fn resolve_anchor(mesh: &ValidMesh, a: &Anchor) -> Result<SurfacePoint, SolveError> {
    match a {
        Anchor::Vertex(v) => vertex_point(mesh, *v),
        Anchor::Point(p) => check_point(mesh, p),
    }
}

/// The mesh vertex a search for this point should start from: the corner with the
/// largest barycentric coordinate (the vertex itself for a vertex).
pub fn nearest_corner(mesh: &TriMesh, p: &SurfacePoint) -> VertexId {
    let mut best = 0;
    for i in 1..3 {
        if p.bary[i] > p.bary[best] {
            best = i;
        }
    }
    mesh.triangles[p.face as usize][best]
}

#[cfg(test)]
mod tests {
    use super::*;
    use wavg_mesh::procedural;

    #[test]
    fn every_malformed_point_is_a_typed_error() {
        let m = ValidMesh::new(procedural::icosphere(1)).unwrap();
        let nf = m.n_faces() as u32;
        let bad = |f, b| check_point(&m, &SurfacePoint::new(f, b));
        assert!(matches!(
            bad(nf, [1.0, 0.0, 0.0]),
            Err(SolveError::FaceOutOfRange { .. })
        ));
        for b in [
            [f64::NAN, 0.5, 0.5],
            [f64::INFINITY, 0.0, 0.0],
            [-0.1, 0.6, 0.5],
            [0.5, 0.5, 0.5],
            [0.0, 0.0, 0.0],
        ] {
            assert!(
                matches!(bad(0, b), Err(SolveError::BadBarycentrics { .. })),
                "{b:?}"
            );
        }
        let p = bad(0, [-1e-7, 0.5, 0.5 + 1e-7]).unwrap();
        assert_eq!(p.bary[0], 0.0);
        assert!((p.bary.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        assert!(matches!(
            resolve_anchor(&m, &Anchor::Vertex(m.n_vertices() as u32)),
            Err(SolveError::VertexOutOfRange { .. })
        ));
        for v in 0..m.n_vertices() as u32 {
            let p = vertex_point(&m, v).unwrap();
            assert_eq!(p.position(&m), m.positions[v as usize]);
            assert_eq!(nearest_corner(&m, &p), v);
        }
    }
}
