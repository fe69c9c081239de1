//! Points on the surface: a face and barycentric coordinates.

use nalgebra::Vector3;

use crate::mesh::{FaceId, TriMesh};

/// A point on the surface: a face and barycentric coordinates (summing to 1) with respect
/// to its corners in order.
///
/// ```
/// use wavg_mesh::{SurfacePoint, procedural};
/// let m = procedural::grid(1, 1, 1.0, 1.0);
/// let p = SurfacePoint::new(0, [1.0 / 3.0; 3]);
/// assert!((p.position(&m).z).abs() < 1e-12);
/// let x: f64 = p.interpolate(&m, &[0.0, 3.0, 6.0, 9.0]);
/// assert!(x > 0.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// The face.
    pub face: FaceId,
    /// Barycentric coordinates with respect to the face's corners.
    pub bary: [f64; 3],
}

impl SurfacePoint {
    /// A surface point.
    pub fn new(face: FaceId, bary: [f64; 3]) -> Self {
        Self { face, bary }
    }

    /// The point at corner `corner` of `face`.
    pub fn at_corner(face: FaceId, corner: usize) -> Self {
        let mut bary = [0.0; 3];
        bary[corner.min(2)] = 1.0;
        Self { face, bary }
    }

    /// Its 3-D position on `mesh`.
    pub fn position(&self, mesh: &TriMesh) -> Vector3<f64> {
        let p = mesh.corners(self.face as usize);
        p[0] * self.bary[0] + p[1] * self.bary[1] + p[2] * self.bary[2]
    }

    /// Linear interpolation of any per-vertex attribute (positions, UVs, embeddings, ...).
    pub fn interpolate<T>(&self, mesh: &TriMesh, values: &[T]) -> T
    where
        T: Copy + std::ops::Mul<f64, Output = T> + std::ops::Add<Output = T>,
    {
        let t = mesh.triangles[self.face as usize];
        values[t[0] as usize] * self.bary[0]
            + values[t[1] as usize] * self.bary[1]
            + values[t[2] as usize] * self.bary[2]
    }
}
