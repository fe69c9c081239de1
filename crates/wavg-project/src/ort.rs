//! 2x2 helpers: the orthogonal polar factor `Ort` and small products, row-major `[a, b, c, d]`.

/// A 2x2 matrix `[[m[0], m[1]], [m[2], m[3]]]`.
pub(crate) type M2 = [f64; 4];

/// Identity.
pub(crate) const I2: M2 = [1.0, 0.0, 0.0, 1.0];

/// Closest orthogonal matrix (rotation or reflection) to `a` in the Frobenius norm.
///
/// Closed form for 2x2: with `C = [[d, -c], [-b, a]]`, `a + C` (det >= 0) or `a - C`
/// (det < 0) has the polar factor's direction; normalise the columns. A (near) zero input
/// has no defined polar factor: the identity is returned so nothing downstream is NaN.
pub(crate) fn ort(m: &M2) -> M2 {
    let [a, b, c, d] = *m;
    // Rotation [[p, -q], [q, p]] from (a + d, c - b); reflection [[p, q], [q, -p]] from
    // (a - d, b + c). The branch matches the sign of det(m); when its vector vanishes
    // (m is a scaled orthogonal matrix of the other kind, or zero) try the other one.
    let rot = (a + d, c - b);
    let refl = (a - d, b + c);
    let det = a * d - b * c;
    let order = if det >= 0.0 {
        [true, false]
    } else {
        [false, true]
    };
    for is_rot in order {
        let (x, y) = if is_rot { rot } else { refl };
        let n = (x * x + y * y).sqrt();
        if n > 1e-300 && n.is_finite() {
            let (p, q) = (x / n, y / n);
            return if is_rot { [p, -q, q, p] } else { [p, q, q, -p] };
        }
    }
    I2
}

/// Product `a b`.
#[inline]
pub(crate) fn mul(a: &M2, b: &M2) -> M2 {
    [
        a[0] * b[0] + a[1] * b[2],
        a[0] * b[1] + a[1] * b[3],
        a[2] * b[0] + a[3] * b[2],
        a[2] * b[1] + a[3] * b[3],
    ]
}

/// Sum `a + b`.
#[inline]
pub(crate) fn add(a: &M2, b: &M2) -> M2 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3]]
}

/// Transpose.
#[inline]
pub(crate) fn transpose(a: &M2) -> M2 {
    [a[0], a[2], a[1], a[3]]
}

#[cfg(test)]
mod tests {
    use super::{mul, ort};

    #[test]
    fn polar_factor_is_orthogonal() {
        let q = ort(&[2.0, 1.0, -0.5, 3.0]);
        let qtq = mul(&[q[0], q[2], q[1], q[3]], &q);
        assert!((qtq[0] - 1.0).abs() < 1e-12 && qtq[1].abs() < 1e-12);
    }
}
