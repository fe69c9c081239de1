//! Per-triangle data: edge alignments `R`, in-plane rotations `E`, the interpolated
//! tangent planes `Psi(xi)` with their analytic derivatives, and Newton's method for the
//! Phong projection onto one triangle.
//!
//! `Psi(xi) = sum_e c_e(xi) X_e T_{i(e)}` over six terms `e`: for each edge `k = (i, i+1)`
//! the term `2k` is `c_first E_k R_k T_i` and the term `2k+1` is `c_second E_k T_{i+1}`
//! (algorithm.md section 3). Each triangle stores the six 2x2 matrices `X_e` and, for the
//! Newton solve, `G_e = X_e T_i (v_k - v_i)` for the two other corners `k`: with
//! `h_i = T_i (y - v_i)` the tangent equations become
//! `F(xi) = sum_e c_e(xi) (sum_k xi_k G_ek - X_e h_i) = Psi(xi) (p(xi) - y)`, a 2-D
//! computation per Newton step. Everything is relative to the triangle's corners, so the
//! results do not depend on where the mesh is or on its scale. Stored as f32; evaluated in
//! f64.

use crate::ort::{self, M2};
use crate::{Mat2x8, Vec8};

/// Corner whose frame term `e` multiplies.
pub const TERM_VERTEX: [usize; 6] = [0, 1, 1, 2, 2, 0];

/// Block coordinate descent sweeps for the in-plane rotations.
pub const PROCRUSTES_SWEEPS: usize = 10;

/// Maximum Newton iterations per triangle.
pub const MAX_NEWTON: usize = 16;

/// Barycentric tolerance of a valid projection (the reference's `eps`).
pub const BARY_EPS: f64 = 1e-4;

/// `S` below which a point counts as a vertex and `Psi` takes its limit there.
const S_MIN: f64 = 1e-12;

/// A tangent frame stored compactly: rows 0 and 1, eight f32 each.
pub type Frame32 = [f32; 16];

/// Converts a frame to f32 storage.
pub fn frame_to_f32(t: &Mat2x8) -> Frame32 {
    let mut f = [0f32; 16];
    for r in 0..2 {
        for c in 0..8 {
            f[r * 8 + c] = t[(r, c)] as f32;
        }
    }
    f
}

/// The f64 frame of a stored one.
pub fn frame_to_f64(f: &Frame32) -> Mat2x8 {
    Mat2x8::from_fn(|r, c| f[r * 8 + c] as f64)
}

/// `T (d)` for a stored frame: the 2-D tangent coordinates of `d`.
#[inline]
pub fn frame_apply(f: &Frame32, d: &Vec8) -> [f64; 2] {
    let mut a = 0.0;
    let mut b = 0.0;
    for c in 0..8 {
        a += f[c] as f64 * d[c];
        b += f[8 + c] as f64 * d[c];
    }
    [a, b]
}

/// Precomputed data of one triangle (196 bytes).
#[derive(Clone, Copy, Debug, Default)]
pub struct TriData {
    /// The six 2x2 blend matrices `X_e` (row-major).
    pub x: [[f32; 4]; 6],
    /// `G_e`: `X_e T_i (v_{i+1} - v_i)` then `X_e T_i (v_{i+2} - v_i)`, `i` = [`TERM_VERTEX`]`[e]`.
    pub g: [[f32; 4]; 6],
    /// Longest embedded edge (the triangle's length scale).
    pub scale: f32,
}

/// The edge alignments `R_k = Ort(T_{k+1} T_k^T)` and rotations `E_k` of a triangle with
/// frames `t` (block coordinate descent, [`PROCRUSTES_SWEEPS`] sweeps from identities).
/// Also returns the Procrustes energy after each sweep (non-increasing).
pub fn alignments(t: &[Mat2x8; 3]) -> ([M2; 3], [M2; 3], [f64; PROCRUSTES_SWEEPS + 1]) {
    let mut r = [ort::I2; 3];
    let mut bases = [Mat2x8::zeros(); 6];
    for k in 0..3 {
        let (ti, tj) = (&t[k], &t[(k + 1) % 3]);
        r[k] = ort::ort(&to_m2(&(tj * ti.transpose())));
        bases[2 * k] = from_m2(&r[k]) * ti;
        bases[2 * k + 1] = *tj;
    }
    let mut gram = [[ort::I2; 6]; 6];
    for a in 0..6 {
        for b in a..6 {
            let g = to_m2(&(bases[a] * bases[b].transpose()));
            gram[a][b] = g;
            gram[b][a] = ort::transpose(&g);
        }
    }
    let mut e = [ort::I2; 3];
    let mut energy = [0.0; PROCRUSTES_SWEEPS + 1];
    energy[0] = procrustes_energy(&e, &gram);
    for sweep in 0..PROCRUSTES_SWEEPS {
        for k in 0..3 {
            let mut m = [0.0; 4];
            for j in 0..3 {
                if j == k {
                    continue;
                }
                for a in [2 * j, 2 * j + 1] {
                    for b in [2 * k, 2 * k + 1] {
                        m = ort::add(&m, &ort::mul(&e[j], &gram[a][b]));
                    }
                }
            }
            e[k] = ort::ort(&m);
        }
        energy[sweep + 1] = procrustes_energy(&e, &gram);
    }
    (r, e, energy)
}

/// `sum_{a<b} |A_a - A_b|^2` with `A_a = E_{pair(a)} B_a`, from the Gram blocks.
fn procrustes_energy(e: &[M2; 3], gram: &[[M2; 6]; 6]) -> f64 {
    let mut s = 0.0;
    for a in 0..6 {
        for b in (a + 1)..6 {
            // |A_a|^2 + |A_b|^2 - 2 tr(E_a G_ab E_b^T)
            let ea = &e[a / 2];
            let eb = &e[b / 2];
            let cross = ort::mul(&ort::mul(ea, &gram[a][b]), &ort::transpose(eb));
            s += gram[a][a][0] + gram[a][a][3] + gram[b][b][0] + gram[b][b][3]
                - 2.0 * (cross[0] + cross[3]);
        }
    }
    s
}

fn to_m2(m: &nalgebra::Matrix2<f64>) -> M2 {
    [m[(0, 0)], m[(0, 1)], m[(1, 0)], m[(1, 1)]]
}

fn from_m2(m: &M2) -> nalgebra::Matrix2<f64> {
    nalgebra::Matrix2::new(m[0], m[1], m[2], m[3])
}

impl TriData {
    /// Precomputes a triangle from its stored corner frames and embedded corners.
    pub fn new(frames: [&Frame32; 3], corners: [Vec8; 3]) -> Self {
        let t = frames.map(frame_to_f64);
        let (r, e, _) = alignments(&t);
        let mut d = TriData::default();
        for k in 0..3 {
            let a = ort::mul(&e[k], &r[k]);
            d.x[2 * k] = a.map(|v| v as f32);
            d.x[2 * k + 1] = e[k].map(|v| v as f32);
        }
        for term in 0..6 {
            let i = TERM_VERTEX[term];
            let xe = d.x[term].map(|v| v as f64);
            for (s, k) in [(i + 1) % 3, (i + 2) % 3].into_iter().enumerate() {
                let g = frame_apply(frames[i], &(corners[k] - corners[i]));
                let xg = [xe[0] * g[0] + xe[1] * g[1], xe[2] * g[0] + xe[3] * g[1]];
                d.g[term][2 * s] = xg[0] as f32;
                d.g[term][2 * s + 1] = xg[1] as f32;
            }
        }
        let mut scale: f64 = 0.0;
        for i in 0..3 {
            scale = scale.max((corners[(i + 1) % 3] - corners[i]).norm());
        }
        d.scale = scale as f32;
        d
    }

    /// `Psi(xi)` for corner frames `frames` (2x8; rows span the interpolated tangent plane).
    pub fn psi(&self, frames: [&Frame32; 3], xi: &[f64; 3]) -> Mat2x8 {
        let (c, _) = coefficients(xi);
        let mut m = Mat2x8::zeros();
        for (e, &ce) in c.iter().enumerate() {
            m += from_m2(&self.x[e].map(|v| v as f64)) * frame_to_f64(frames[TERM_VERTEX[e]]) * ce;
        }
        m
    }

    /// The partial derivatives `dPsi/dxi_k`, `k = 0, 1, 2`, treating the three barycentrics
    /// as independent (on the plane `sum xi = 1` take differences). At a vertex, where
    /// `Psi` is not differentiable, the derivative just inside the triangle is returned.
    pub fn psi_derivatives(&self, frames: [&Frame32; 3], xi: &[f64; 3]) -> [Mat2x8; 3] {
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

    /// Newton's method for `Psi(xi) (p(xi) - y) = 0`, `sum xi = 1`, from the centroid,
    /// kept inside the triangle; `h[i] = T_i (y - v_i)`. Returns the barycentrics of a
    /// projection, or `None` when Newton finds none (the root lies outside the triangle,
    /// the Jacobian is singular, or it does not converge in [`MAX_NEWTON`] steps).
    pub fn solve(&self, h: &[[f64; 2]; 3]) -> Option<[f64; 3]> {
        let mut q = [[0.0f64; 2]; 6];
        let mut g = [[0.0f64; 4]; 6];
        let mut hmax: f64 = 0.0;
        for hi in h {
            hmax = hmax.max(hi[0].abs()).max(hi[1].abs());
        }
        for e in 0..6 {
            let x = self.x[e];
            let hi = h[TERM_VERTEX[e]];
            q[e] = [
                x[0] as f64 * hi[0] + x[1] as f64 * hi[1],
                x[2] as f64 * hi[0] + x[3] as f64 * hi[1],
            ];
            g[e] = self.g[e].map(|v| v as f64);
        }
        let fscale = self.scale as f64 + hmax;
        let ftol = 1e-11 * fscale;
        let mut xi = [1.0 / 3.0; 3];
        let mut stuck = 0;
        for _ in 0..MAX_NEWTON {
            let (f, j) = residual(&g, &q, &xi);
            let fn_ = f[0].abs().max(f[1].abs());
            if fn_ <= ftol {
                return Some(xi);
            }
            let det = j[0] * j[3] - j[1] * j[2];
            let jn = j.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            if !(det.abs() > 1e-14 * jn * jn) {
                return None;
            }
            let d0 = -(j[3] * f[0] - j[1] * f[1]) / det;
            let d1 = -(-j[2] * f[0] + j[0] * f[1]) / det;
            let d = [d0, d1, -d0 - d1];
            // Largest step in direction d that stays in the triangle.
            let mut t: f64 = 1.0;
            for k in 0..3 {
                if xi[k] + d[k] < 0.0 {
                    t = t.min(xi[k] / -d[k]);
                }
            }
            if t < 1e-9 {
                stuck += 1;
                if stuck >= 2 {
                    return None;
                }
                // Slide: clamp the full step onto the triangle.
                let mut n = [0.0; 3];
                for k in 0..3 {
                    n[k] = (xi[k] + d[k]).max(0.0);
                }
                let s = n[0] + n[1] + n[2];
                if !(s > 0.0) {
                    return None;
                }
                xi = n.map(|v| v / s);
            } else {
                stuck = 0;
                for k in 0..3 {
                    xi[k] = (xi[k] + t * d[k]).max(0.0);
                }
                let s = xi[0] + xi[1] + xi[2];
                xi = xi.map(|v| v / s);
                let step = (t * d0).abs().max((t * d1).abs());
                if step < 1e-13 {
                    let (f, _) = residual(&g, &q, &xi);
                    if f[0].abs().max(f[1].abs()) <= 1e-8 * fscale {
                        return Some(xi);
                    }
                }
            }
        }
        None
    }

    /// `F(xi) = Psi(xi) (p(xi) - y)` given `h[i] = T_i (y - v_i)` (for tests).
    pub fn tangent_residual(&self, h: &[[f64; 2]; 3], xi: &[f64; 3]) -> [f64; 2] {
        let mut q = [[0.0f64; 2]; 6];
        let mut g = [[0.0f64; 4]; 6];
        for e in 0..6 {
            let x = self.x[e].map(|v| v as f64);
            let hi = h[TERM_VERTEX[e]];
            q[e] = [x[0] * hi[0] + x[1] * hi[1], x[2] * hi[0] + x[3] * hi[1]];
            g[e] = self.g[e].map(|v| v as f64);
        }
        residual(&g, &q, xi).0
    }
}

/// `F(xi)` and its Jacobian with respect to `(xi_0, xi_1)` (`xi_2 = 1 - xi_0 - xi_1`),
/// row-major.
#[inline]
fn residual(g: &[[f64; 4]; 6], q: &[[f64; 2]; 6], xi: &[f64; 3]) -> ([f64; 2], [f64; 4]) {
    let (c, dc) = coefficients(xi);
    let mut f = [0.0; 2];
    let mut df = [[0.0; 2]; 3];
    for e in 0..6 {
        let i = TERM_VERTEX[e];
        let k1 = if i == 2 { 0 } else { i + 1 };
        let k2 = if i == 0 { 2 } else { i - 1 };
        let ge = &g[e];
        let z = [
            xi[k1] * ge[0] + xi[k2] * ge[2] - q[e][0],
            xi[k1] * ge[1] + xi[k2] * ge[3] - q[e][1],
        ];
        f[0] += c[e] * z[0];
        f[1] += c[e] * z[1];
        for k in 0..3 {
            df[k][0] += dc[e][k] * z[0];
            df[k][1] += dc[e][k] * z[1];
        }
        df[k1][0] += c[e] * ge[0];
        df[k1][1] += c[e] * ge[1];
        df[k2][0] += c[e] * ge[2];
        df[k2][1] += c[e] * ge[3];
    }
    (
        f,
        [
            df[0][0] - df[2][0],
            df[1][0] - df[2][0],
            df[0][1] - df[2][1],
            df[1][1] - df[2][1],
        ],
    )
}

/// Blend coefficients `c_e(xi)` of the six terms and their partial derivatives.
///
/// `c_{2k} = (xi_k^2 xi_l + P/2) / S`, `c_{2k+1} = (xi_k xi_l^2 + P/2) / S` with
/// `l = k + 1`, `P = xi_0 xi_1 xi_2`, `S = xi_0 xi_1 + xi_1 xi_2 + xi_2 xi_0`; they sum to 1.
/// At a vertex (`S` ~ 0) the values take the symmetric limit (half on each of the two
/// terms of that corner, so `Psi` spans the corner's frame) and the derivatives are those
/// at a point just inside, so nothing divides by zero.
#[inline]
pub fn coefficients(xi: &[f64; 3]) -> ([f64; 6], [[f64; 3]; 6]) {
    let s = xi[0] * xi[1] + xi[1] * xi[2] + xi[2] * xi[0];
    if s >= S_MIN {
        return coefficients_regular(xi, s);
    }
    let v = if xi[0] >= xi[1] && xi[0] >= xi[2] {
        0
    } else if xi[1] >= xi[2] {
        1
    } else {
        2
    };
    let inner = xi.map(|x| (1.0 - 1e-6) * x + 1e-6 / 3.0);
    let si = inner[0] * inner[1] + inner[1] * inner[2] + inner[2] * inner[0];
    let (_, dc) = coefficients_regular(&inner, si);
    let mut c = [0.0; 6];
    // Corner v's terms: c_first of edge v and c_second of edge v-1.
    c[2 * v] = 0.5;
    c[2 * ((v + 2) % 3) + 1] = 0.5;
    (c, dc)
}

#[inline]
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
        let mut dn1 = dp.map(|v| 0.5 * v);
        dn1[k] += 2.0 * a * b;
        dn1[l] += a * a;
        // second: a b^2 + P/2
        let n2 = a * b * b + 0.5 * p;
        let mut dn2 = dp.map(|v| 0.5 * v);
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
