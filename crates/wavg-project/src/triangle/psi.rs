//! The blend coefficients `c_e(xi)` with their derivatives, and the interpolated tangent
//! planes `Psi(xi)` of one triangle with their derivatives.

use super::{Frame32, TERM_VERTEX, TriData, frame_to_f64};
use crate::Mat2x8;
use crate::ort::M2;

/// `S` below which a point counts as a vertex and `Psi` takes its limit there.
const S_MIN: f64 = 1e-12;

fn from_m2(m: &M2) -> nalgebra::Matrix2<f64> {
    nalgebra::Matrix2::new(m[0], m[1], m[2], m[3])
}

impl TriData {
    /// `Psi(xi)` for corner frames `frames` (2x8; rows span the interpolated tangent plane).
    pub(crate) fn psi(&self, frames: [&Frame32; 3], xi: &[f64; 3]) -> Mat2x8 {
        let (c, _) = coefficients(xi);
        // Two terms share each corner's frame: sum their weighted blends first, then one
        // 2x2-by-2x8 product per corner.
        let mut b = [[0.0f64; 4]; 3];
        for (e, &ce) in c.iter().enumerate() {
            let i = TERM_VERTEX[e];
            for k in 0..4 {
                b[i][k] += ce * self.x[e][k] as f64;
            }
        }
        let mut m = Mat2x8::zeros();
        for (i, f) in frames.iter().enumerate() {
            let b = &b[i];
            for col in 0..8 {
                let (t0, t1) = (f[col] as f64, f[8 + col] as f64);
                m[(0, col)] += b[0] * t0 + b[1] * t1;
                m[(1, col)] += b[2] * t0 + b[3] * t1;
            }
        }
        m
    }

    /// The partial derivatives `dPsi/dxi_k`, `k = 0, 1, 2`, treating the three barycentrics
    /// as independent (on the plane `sum xi = 1` take differences). At a vertex, where
    /// `Psi` is not differentiable, the derivative just inside the triangle is returned.
    pub(crate) fn psi_derivatives(&self, frames: [&Frame32; 3], xi: &[f64; 3]) -> [Mat2x8; 3] {
        let (_, dc) = coefficients(xi);
        let mut out = [Mat2x8::zeros(); 3];
        for (e, dce) in dc.iter().enumerate() {
            let b = from_m2(&self.x[e].map(|v| v as f64)) * frame_to_f64(frames[TERM_VERTEX[e]]);
            for k in 0..3 {
                out[k] += b * dce[k];
            }
        }
        out
    }
}

/// [`coefficients`] with derivatives along `(xi_0, xi_1)` on the plane `sum xi = 1`
/// (`d/du = d/dxi_0 - d/dxi_2`, `d/dv = d/dxi_1 - d/dxi_2`), computed directly: Newton's
/// method needs only these two, once per iteration.
#[inline(always)]
pub(super) fn coefficients_reduced(x: &[f64; 3]) -> ([f64; 6], [[f64; 2]; 6]) {
    let s = x[0] * x[1] + x[1] * x[2] + x[2] * x[0];
    if s >= S_MIN {
        return reduced_regular(x, s);
    }
    reduced_at_vertex(x)
}

/// [`coefficients_reduced`] at a vertex, as in `coefficients`: the limit values, the
/// derivatives just inside.
#[cold]
#[inline(never)]
fn reduced_at_vertex(x: &[f64; 3]) -> ([f64; 6], [[f64; 2]; 6]) {
    let v = corner_of(x);
    let inner = x.map(|x| (1.0 - 1e-6) * x + 1e-6 / 3.0);
    let si = inner[0] * inner[1] + inner[1] * inner[2] + inner[2] * inner[0];
    let (_, dc) = reduced_regular(&inner, si);
    (vertex_limit(v), dc)
}

/// The corner a point with `S` ~ 0 sits at: its largest barycentric.
#[inline(always)]
fn corner_of(xi: &[f64; 3]) -> usize {
    if xi[0] >= xi[1] && xi[0] >= xi[2] {
        0
    } else if xi[1] >= xi[2] {
        1
    } else {
        2
    }
}

/// The coefficients' limit at corner `v`: half on each of its two terms (the first of
/// edge `v`, the second of edge `v - 1`), so `Psi` spans the corner's frame.
#[inline(always)]
fn vertex_limit(v: usize) -> [f64; 6] {
    let mut c = [0.0; 6];
    c[2 * v] = 0.5;
    c[2 * ((v + 2) % 3) + 1] = 0.5;
    c
}

/// [`coefficients_reduced`] away from the corners. With `a = xi_k`, `b = xi_l` the
/// numerators are `n1 = a^2 b + P/2`, `n2 = a b^2 + P/2`; their reduced derivatives add
/// `dP/2` to the terms of `a` and `b` along `u` and `v`, and `c' = (n' - c S') / S`.
#[inline(always)]
fn reduced_regular(x: &[f64; 3], s: f64) -> ([f64; 6], [[f64; 2]; 6]) {
    let (x0, x1, x2) = (x[0], x[1], x[2]);
    let inv = 1.0 / s;
    let hp = 0.5 * (x0 * x1 * x2);
    let (hpu, hpv) = (0.5 * (x1 * (x2 - x0)), 0.5 * (x0 * (x2 - x1)));
    let (su, sv) = (x2 - x0, x2 - x1);
    let mut c = [0.0; 6];
    let mut dc = [[0.0; 2]; 6];
    let mut term = |e: usize, n: f64, nu: f64, nv: f64| {
        let ce = n * inv;
        c[e] = ce;
        dc[e] = [(nu - ce * su) * inv, (nv - ce * sv) * inv];
    };
    // k = 0: a = xi_0 (along u), b = xi_1 (along v).
    let (a, b) = (x0, x1);
    let (ab2, aa, bb) = (2.0 * a * b, a * a, b * b);
    term(0, aa * b + hp, hpu + ab2, hpv + aa);
    term(1, a * bb + hp, hpu + bb, hpv + ab2);
    // k = 1: a = xi_1 (along v), b = xi_2 (against both).
    let (a, b) = (x1, x2);
    let (ab2, aa, bb) = (2.0 * a * b, a * a, b * b);
    term(2, aa * b + hp, hpu - aa, hpv + (ab2 - aa));
    term(3, a * bb + hp, hpu - ab2, hpv + (bb - ab2));
    // k = 2: a = xi_2 (against both), b = xi_0 (along u).
    let (a, b) = (x2, x0);
    let (ab2, aa, bb) = (2.0 * a * b, a * a, b * b);
    term(4, aa * b + hp, hpu + (aa - ab2), hpv - ab2);
    term(5, a * bb + hp, hpu + (ab2 - bb), hpv - bb);
    (c, dc)
}

/// Blend coefficients `c_e(xi)` of the six terms and their partial derivatives.
///
/// `c_{2k} = (xi_k^2 xi_l + P/2) / S`, `c_{2k+1} = (xi_k xi_l^2 + P/2) / S` with
/// `l = k + 1`, `P = xi_0 xi_1 xi_2`, `S = xi_0 xi_1 + xi_1 xi_2 + xi_2 xi_0`; they sum to 1.
/// At a vertex (`S` ~ 0) the values take the symmetric limit (half on each of the two
/// terms of that corner, so `Psi` spans the corner's frame) and the derivatives are those
/// at a point just inside, so nothing divides by zero.
#[inline(always)]
pub(crate) fn coefficients(xi: &[f64; 3]) -> ([f64; 6], [[f64; 3]; 6]) {
    let s = xi[0] * xi[1] + xi[1] * xi[2] + xi[2] * xi[0];
    if s >= S_MIN {
        return coefficients_regular(xi, s);
    }
    let v = corner_of(xi);
    let inner = xi.map(|x| (1.0 - 1e-6) * x + 1e-6 / 3.0);
    let si = inner[0] * inner[1] + inner[1] * inner[2] + inner[2] * inner[0];
    let (_, dc) = coefficients_regular(&inner, si);
    (vertex_limit(v), dc)
}

#[inline(always)]
fn coefficients_regular(xi: &[f64; 3], s: f64) -> ([f64; 6], [[f64; 3]; 6]) {
    let p = xi[0] * xi[1] * xi[2];
    let dp = [xi[1] * xi[2], xi[0] * xi[2], xi[0] * xi[1]];
    let ds = [xi[1] + xi[2], xi[0] + xi[2], xi[0] + xi[1]];
    let inv = 1.0 / s;
    let mut c = [0.0; 6];
    let mut dc = [[0.0; 3]; 6];
    for k in 0..3 {
        let l = (k + 1) % 3;
        let (a, b) = (xi[k], xi[l]);
        // first: a^2 b + P/2
        let n1 = a * a * b + 0.5 * p;
        let mut dn1 = [0.5 * dp[0], 0.5 * dp[1], 0.5 * dp[2]];
        dn1[k] += 2.0 * a * b;
        dn1[l] += a * a;
        // second: a b^2 + P/2
        let n2 = a * b * b + 0.5 * p;
        let mut dn2 = [0.5 * dp[0], 0.5 * dp[1], 0.5 * dp[2]];
        dn2[k] += b * b;
        dn2[l] += 2.0 * a * b;
        let c1 = n1 * inv;
        let c2 = n2 * inv;
        c[2 * k] = c1;
        c[2 * k + 1] = c2;
        for m in 0..3 {
            dc[2 * k][m] = (dn1[m] - c1 * ds[m]) * inv;
            dc[2 * k + 1][m] = (dn2[m] - c2 * ds[m]) * inv;
        }
    }
    (c, dc)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn bary() -> impl Strategy<Value = [f64; 3]> {
        (0.0f64..1.0, 0.0f64..1.0).prop_map(|(a, b)| {
            let (a, b) = if a + b > 1.0 {
                (1.0 - a, 1.0 - b)
            } else {
                (a, b)
            };
            [a, b, 1.0 - a - b]
        })
    }

    proptest! {
        #[test]
        fn coefficients_sum_to_one_and_derivatives_match(xi in bary()) {
            let (c, dc) = coefficients(&xi);
            prop_assert!((c.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            let s = xi[0] * xi[1] + xi[1] * xi[2] + xi[2] * xi[0];
            prop_assume!(s > 1e-3);
            for k in 0..3 {
                let h = 1e-6;
                let mut a = xi;
                let mut b = xi;
                a[k] += h;
                b[k] -= h;
                let (ca, _) = coefficients_regular(&a, a[0]*a[1]+a[1]*a[2]+a[2]*a[0]);
                let (cb, _) = coefficients_regular(&b, b[0]*b[1]+b[1]*b[2]+b[2]*b[0]);
                for e in 0..6 {
                    let fd = (ca[e] - cb[e]) / (2.0 * h);
                    prop_assert!((fd - dc[e][k]).abs() < 1e-5 * (1.0 + fd.abs() / s), "{e} {k} {fd} {}", dc[e][k]);
                }
            }
        }
    }

    /// The direct reduced derivatives are those of [`coefficients`], differenced.
    fn check_reduced(xi: [f64; 3]) {
        let (c, dc) = coefficients(&xi);
        let (cr, dr) = coefficients_reduced(&xi);
        let scale = 1.0 + dc.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        for e in 0..6 {
            assert!((c[e] - cr[e]).abs() <= 1e-14, "{xi:?} {e}");
            let want = [dc[e][0] - dc[e][2], dc[e][1] - dc[e][2]];
            for m in 0..2 {
                let d = (want[m] - dr[e][m]).abs();
                assert!(d <= 1e-12 * scale, "{xi:?} {e} {m}: {want:?} {:?}", dr[e]);
            }
        }
    }

    proptest! {
        #[test]
        fn reduced_coefficients_match_the_full_ones(xi in bary()) {
            check_reduced(xi);
        }
    }

    #[test]
    fn reduced_coefficients_match_on_edges_and_near_corners() {
        for xi in [
            [0.3, 0.7, 0.0],
            [0.0, 0.4, 0.6],
            [0.5, 0.0, 0.5],
            [1.0 - 2e-7, 1e-7, 1e-7],
            [1e-9, 1.0 - 2e-9, 1e-9],
            [0.0, 0.0, 1.0],
            [1.0 / 3.0; 3],
        ] {
            check_reduced(xi);
        }
    }

    #[test]
    fn coefficients_reduce_to_linear_on_edges() {
        let (c, _) = coefficients(&[0.3, 0.7, 0.0]);
        assert!((c[0] - 0.3).abs() < 1e-15 && (c[1] - 0.7).abs() < 1e-15);
        assert!(c[2..].iter().all(|v| v.abs() < 1e-15));
        let (c, dc) = coefficients(&[0.0, 0.0, 1.0]);
        assert_eq!(c, [0.0, 0.0, 0.0, 0.5, 0.5, 0.0]);
        assert!(dc.iter().flatten().all(|v| v.is_finite()));
    }
}
