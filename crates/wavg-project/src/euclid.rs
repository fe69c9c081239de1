//! Euclidean closest point on a triangle in R^8: the mesh crate's, at the embedding's
//! dimension.

/// Barycentrics of the point of triangle `(a, b, c)` closest to `p` (see
/// [`wavg_mesh::closest_point_barycentric`]).
///
/// ```
/// use wavg_project::{Vec8, closest_point_barycentric};
/// let a = Vec8::zeros();
/// let b = Vec8::x();
/// let c = Vec8::y();
/// let mut p = Vec8::repeat(0.0);
/// p[0] = 0.25; p[1] = 0.25; p[5] = 3.0;
/// let w = closest_point_barycentric(&p, &a, &b, &c);
/// assert!((w[1] - 0.25).abs() < 1e-12 && (w[2] - 0.25).abs() < 1e-12);
/// ```
pub use wavg_mesh::closest_point_barycentric;
