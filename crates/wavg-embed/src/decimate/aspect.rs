//! The triangle shape measure the aspect-ratio bound of the collapses and of the landmark
//! decimation reads.

use nalgebra::Vector3;

/// Longest edge squared over twice the area of the triangle `(a, b, c)` (OpenMesh's
/// aspect ratio; 2/sqrt(3) for an equilateral triangle, infinite for a degenerate one).
pub(crate) fn aspect_ratio(a: Vector3<f64>, b: Vector3<f64>, c: Vector3<f64>) -> f64 {
    let longest = (b - a)
        .norm_squared()
        .max((c - b).norm_squared())
        .max((a - c).norm_squared());
    let twice_area = (b - a).cross(&(c - a)).norm();
    if twice_area > 0.0 {
        longest / twice_area
    } else {
        f64::INFINITY
    }
}
