//! The inverse problem's linear algebra, given the tangent plane `Psi` and the embedded
//! point `yhat` (algorithm notes, section 6), over anchors stored structure-of-arrays so
//! the per-anchor loop vectorises.
//!
//! For anchor `j` with `v_j = y_j - yhat`, `a_j = Psi v_j` (2-vector),
//! `|v_T|^2 = a_j^T (Psi Psi^T)^{-1} a_j` (a proper projector: Psi's rows are only nearly
//! orthonormal) and `d_j = |v_T|^2 + gamma |v_O|^2`. The weights minimise
//! `sum (d_j w_j)^2` subject to `sum w_j a_j = 0` (the point is the Phong projection of the
//! average) and `sum w_j = 1`.
//!
//! Conditioning. The closed form is `w = S C^T (C S C^T)^{-1} b` with `S = diag(1/d_j^2)`.
//! Scaling `S` by a constant does not change `w`, so we use `s_j = (d_min / d_j)^2 <= 1`.
//! Any invertible transform of the constraint rows does not change `w` either, so they are
//! centred on the nearest anchor `m`: `c_j = (a_j - a_m, 1)`, `b = (-a_m, 1)`. Near an
//! anchor the 3x3 system then splits into a well-scaled 2x2 block and a `1`, and after
//! Jacobi (diagonal) scaling it stays well conditioned however close the point is to the
//! anchor: the weights tend smoothly to the one-hot weight, which is returned exactly when
//! `d_min` is zero.

use crate::error::SolveError;
use crate::{DIM, Mat2x8, Vec8};

/// Default `gamma`: how much more the distance off the tangent plane counts (the paper's 10).
pub const DEFAULT_GAMMA: f64 = 10.0;

/// Anchor coordinates in R^8, one array per coordinate (structure of arrays).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AnchorCoords {
    dims: [Vec<f64>; DIM],
}

impl AnchorCoords {
    /// No anchors.
    pub fn new() -> Self {
        Self::default()
    }

    /// From a list of points.
    pub fn from_points(points: &[Vec8]) -> Self {
        let mut c = Self::new();
        for p in points {
            c.push(p);
        }
        c
    }

    /// Number of anchors.
    pub fn len(&self) -> usize {
        self.dims[0].len()
    }

    /// Whether there are no anchors.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Appends an anchor.
    pub fn push(&mut self, y: &Vec8) {
        for k in 0..DIM {
            self.dims[k].push(y[k]);
        }
    }

    /// Replaces anchor `i` (panics when out of range; callers check).
    pub fn set(&mut self, i: usize, y: &Vec8) {
        for k in 0..DIM {
            self.dims[k][i] = y[k];
        }
    }

    /// Removes anchor `i`, keeping the order of the others (panics when out of range).
    pub fn remove(&mut self, i: usize) {
        for k in 0..DIM {
            self.dims[k].remove(i);
        }
    }

    /// Anchor `i`'s coordinates.
    pub fn get(&self, i: usize) -> Vec8 {
        Vec8::from_fn(|k, _| self.dims[k][i])
    }

    /// `sum_j w_j y_j * scale`: the weighted average in R^8.
    pub fn weighted_sum(&self, weights: &[f64], scale: f64) -> Vec8 {
        let n = self.len().min(weights.len());
        let w = &weights[..n];
        Vec8::from_fn(|k, _| {
            let y = &self.dims[k][..n];
            let mut s = 0.0;
            for j in 0..n {
                s += w[j] * y[j];
            }
            s * scale
        })
    }
}

/// Reusable buffers for [`inverse_weights`] (so batches do not allocate per query).
#[derive(Clone, Debug, Default)]
pub struct InverseScratch {
    a0: Vec<f64>,
    a1: Vec<f64>,
    d: Vec<f64>,
}

/// Squared-distance weights `d_j` (see the module docs) and `a_j = Psi (y_j - yhat)`,
/// written into `scratch`; returns `(d_min, index of d_min, d_max)`.
fn distances(
    psi: &Mat2x8,
    yhat: &Vec8,
    anchors: &AnchorCoords,
    gamma: f64,
    scratch: &mut InverseScratch,
) -> Result<(f64, usize, f64), SolveError> {
    let n = anchors.len();
    let p0: [f64; DIM] = std::array::from_fn(|k| psi[(0, k)]);
    let p1: [f64; DIM] = std::array::from_fn(|k| psi[(1, k)]);
    let g00: f64 = p0.iter().map(|x| x * x).sum();
    let g11: f64 = p1.iter().map(|x| x * x).sum();
    let g01: f64 = p0.iter().zip(&p1).map(|(x, y)| x * y).sum();
    let det = g00 * g11 - g01 * g01;
    if det.is_nan() || det <= 1e-12 * g00 * g11 || !det.is_finite() {
        return Err(SolveError::DegenerateTangentPlane);
    }
    // Inverse Gram matrix, so |v_T|^2 = a^T G^{-1} a.
    let (h00, h01, h11) = (g11 / det, -g01 / det, g00 / det);
    let yh: [f64; DIM] = std::array::from_fn(|k| yhat[k]);
    scratch.a0.resize(n, 0.0);
    scratch.a1.resize(n, 0.0);
    scratch.d.resize(n, 0.0);
    let ys: [&[f64]; DIM] = std::array::from_fn(|k| &anchors.dims[k][..n]);
    let (a0s, a1s, ds) = (
        &mut scratch.a0[..n],
        &mut scratch.a1[..n],
        &mut scratch.d[..n],
    );
    let gm1 = gamma - 1.0;
    for j in 0..n {
        let mut vv = 0.0;
        let mut a0 = 0.0;
        let mut a1 = 0.0;
        for k in 0..DIM {
            let v = ys[k][j] - yh[k];
            vv += v * v;
            a0 += p0[k] * v;
            a1 += p1[k] * v;
        }
        let vt = (h00 * a0 * a0 + 2.0 * h01 * a0 * a1 + h11 * a1 * a1).min(vv);
        // |v_T|^2 + gamma |v_O|^2 with |v_O|^2 = |v|^2 - |v_T|^2 >= 0.
        ds[j] = gamma * vv - gm1 * vt;
        a0s[j] = a0;
        a1s[j] = a1;
    }
    let mut dmin = f64::INFINITY;
    let mut imin = 0;
    let mut dmax = 0.0f64;
    for (j, &d) in ds.iter().enumerate() {
        if d < dmin {
            dmin = d;
            imin = j;
        }
        dmax = dmax.max(d);
    }
    if !dmin.is_finite() || !dmax.is_finite() {
        return Err(SolveError::InvalidParameter(
            "non-finite anchor or point coordinates".into(),
        ));
    }
    Ok((dmin, imin, dmax))
}

/// Solves the inverse problem for one point: `psi` is the tangent plane at the point,
/// `yhat` its embedded position; writes one weight per anchor into `out` (cleared first).
/// The weights sum to 1 (renormalised, so to rounding), are one-hot (split evenly among
/// coincident anchors) when the point is exactly at an anchor, and tend to that smoothly.
///
/// ```
/// use wavg_solve::kernel::{AnchorCoords, InverseScratch, inverse_weights};
/// use wavg_solve::{Mat2x8, Vec8};
/// // Three anchors in the plane spanned by the first two axes, point at their centroid.
/// let mut psi = Mat2x8::zeros();
/// psi[(0, 0)] = 1.0;
/// psi[(1, 1)] = 1.0;
/// let ys = [[0.0, 0.0], [3.0, 0.0], [0.0, 3.0]]
///     .map(|[x, y]| Vec8::from_fn(|k, _| [x, y][..].get(k).copied().unwrap_or(0.0)));
/// let anchors = AnchorCoords::from_points(&ys);
/// let yhat = Vec8::from_fn(|k, _| if k < 2 { 1.0 } else { 0.0 });
/// let mut w = Vec::new();
/// inverse_weights(&psi, &yhat, &anchors, 10.0, &mut InverseScratch::default(), &mut w).unwrap();
/// assert!(w.iter().all(|w| (w - 1.0 / 3.0).abs() < 1e-12));
/// ```
pub fn inverse_weights(
    psi: &Mat2x8,
    yhat: &Vec8,
    anchors: &AnchorCoords,
    gamma: f64,
    scratch: &mut InverseScratch,
    out: &mut Vec<f64>,
) -> Result<(), SolveError> {
    out.clear();
    let n = anchors.len();
    if n == 0 {
        return Err(SolveError::NoAnchors);
    }
    if gamma.is_nan() || gamma <= 0.0 || !gamma.is_finite() {
        return Err(SolveError::InvalidParameter(format!(
            "gamma must be finite and positive, got {gamma}"
        )));
    }
    let (dmin, m, dmax) = distances(psi, yhat, anchors, gamma, scratch)?;
    out.resize(n, 0.0);
    if dmin <= 0.0 {
        return one_hot(&scratch.d[..n], out);
    }
    let (a0s, a1s, ds) = (&scratch.a0[..n], &scratch.a1[..n], &scratch.d[..n]);
    let (am0, am1) = (a0s[m], a1s[m]);
    // Constraint rows centred on anchor m; s_j = (d_min/d_j)^2 in `out` for now.
    let (mut m00, mut m01, mut m02, mut m11, mut m12, mut m22) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for j in 0..n {
        let r = dmin / ds[j];
        let s = r * r;
        let c0 = a0s[j] - am0;
        let c1 = a1s[j] - am1;
        let sc0 = s * c0;
        let sc1 = s * c1;
        m00 += sc0 * c0;
        m01 += sc0 * c1;
        m02 += sc0;
        m11 += sc1 * c1;
        m12 += sc1;
        m22 += s;
        out[j] = s;
    }
    let b = [-am0, -am1, 1.0];
    let Some(z) = solve_scaled_3x3([[m00, m01, m02], [m01, m11, m12], [m02, m12, m22]], b) else {
        // Singular: either the other anchors' contributions underflowed because the point
        // is (to within ~1e-150 relative) at an anchor, or the anchors are degenerate.
        if dmin <= 1e-100 * dmax {
            return one_hot(ds, out);
        }
        return Err(SolveError::DegenerateAnchors);
    };
    let mut sum = 0.0;
    for j in 0..n {
        let c0 = a0s[j] - am0;
        let c1 = a1s[j] - am1;
        let w = out[j] * (c0 * z[0] + c1 * z[1] + z[2]);
        out[j] = w;
        sum += w;
    }
    if !sum.is_finite() || (sum - 1.0).abs() > 1e-6 {
        return Err(SolveError::DegenerateAnchors);
    }
    let inv = 1.0 / sum;
    for w in out.iter_mut() {
        *w *= inv;
    }
    Ok(())
}

/// Equal weights on the anchors with `d == 0`, zero elsewhere.
fn one_hot(ds: &[f64], out: &mut [f64]) -> Result<(), SolveError> {
    let dmin = ds.iter().copied().fold(f64::INFINITY, f64::min);
    let hits = ds.iter().filter(|&&d| d <= dmin).count() as f64;
    for (w, &d) in out.iter_mut().zip(ds) {
        *w = if d <= dmin { 1.0 / hits } else { 0.0 };
    }
    Ok(())
}

/// Solves the symmetric positive semi-definite 3x3 system `m z = b` after Jacobi scaling
/// (unit diagonal), by cofactors; `None` when it is numerically singular.
#[inline]
fn solve_scaled_3x3(m: [[f64; 3]; 3], b: [f64; 3]) -> Option<[f64; 3]> {
    let diag = [m[0][0], m[1][1], m[2][2]];
    if !diag.iter().all(|&x| x.is_normal() && x > 0.0) {
        return None;
    }
    let s = diag.map(|x| 1.0 / x.sqrt());
    let a = |i: usize, j: usize| m[i][j] * s[i] * s[j];
    let (a00, a01, a02, a11, a12, a22) = (1.0, a(0, 1), a(0, 2), 1.0, a(1, 2), 1.0);
    let c00 = a11 * a22 - a12 * a12;
    let c01 = a02 * a12 - a01 * a22;
    let c02 = a01 * a12 - a02 * a11;
    let c11 = a00 * a22 - a02 * a02;
    let c12 = a01 * a02 - a00 * a12;
    let c22 = a00 * a11 - a01 * a01;
    let det = a00 * c00 + a01 * c01 + a02 * c02;
    // Unit diagonal: det <= 1; far below rounding level means rank deficiency.
    if det.is_nan() || det <= 1e-13 {
        return None;
    }
    let bs = [b[0] * s[0], b[1] * s[1], b[2] * s[2]];
    let inv = 1.0 / det;
    let z0 = (c00 * bs[0] + c01 * bs[1] + c02 * bs[2]) * inv;
    let z1 = (c01 * bs[0] + c11 * bs[1] + c12 * bs[2]) * inv;
    let z2 = (c02 * bs[0] + c12 * bs[1] + c22 * bs[2]) * inv;
    Some([z0 * s[0], z1 * s[1], z2 * s[2]])
}
