//! Euclidean closest point on a triangle in R^8 (Ericson, "Real-Time Collision Detection",
//! 5.1.5, which uses only dot products and so works in any dimension).

use crate::Vec8;

/// Barycentrics of the point of triangle `(a, b, c)` closest to `p`.
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
pub fn closest_point_barycentric(p: &Vec8, a: &Vec8, b: &Vec8, c: &Vec8) -> [f64; 3] {
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
    if !(denom.abs() > 0.0) || !denom.is_finite() {
        // Degenerate triangle (collapsed by the embedding): best vertex.
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
