//! The inverse problem's linear algebra, given the tangent plane `Psi` and the embedded
//! point `yhat`, over anchors stored structure-of-arrays so
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
use crate::simd::{LANES, Plain, Quad, Wide, dispatch, sum_lanes};
use crate::{DIM, Mat2x8, Vec8};

/// Default `gamma`: how much more the distance off the tangent plane counts (the paper's 10).
pub const DEFAULT_GAMMA: f64 = 10.0;

/// Anchor coordinates in R^8, one array per coordinate (structure of arrays) so the
/// per-anchor loops vectorise; each array is padded with zeros to a multiple of the SIMD lane count (4).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AnchorCoords {
    dims: [Vec<f64>; DIM],
    n: usize,
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
        self.n
    }

    /// Whether there are no anchors.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// Padded length of the coordinate arrays.
    pub(crate) fn padded(&self) -> usize {
        self.dims[0].len()
    }

    /// Appends an anchor.
    pub fn push(&mut self, y: &Vec8) {
        if self.n == self.padded() {
            for d in &mut self.dims {
                d.resize(self.n + LANES, 0.0);
            }
        }
        self.n += 1;
        self.set(self.n - 1, y);
    }

    /// Replaces anchor `i` (panics when out of range; callers check).
    pub fn set(&mut self, i: usize, y: &Vec8) {
        assert!(i < self.n, "anchor {i} out of range");
        for k in 0..DIM {
            self.dims[k][i] = y[k];
        }
    }

    /// Removes anchor `i`, keeping the order of the others (panics when out of range).
    pub fn remove(&mut self, i: usize) {
        assert!(i < self.n, "anchor {i} out of range");
        for d in &mut self.dims {
            d.remove(i);
            d.push(0.0);
        }
        self.n -= 1;
        let padded = self.padded();
        if padded - self.n >= LANES {
            for d in &mut self.dims {
                d.truncate(padded - LANES);
            }
        }
    }

    /// Coordinate `k` of every anchor, zero-padded to [`AnchorCoords::padded`].
    pub(crate) fn dim(&self, k: usize) -> &[f64] {
        &self.dims[k]
    }

    /// Anchor `i`'s coordinates (panics when out of range).
    pub fn get(&self, i: usize) -> Vec8 {
        assert!(i < self.n, "anchor {i} out of range");
        Vec8::from_fn(|k, _| self.dims[k][i])
    }

    /// `sum_j w_j y_j * scale`: the weighted average in R^8 (`weights` has one entry per
    /// anchor; extra entries are ignored, missing ones count as zero). Compiled for the
    /// CPU's SIMD width at run time; every build gives the same bits (same operations, same
    /// order).
    pub fn weighted_sum(&self, weights: &[f64], scale: f64) -> Vec8 {
        dispatch(WeightedSum {
            coords: self,
            weights,
            scale,
        })
    }

    /// [`AnchorCoords::weighted_sum`] in vectors of `q`: one pass over the weights for all
    /// coordinates, each summed as [`LANES`] running lanes, added pairwise, then the
    /// remainder in order (what a dot product per coordinate would do).
    #[inline(always)]
    fn weighted_sum_with<Q: Quad>(&self, q: Q, weights: &[f64], scale: f64) -> Vec8 {
        let n = self.n.min(weights.len());
        let nc = n / LANES;
        let w = quads(weights, nc);
        let dims: [&[[f64; LANES]]; DIM] = std::array::from_fn(|k| quads(&self.dims[k], nc));
        let mut acc = [q.splat(0.0); DIM];
        for c in 0..nc {
            let wc = q.load(&w[c]);
            for k in 0..DIM {
                acc[k] = q.add(acc[k], q.mul(wc, q.load(&dims[k][c])));
            }
        }
        Vec8::from_fn(|k, _| {
            let mut s = sum_lanes(q.lanes(acc[k]));
            let tail = nc * LANES..n;
            for (w, y) in weights[tail.clone()].iter().zip(&self.dims[k][tail]) {
                s += w * y;
            }
            s * scale
        })
    }
}

/// [`AnchorCoords::weighted_sum`] as one SIMD operation.
struct WeightedSum<'a> {
    coords: &'a AnchorCoords,
    weights: &'a [f64],
    scale: f64,
}

impl pulp::WithSimd for WeightedSum<'_> {
    type Output = Vec8;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) -> Vec8 {
        match Wide::new(simd) {
            Some(q) => self.coords.weighted_sum_with(q, self.weights, self.scale),
            None => self
                .coords
                .weighted_sum_with(Plain, self.weights, self.scale),
        }
    }
}

/// Reusable buffers for [`inverse_weights`] (so batches do not allocate per query).
#[derive(Clone, Debug, Default)]
pub struct InverseScratch {
    a0: Vec<f64>,
    a1: Vec<f64>,
    d: Vec<f64>,
}

/// The error for kernel distances that are not finite: NaN comes from non-finite
/// coordinates; infinity with finite coordinates from `gamma` times a squared distance
/// overflowing.
pub(crate) fn distance_overflow(nan: bool, gamma: f64) -> SolveError {
    SolveError::InvalidParameter(if nan {
        "non-finite anchor or point coordinates".into()
    } else {
        format!(
            "gamma {gamma:e} is too large for these anchors: gamma times a squared distance \
             overflows"
        )
    })
}

/// Solves the inverse problem for one point: `psi` is the tangent plane at the point,
/// `yhat` its embedded position; writes one weight per anchor into `out` (cleared first).
/// The weights sum to 1 (renormalised, so to rounding), are one-hot (split evenly among
/// coincident anchors) when the point is exactly at an anchor, and tend to that smoothly.
///
/// ```
/// use wavg_solve::{AnchorCoords, InverseScratch, inverse_weights};
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
    let ctx = Ctx::new(psi, yhat, n, gamma)?;
    let padded = anchors.padded();
    scratch.a0.resize(padded, 0.0);
    scratch.a1.resize(padded, 0.0);
    scratch.d.resize(padded, 0.0);
    out.resize(padded, 0.0);
    let r = dispatch(InverseKernel {
        ctx: &ctx,
        ys: anchors,
        sc: scratch,
        out,
    });
    out.truncate(if r.is_ok() { n } else { 0 });
    r
}

/// The per-query constants of the kernel.
pub(crate) struct Ctx {
    p0: [f64; DIM],
    p1: [f64; DIM],
    yh: [f64; DIM],
    /// The inverse Gram matrix of `Psi`'s rows, `(h00, h01, h11)`: `|v_T|^2 = a^T G^{-1} a`.
    h: [f64; 3],
    gamma: f64,
    n: usize,
}

impl Ctx {
    /// The constants at the point `yhat` with tangent plane `psi`, for `n` anchors:
    /// [`SolveError::NoAnchors`], [`SolveError::InvalidParameter`] for a `gamma` that is
    /// not finite and positive, [`SolveError::DegenerateTangentPlane`] for a `psi` of
    /// (nearly) rank 1.
    pub(crate) fn new(psi: &Mat2x8, yhat: &Vec8, n: usize, gamma: f64) -> Result<Self, SolveError> {
        if n == 0 {
            return Err(SolveError::NoAnchors);
        }
        if gamma.is_nan() || gamma <= 0.0 || !gamma.is_finite() {
            return Err(SolveError::InvalidParameter(format!(
                "gamma must be finite and positive, got {gamma}"
            )));
        }
        let p0: [f64; DIM] = std::array::from_fn(|k| psi[(0, k)]);
        let p1: [f64; DIM] = std::array::from_fn(|k| psi[(1, k)]);
        let g00: f64 = p0.iter().map(|x| x * x).sum();
        let g11: f64 = p1.iter().map(|x| x * x).sum();
        let g01: f64 = p0.iter().zip(&p1).map(|(x, y)| x * y).sum();
        let det = g00 * g11 - g01 * g01;
        if det.is_nan() || det <= 1e-12 * g00 * g11 || !det.is_finite() {
            return Err(SolveError::DegenerateTangentPlane);
        }
        Ok(Self {
            p0,
            p1,
            yh: std::array::from_fn(|k| yhat[k]),
            h: [g11 / det, -g01 / det, g00 / det],
            gamma,
            n,
        })
    }

    /// The embedded point.
    pub(crate) fn yhat(&self) -> &[f64; DIM] {
        &self.yh
    }
}

/// The kernel's first pass, `LANES` anchors at a time: `a_j = Psi (y_j - yhat)` into `a0`
/// and `a1` and `d_j = |v_T|^2 + gamma |v_O|^2` into `ds` (all of the padded length), where
/// `|v_O|^2 = |v|^2 - |v_T|^2 >= 0`. Padded entries hold the values of a zero anchor.
#[inline(always)]
pub(crate) fn offsets<Q: Quad>(
    q: Q,
    ctx: &Ctx,
    ys: &AnchorCoords,
    a0: &mut [f64],
    a1: &mut [f64],
    ds: &mut [f64],
) {
    let Ctx {
        p0,
        p1,
        yh,
        h,
        gamma,
        ..
    } = ctx;
    let (h0, h01, h2) = (q.splat(h[0]), q.splat(2.0 * h[1]), q.splat(h[2]));
    let (gv, gm1) = (q.splat(*gamma), q.splat(gamma - 1.0));
    let (yhs, p0s, p1s) = (
        yh.map(|x| q.splat(x)),
        p0.map(|x| q.splat(x)),
        p1.map(|x| q.splat(x)),
    );
    let zero = q.splat(0.0);
    let nc = ys.padded() / LANES;
    let dims: [&[[f64; LANES]]; DIM] = std::array::from_fn(|k| quads(&ys.dims[k], nc));
    let (a0, a1, ds) = (quads_mut(a0, nc), quads_mut(a1, nc), quads_mut(ds, nc));
    for c in 0..nc {
        let (mut vv, mut x0, mut x1) = (zero, zero, zero);
        for k in 0..DIM {
            let v = q.sub(q.load(&dims[k][c]), yhs[k]);
            vv = q.add(vv, q.mul(v, v));
            x0 = q.add(x0, q.mul(p0s[k], v));
            x1 = q.add(x1, q.mul(p1s[k], v));
        }
        let vt = q.add(
            q.add(q.mul(q.mul(h0, x0), x0), q.mul(q.mul(h01, x0), x1)),
            q.mul(q.mul(h2, x1), x1),
        );
        let vt = q.min_left(vt, vv);
        q.store(q.sub(q.mul(gv, vv), q.mul(gm1, vt)), &mut ds[c]);
        q.store(x0, &mut a0[c]);
        q.store(x1, &mut a1[c]);
    }
}

/// The first `nc` groups of [`LANES`] of `x` (panics when shorter).
#[inline(always)]
pub(crate) fn quads(x: &[f64], nc: usize) -> &[[f64; LANES]] {
    bytemuck::cast_slice(&x[..nc * LANES])
}

/// [`quads`], mutable.
#[inline(always)]
pub(crate) fn quads_mut(x: &mut [f64], nc: usize) -> &mut [[f64; LANES]] {
    bytemuck::cast_slice_mut(&mut x[..nc * LANES])
}

/// [`kernel`] for one query as one SIMD operation.
struct InverseKernel<'a> {
    ctx: &'a Ctx,
    ys: &'a AnchorCoords,
    sc: &'a mut InverseScratch,
    out: &'a mut [f64],
}

impl pulp::WithSimd for InverseKernel<'_> {
    type Output = Result<(), SolveError>;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) -> Self::Output {
        match Wide::new(simd) {
            Some(q) => kernel(q, self.ctx, self.ys, self.sc, self.out),
            None => kernel(Plain, self.ctx, self.ys, self.sc, self.out),
        }
    }
}

/// The inverse problem's passes over the anchors, [`LANES`] at a time in vectors of `q`
/// (the same operations in the same order whatever the instruction set, so the same bits).
/// `sc` and `out` have the padded length; padded entries get `d = inf`, hence `s = 0` and
/// no influence.
#[inline(always)]
fn kernel<Q: Quad>(
    q: Q,
    ctx: &Ctx,
    ys: &AnchorCoords,
    sc: &mut InverseScratch,
    out: &mut [f64],
) -> Result<(), SolveError> {
    let (gamma, n) = (ctx.gamma, ctx.n);
    let len = ys.padded();
    let (a0, a1, ds) = (&mut sc.a0[..len], &mut sc.a1[..len], &mut sc.d[..len]);
    let out = &mut out[..len];
    offsets(q, ctx, ys, a0, a1, ds);
    let zero = q.splat(0.0);
    // Smallest d (first index), largest, and a NaN check, over the n real anchors.
    let full = n / LANES * LANES;
    let (mut lo, mut hi, mut bad) = (q.splat(f64::INFINITY), zero, zero);
    for d in quads(ds, n / LANES) {
        let d = q.load(d);
        lo = q.min_left(d, lo);
        hi = q.max_left(d, hi);
        // d - d is 0 for finite d, NaN for NaN and infinite d: an infinite d is caught below.
        bad = q.add(bad, q.sub(d, d));
    }
    let (mut dmin, mut dmax) = (f64::INFINITY, 0.0f64);
    let mut nan = q.lanes(bad).iter().any(|x| x.is_nan());
    for (l, h) in q.lanes(lo).into_iter().zip(q.lanes(hi)) {
        dmin = if l < dmin { l } else { dmin };
        dmax = if h > dmax { h } else { dmax };
    }
    for &d in &ds[full..n] {
        dmin = if d < dmin { d } else { dmin };
        dmax = if d > dmax { d } else { dmax };
        nan |= d.is_nan();
    }
    if nan || !dmax.is_finite() {
        return Err(distance_overflow(ds[..n].iter().any(|d| d.is_nan()), gamma));
    }
    if dmin <= 0.0 {
        one_hot(&ds[..n], &mut out[..n]);
        return Ok(());
    }
    let m = ds[..n].iter().position(|&d| d == dmin).unwrap_or(0);
    ds[n..].fill(f64::INFINITY);
    let (am0, am1) = (a0[m], a1[m]);
    let (am0s, am1s, dmins) = (q.splat(am0), q.splat(am1), q.splat(dmin));
    // Pass 2: constraint rows centred on anchor m, s_j = (d_min/d_j)^2 (kept in `out`).
    let nc = len / LANES;
    let (a0, a1, ds) = (quads(a0, nc), quads(a1, nc), quads(ds, nc));
    let out = quads_mut(out, nc);
    let mut acc = [zero; 6];
    for c in 0..nc {
        let r = q.div(dmins, q.load(&ds[c]));
        let s = q.mul(r, r);
        let c0 = q.sub(q.load(&a0[c]), am0s);
        let c1 = q.sub(q.load(&a1[c]), am1s);
        let (sc0, sc1) = (q.mul(s, c0), q.mul(s, c1));
        acc[0] = q.add(acc[0], q.mul(sc0, c0));
        acc[1] = q.add(acc[1], q.mul(sc0, c1));
        acc[2] = q.add(acc[2], sc0);
        acc[3] = q.add(acc[3], q.mul(sc1, c1));
        acc[4] = q.add(acc[4], sc1);
        acc[5] = q.add(acc[5], s);
        q.store(s, &mut out[c]);
    }
    let [m00, m01, m02, m11, m12, m22] = acc.map(|a| sum_lanes(q.lanes(a)));
    let b = [-am0, -am1, 1.0];
    let Some(z) = solve_scaled_3x3([[m00, m01, m02], [m01, m11, m12], [m02, m12, m22]], b) else {
        // Singular: either the other anchors' contributions underflowed because the point
        // is (to within ~1e-150 relative) at an anchor, or the anchors are degenerate.
        if dmin <= 1e-100 * dmax {
            one_hot(&ds.as_flattened()[..n], &mut out.as_flattened_mut()[..n]);
            return Ok(());
        }
        return Err(SolveError::DegenerateAnchors);
    };
    // Pass 3: w_j = s_j c_j . z.
    let (z0, z1, z2) = (q.splat(z[0]), q.splat(z[1]), q.splat(z[2]));
    let mut sums = zero;
    for c in 0..nc {
        let c0 = q.sub(q.load(&a0[c]), am0s);
        let c1 = q.sub(q.load(&a1[c]), am1s);
        let w = q.mul(
            q.load(&out[c]),
            q.add(q.add(q.mul(c0, z0), q.mul(c1, z1)), z2),
        );
        q.store(w, &mut out[c]);
        sums = q.add(sums, w);
    }
    let sum = sum_lanes(q.lanes(sums));
    if !sum.is_finite() || (sum - 1.0).abs() > 1e-6 {
        return Err(SolveError::DegenerateAnchors);
    }
    let inv = q.splat(1.0 / sum);
    for w in out {
        q.store(q.mul(q.load(w), inv), w);
    }
    Ok(())
}

/// Equal weights on the anchors with the smallest `d` (the point is at them), zero elsewhere.
fn one_hot(ds: &[f64], out: &mut [f64]) {
    let dmin = ds.iter().copied().fold(f64::INFINITY, f64::min);
    let hits = ds.iter().filter(|&&d| d <= dmin).count() as f64;
    for (w, &d) in out.iter_mut().zip(ds) {
        *w = if d <= dmin { 1.0 / hits } else { 0.0 };
    }
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

#[cfg(test)]
mod tests {

    /// The run-time dispatched weighted sum gives the plain loops' bits, for anchor
    /// counts around the vector width.
    #[test]
    fn weighted_sum_paths_agree_bitwise() {
        for n in [1usize, 3, 4, 5, 27, 93, 100] {
            let pts: Vec<Vec8> = (0..n)
                .map(|i| Vec8::from_fn(|k, _| ((i * 8 + k) as f64 * 0.7316).sin() * 3.0))
                .collect();
            let c = AnchorCoords::from_points(&pts);
            let w: Vec<f64> = (0..n)
                .map(|i| ((i as f64) * 1.37).cos() / n as f64)
                .collect();
            let a = c.weighted_sum(&w, 1.25);
            let b = c.weighted_sum_with(Plain, &w, 1.25);
            assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits), "{n}");
            // One dot product per coordinate, in the same order.
            let dots = Vec8::from_fn(|k, _| {
                crate::simd::dot(pulp::Scalar::new(), &w, &c.dims[k][..n]) * 1.25
            });
            assert_eq!(a.map(f64::to_bits), dots.map(f64::to_bits), "{n}");
            let direct: Vec8 = pts.iter().zip(&w).map(|(p, w)| p * (*w * 1.25)).sum();
            assert!((a - direct).norm() < 1e-12, "{n}");
        }
    }

    use super::*;
    use rand::{Rng, SeedableRng};

    /// The kernel built for this CPU gives the plain build's results bit for bit, so
    /// answers do not depend on the machine.
    #[test]
    fn simd_and_portable_kernels_agree_exactly() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        // Anchor counts around the vector width; points anywhere, near an anchor (down to
        // rounding level) and at one (one-hot).
        let cases = [1usize, 3, 4, 5, 27, 93, 100]
            .into_iter()
            .flat_map(|n| [0.0, 1e-3, 1e-9, 1e-160, -1.0].map(move |near| (n, near)))
            .chain((0..200).map(|i| (1 + i % 130, 0.0)));
        for (n, near) in cases {
            let ys: Vec<Vec8> = (0..n)
                .map(|_| Vec8::from_fn(|_, _| rng.random_range(-1.0..1.0)))
                .collect();
            let coords = AnchorCoords::from_points(&ys);
            let yh: [f64; DIM] = std::array::from_fn(|k| match near {
                0.0 => rng.random_range(-1.0..1.0),
                -1.0 => ys[n / 2][k],
                e => ys[n / 2][k] + e * rng.random_range(-1.0..1.0),
            });
            let ctx = Ctx {
                p0: std::array::from_fn(|_| rng.random_range(-1.0..1.0)),
                p1: std::array::from_fn(|_| rng.random_range(-1.0..1.0)),
                yh,
                h: [1.1, 0.1, 0.9],
                gamma: [10.0, 1.0, 3.5][n % 3],
                n,
            };
            let padded = coords.padded();
            type Kernel<'a> = &'a dyn Fn(&mut InverseScratch, &mut [f64]) -> Result<(), SolveError>;
            let run = |f: Kernel<'_>| {
                let mut sc = InverseScratch {
                    a0: vec![0.0; padded],
                    a1: vec![0.0; padded],
                    d: vec![0.0; padded],
                };
                let mut out = vec![0.0; padded];
                f(&mut sc, &mut out).map(|()| out)
            };
            let a = run(&|sc, out| {
                dispatch(InverseKernel {
                    ctx: &ctx,
                    ys: &coords,
                    sc,
                    out,
                })
            });
            let b = run(&|sc, out| kernel(Plain, &ctx, &coords, sc, out));
            let c = run(&|sc, out| reference_kernel(&ctx, &coords, sc, out));
            let bits = |r: &Result<Vec<f64>, SolveError>| {
                r.as_ref()
                    .map(|w| w.iter().map(|x| x.to_bits()).collect::<Vec<_>>())
                    .ok()
            };
            assert!(a.is_ok() || n < 4, "n = {n}, near {near}");
            assert_eq!(a.is_ok(), c.is_ok(), "n = {n}");
            assert_eq!(bits(&a), bits(&b), "n = {n}");
            assert_eq!(bits(&a), bits(&c), "n = {n}");
        }
    }

    /// The kernel as plain per-lane loops, each lane's operations written out in order:
    /// the vector kernel must give its bits.
    fn reference_kernel(
        ctx: &Ctx,
        ys: &AnchorCoords,
        sc: &mut InverseScratch,
        out: &mut [f64],
    ) -> Result<(), SolveError> {
        let Ctx {
            p0,
            p1,
            yh,
            h,
            gamma,
            n,
        } = ctx;
        let (gamma, n) = (*gamma, *n);
        let len = ys.padded();
        let (a0, a1, ds) = (&mut sc.a0[..len], &mut sc.a1[..len], &mut sc.d[..len]);
        let out = &mut out[..len];
        // Pass 1, [`LANES`] anchors at a time with the sums in registers:
        // a_j = Psi (y_j - yhat), |v_j|^2 and d_j = |v_T|^2 + gamma |v_O|^2, where
        // |v_O|^2 = |v|^2 - |v_T|^2 >= 0.
        let gm1 = gamma - 1.0;
        let chunks = a0
            .chunks_exact_mut(LANES)
            .zip(a1.chunks_exact_mut(LANES))
            .zip(ds.chunks_exact_mut(LANES))
            .enumerate();
        for (c, ((x0s, x1s), dd)) in chunks {
            let mut vv = [0.0; LANES];
            let mut x0 = [0.0; LANES];
            let mut x1 = [0.0; LANES];
            for k in 0..DIM {
                let y = &ys.dims[k][c * LANES..(c + 1) * LANES];
                for l in 0..LANES {
                    let v = y[l] - yh[k];
                    vv[l] += v * v;
                    x0[l] += p0[k] * v;
                    x1[l] += p1[k] * v;
                }
            }
            for l in 0..LANES {
                let vt = h[0] * x0[l] * x0[l] + 2.0 * h[1] * x0[l] * x1[l] + h[2] * x1[l] * x1[l];
                let vt = if vt < vv[l] { vt } else { vv[l] };
                dd[l] = gamma * vv[l] - gm1 * vt;
                x0s[l] = x0[l];
                x1s[l] = x1[l];
            }
        }
        // Smallest d (first index), largest, and a NaN check.
        let (mut dmin, mut m, mut dmax, mut bad) = (f64::INFINITY, 0, 0.0f64, false);
        for (j, &d) in ds[..n].iter().enumerate() {
            if d < dmin {
                dmin = d;
                m = j;
            }
            if d > dmax {
                dmax = d;
            }
            bad |= d.is_nan();
        }
        if bad || !dmax.is_finite() {
            return Err(distance_overflow(bad, gamma));
        }
        if dmin <= 0.0 {
            one_hot(&ds[..n], &mut out[..n]);
            return Ok(());
        }
        ds[n..].fill(f64::INFINITY);
        let (am0, am1) = (a0[m], a1[m]);
        // Pass 2: constraint rows centred on anchor m, s_j = (d_min/d_j)^2 (kept in `out`).
        let mut acc = [[0.0; LANES]; 6];
        let chunks = a0
            .chunks_exact(LANES)
            .zip(a1.chunks_exact(LANES))
            .zip(ds.chunks_exact(LANES))
            .zip(out.chunks_exact_mut(LANES));
        for (((x0, x1), d), ss) in chunks {
            for l in 0..LANES {
                let r = dmin / d[l];
                let s = r * r;
                let c0 = x0[l] - am0;
                let c1 = x1[l] - am1;
                let sc0 = s * c0;
                let sc1 = s * c1;
                acc[0][l] += sc0 * c0;
                acc[1][l] += sc0 * c1;
                acc[2][l] += sc0;
                acc[3][l] += sc1 * c1;
                acc[4][l] += sc1;
                acc[5][l] += s;
                ss[l] = s;
            }
        }
        let [m00, m01, m02, m11, m12, m22] = acc.map(sum_lanes);
        let b = [-am0, -am1, 1.0];
        let Some(z) = solve_scaled_3x3([[m00, m01, m02], [m01, m11, m12], [m02, m12, m22]], b)
        else {
            // Singular: either the other anchors' contributions underflowed because the point
            // is (to within ~1e-150 relative) at an anchor, or the anchors are degenerate.
            if dmin <= 1e-100 * dmax {
                one_hot(&ds[..n], &mut out[..n]);
                return Ok(());
            }
            return Err(SolveError::DegenerateAnchors);
        };
        // Pass 3: w_j = s_j c_j . z.
        let mut sums = [0.0; LANES];
        let chunks = a0
            .chunks_exact(LANES)
            .zip(a1.chunks_exact(LANES))
            .zip(out.chunks_exact_mut(LANES));
        for ((x0, x1), ws) in chunks {
            for l in 0..LANES {
                let w = ws[l] * ((x0[l] - am0) * z[0] + (x1[l] - am1) * z[1] + z[2]);
                ws[l] = w;
                sums[l] += w;
            }
        }
        let sum = sum_lanes(sums);
        if !sum.is_finite() || (sum - 1.0).abs() > 1e-6 {
            return Err(SolveError::DegenerateAnchors);
        }
        let inv = 1.0 / sum;
        for w in out.iter_mut() {
            *w *= inv;
        }
        Ok(())
    }

    #[test]
    fn storage_edits_keep_order_and_zero_padding() {
        let p = |x: f64| Vec8::from_fn(|k, _| x + k as f64);
        let mut c = AnchorCoords::from_points(&[p(0.0), p(10.0), p(20.0), p(30.0), p(40.0)]);
        c.remove(1);
        assert_eq!(c.len(), 4);
        assert_eq!(c.padded(), 4);
        assert_eq!(
            (0..4).map(|i| c.get(i)[0]).collect::<Vec<_>>(),
            [0.0, 20.0, 30.0, 40.0]
        );
        c.set(0, &p(5.0));
        c.push(&p(50.0));
        assert_eq!(c.padded(), 8);
        assert!(c.dims.iter().all(|d| d[5..].iter().all(|&x| x == 0.0)));
        let w = [0.0, 0.0, 0.5, 0.0, 0.5];
        assert_eq!(c.weighted_sum(&w, 1.0)[0], 40.0);
    }
}
