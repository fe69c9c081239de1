//! Euclidean closest point on a triangle in any dimension (Ericson, "Real-Time Collision
//! Detection", 5.1.5, which uses only dot products): 3-D for meshes, 8-D for embeddings.

use nalgebra::SVector;

/// Barycentrics of the point of triangle `(a, b, c)` closest to `p`; a degenerate
/// triangle gives its corner closest to `p`.
///
/// ```
/// use nalgebra::Vector3;
/// use wavg_mesh::closest_point_barycentric;
/// let (a, b, c) = (Vector3::zeros(), Vector3::x(), Vector3::y());
/// let w = closest_point_barycentric(&Vector3::new(0.25, 0.25, 3.0), &a, &b, &c);
/// assert!((w[1] - 0.25).abs() < 1e-12 && (w[2] - 0.25).abs() < 1e-12);
/// let w = closest_point_barycentric(&Vector3::new(-1.0, -1.0, 0.0), &a, &b, &c);
/// assert_eq!(w, [1.0, 0.0, 0.0]);
/// ```
pub fn closest_point_barycentric<const D: usize>(
    p: &SVector<f64, D>,
    a: &SVector<f64, D>,
    b: &SVector<f64, D>,
    c: &SVector<f64, D>,
) -> [f64; 3] {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(&ap);
    let d2 = ac.dot(&ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = p - b;
    let d3 = ab.dot(&bp);
    let d4 = ac.dot(&bp);
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return [1.0 - v, v, 0.0];
    }
    let cp = p - c;
    let d5 = ab.dot(&cp);
    let d6 = ac.dot(&cp);
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return [1.0 - w, 0.0, w];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - w, w];
    }
    let denom = va + vb + vc;
    if denom == 0.0 || !denom.is_finite() {
        // Degenerate triangle (zero area, or collapsed by an embedding): best corner.
        let d = [ap.norm_squared(), bp.norm_squared(), cp.norm_squared()];
        let i = (0..3).min_by(|&x, &y| d[x].total_cmp(&d[y])).unwrap_or(0);
        let mut w = [0.0; 3];
        w[i] = 1.0;
        return w;
    }
    let v = vb / denom;
    let w = vc / denom;
    [1.0 - v - w, v, w]
}
