//! 2x2 helpers: the orthogonal polar factor `Ort` and small products, row-major `[a, b, c, d]`.

/// A 2x2 matrix `[[m[0], m[1]], [m[2], m[3]]]`.
pub type M2 = [f64; 4];

/// Identity.
pub const I2: M2 = [1.0, 0.0, 0.0, 1.0];

/// Closest orthogonal matrix (rotation or reflection) to `a` in the Frobenius norm.
///
/// Closed form for 2x2: with `C = [[d, -c], [-b, a]]`, `a + C` (det >= 0) or `a - C`
/// (det < 0) has the polar factor's direction; normalise the columns. A (near) zero input
/// has no defined polar factor: the identity is returned so nothing downstream is NaN.
///
/// ```
/// use wavg_project::ort::{ort, mul};
/// let q = ort(&[2.0, 1.0, -0.5, 3.0]);
/// let qtq = mul(&[q[0], q[2], q[1], q[3]], &q);
/// assert!((qtq[0] - 1.0).abs() < 1e-12 && qtq[1].abs() < 1e-12);
/// ```
pub fn ort(m: &M2) -> M2 {
    let [a, b, c, d] = *m;
    let scale = a.abs().max(b.abs()).max(c.abs()).max(d.abs());
    if !(scale > 1e-300) || !scale.is_finite() {
        return I2;
    }
    let (a, b, c, d) = (a / scale, b / scale, c / scale, d / scale);
    let det = a * d - b * c;
    // Rotation: [[a+d, b-c], [c-b, a+d]]; reflection: [[a-d, b+c], [c+b, d-a]].
    let (p, q, r, s) = if det >= 0.0 {
        (a + d, b - c, c - b, a + d)
    } else {
        (a - d, b + c, c + b, d - a)
    };
    let n0 = (p * p + r * r).sqrt();
    let n1 = (q * q + s * s).sqrt();
    if n0 < 1e-150 || n1 < 1e-150 {
        // a is (numerically) rank deficient in a way that makes both choices degenerate:
        // any orthogonal matrix is equally close; fall back to the other branch or I.
        let (p, q, r, s) = if det >= 0.0 {
            (a - d, b + c, c + b, d - a)
        } else {
            (a + d, b - c, c - b, a + d)
        };
        let n0 = (p * p + r * r).sqrt();
        let n1 = (q * q + s * s).sqrt();
        if n0 < 1e-150 || n1 < 1e-150 {
            return I2;
        }
        return [p / n0, q / n1, r / n0, s / n1];
    }
    [p / n0, q / n1, r / n0, s / n1]
}

/// Product `a b`.
#[inline]
pub fn mul(a: &M2, b: &M2) -> M2 {
    [
        a[0] * b[0] + a[1] * b[2],
        a[0] * b[1] + a[1] * b[3],
        a[2] * b[0] + a[3] * b[2],
        a[2] * b[1] + a[3] * b[3],
    ]
}

/// Sum `a + b`.
#[inline]
pub fn add(a: &M2, b: &M2) -> M2 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3]]
}

/// Transpose.
#[inline]
pub fn transpose(a: &M2) -> M2 {
    [a[0], a[2], a[1], a[3]]
}
