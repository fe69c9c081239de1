//! The verified inverse's penalised weights: the paper's objective plus an offset penalty
//! `lambda * d_ref * |ybar - yhat|^2`, solved for a ladder of `lambda`s at one point.
//!
//! Everything that does not depend on `lambda` (the anchors' `D_ii` and constraint rows,
//! the sums `V D^-2 V^T`, `C D^-2 C^T` and `V D^-2 1`) is computed once per point by
//! [`PenaltySystem::new`]; each rung then costs an 8x8 Cholesky factor, a 3x3 solve and
//! one pass over the anchors. The passes run [`LANES`] anchors at a time in vectors (see
//! [`crate::simd::Quad`]), so the results are the same on every machine.

use nalgebra::{Matrix3, SMatrix, Vector3};

use crate::error::SolveError;
use crate::kernel::{AnchorCoords, Ctx, distance_overflow, offsets, quads, quads_mut};
use crate::simd::{LANES, Plain, Quad, Wide, dispatch, sum_lanes};
use crate::{DIM, Mat2x8, Vec8};

/// The lambda-independent part of the penalised problem at one point.
#[derive(Clone, Debug)]
pub(crate) enum PenaltySystem<'a> {
    /// The point is an anchor: every penalty gives the one-hot weight of anchor `i`.
    OneHot {
        /// Anchor count.
        n: usize,
        /// The anchor at the point.
        i: usize,
    },
    /// The general case.
    Solve(Box<System<'a>>),
}

/// Per-anchor data (padded, structure of arrays) and lambda-independent sums of
/// [`PenaltySystem::Solve`], with `v_i = y_i - yhat` and `s_i = (d_ref / D_ii)^2`.
#[derive(Clone, Debug)]
pub(crate) struct System<'a> {
    anchors: &'a AnchorCoords,
    yhat: [f64; DIM],
    /// `Psi v_i`: the first two entries of the constraint rows `c_i = (Psi v_i, 1)`.
    a0: Vec<f64>,
    a1: Vec<f64>,
    /// `s_i`; zero in the padding.
    s: Vec<f64>,
    /// `m = V S 1 = sum s_i v_i`, the last column of `V S C^T` (its first two columns,
    /// `V S V^T Psi^T`, are not needed: see [`System::weights_into`]).
    m: Vec8,
    /// `V S V^T = sum s_i v_i v_i^T`.
    vsv: SMatrix<f64, DIM, DIM>,
    /// `C S C^T = sum s_i c_i c_i^T`.
    csc: Matrix3<f64>,
    /// `Psi`, whose rows give the first two entries of the constraint rows.
    psi: Mat2x8,
    /// The fourth smallest `D_ii`.
    d_ref: f64,
}

impl<'a> PenaltySystem<'a> {
    /// The system at the point `yhat` with tangent plane `psi` (errors as
    /// [`penalized_weights`]'s, except for `lambda`'s).
    pub(crate) fn new(
        psi: &Mat2x8,
        yhat: &Vec8,
        anchors: &'a AnchorCoords,
        gamma: f64,
    ) -> Result<Self, SolveError> {
        let n = anchors.len();
        let ctx = Ctx::new(psi, yhat, n, gamma)?;
        let len = anchors.padded();
        let (mut a0, mut a1, mut d) = (vec![0.0; len], vec![0.0; len], vec![0.0; len]);
        dispatch(Offsets {
            ctx: &ctx,
            anchors,
            a0: &mut a0,
            a1: &mut a1,
            d: &mut d,
        });
        if let Some(x) = d[..n].iter().find(|x| !x.is_finite()) {
            return Err(distance_overflow(x.is_nan(), gamma));
        }
        if let Some(i) = d[..n].iter().position(|&x| x <= 0.0) {
            // The point is an anchor: the one-hot weight is exact (and has no offset).
            return Ok(Self::OneHot { n, i });
        }
        // Scale-free: D / d_ref, and the penalty scaled the same way.
        let d_ref = nth_smallest(&d[..n], 3.min(n - 1));
        // Zero in the padding; `s` in place of `D` (one buffer fewer).
        d[n..].fill(f64::INFINITY);
        for x in &mut d {
            let r = d_ref / *x;
            *x = r * r;
        }
        let s = d;
        let mut system = System {
            anchors,
            yhat: *ctx.yhat(),
            a0,
            a1,
            s,
            m: Vec8::zeros(),
            vsv: SMatrix::zeros(),
            csc: Matrix3::zeros(),
            psi: *psi,
            d_ref,
        };
        dispatch(Sums(&mut system));
        Ok(Self::Solve(Box::new(system)))
    }

    /// The weights for penalty `lambda` (finite, non-negative).
    pub(crate) fn weights(&self, lambda: f64) -> Result<Vec<f64>, SolveError> {
        let mut w = Vec::new();
        self.weights_into(lambda, &mut w)?;
        Ok(w)
    }

    /// [`PenaltySystem::weights`] into `out` (its memory reused from rung to rung).
    pub(crate) fn weights_into(&self, lambda: f64, out: &mut Vec<f64>) -> Result<(), SolveError> {
        if !(lambda.is_finite() && lambda >= 0.0) {
            return Err(SolveError::InvalidParameter(format!(
                "lambda must be finite and non-negative, got {lambda}"
            )));
        }
        match self {
            Self::OneHot { n, i } => {
                out.clear();
                out.extend((0..*n).map(|j| if j == *i { 1.0 } else { 0.0 }));
                Ok(())
            }
            Self::Solve(s) => s.weights_into(lambda, out),
        }
    }
}

/// The `k`-th smallest (from 0; `k < 4`, `k < xs.len()`) of the finite `xs`, in one pass
/// keeping the `k + 1` smallest seen (no copy, no sort).
fn nth_smallest(xs: &[f64], k: usize) -> f64 {
    let mut low = [f64::INFINITY; 4];
    for &x in xs {
        if x < low[k] {
            let mut j = k;
            while j > 0 && low[j - 1] > x {
                low[j] = low[j - 1];
                j -= 1;
            }
            low[j] = x;
        }
    }
    low[k]
}

/// [`offsets`] as one SIMD operation.
struct Offsets<'a> {
    ctx: &'a Ctx,
    anchors: &'a AnchorCoords,
    a0: &'a mut [f64],
    a1: &'a mut [f64],
    d: &'a mut [f64],
}

impl pulp::WithSimd for Offsets<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) {
        match Wide::new(simd) {
            Some(q) => offsets(q, self.ctx, self.anchors, self.a0, self.a1, self.d),
            None => offsets(Plain, self.ctx, self.anchors, self.a0, self.a1, self.d),
        }
    }
}

/// [`System::sums`] as one SIMD operation.
struct Sums<'s, 'a>(&'s mut System<'a>);

impl pulp::WithSimd for Sums<'_, '_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) {
        match Wide::new(simd) {
            Some(q) => self.0.sums(q),
            None => self.0.sums(Plain),
        }
    }
}

/// [`System::weigh`] as one SIMD operation.
struct Weigh<'s, 'a> {
    system: &'s System<'a>,
    z: [f64; 3],
    g: [f64; DIM],
    out: &'s mut [f64],
}

impl pulp::WithSimd for Weigh<'_, '_> {
    type Output = f64;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) -> f64 {
        match Wide::new(simd) {
            Some(q) => self.system.weigh(q, self.z, &self.g, self.out),
            None => self.system.weigh(Plain, self.z, &self.g, self.out),
        }
    }
}

impl System<'_> {
    /// Fills in `m`, `vsv` and `csc` (`s` and the rows already set): one pass over the
    /// anchors per row `K` of `vsv` and entry `K` of `m`, then one for `csc`, so that each pass's sums
    /// stay in vector registers (all 66 at once spill to memory at every anchor). Each sum
    /// adds the same products in the same order as one pass would.
    #[inline(always)]
    fn sums<Q: Quad>(&mut self, q: Q) {
        self.row_sums::<0, Q>(q);
        self.row_sums::<1, Q>(q);
        self.row_sums::<2, Q>(q);
        self.row_sums::<3, Q>(q);
        self.row_sums::<4, Q>(q);
        self.row_sums::<5, Q>(q);
        self.row_sums::<6, Q>(q);
        self.row_sums::<7, Q>(q);
        let zero = q.splat(0.0);
        let one = q.splat(1.0);
        let mut csc = [[zero; 3]; 3];
        let nc = self.s.len() / LANES;
        let (ss, a0, a1) = (quads(&self.s, nc), quads(&self.a0, nc), quads(&self.a1, nc));
        for c in 0..nc {
            let s = q.load(&ss[c]);
            let cr = [q.load(&a0[c]), q.load(&a1[c]), one];
            let sc = [q.mul(s, cr[0]), q.mul(s, cr[1]), s];
            for r in 0..3 {
                for j in r..3 {
                    csc[r][j] = q.add(csc[r][j], q.mul(cr[r], sc[j]));
                }
            }
        }
        self.csc = Matrix3::from_fn(|r, j| sum_lanes(q.lanes(csc[r.min(j)][r.max(j)])));
    }

    /// Entry `K` of `m` (`sum s_i v_ik`) and row `K` of `vsv` (`sum s_i v_ik v_il`,
    /// `l >= K`, mirrored).
    #[inline(always)]
    fn row_sums<const K: usize, Q: Quad>(&mut self, q: Q) {
        let zero = q.splat(0.0);
        let mut m = zero;
        let mut row = [zero; DIM];
        let nc = self.s.len() / LANES;
        let ss = quads(&self.s, nc);
        let ys: [&[[f64; LANES]]; DIM] = std::array::from_fn(|k| quads(self.anchors.dim(k), nc));
        let yhat: [Q::V; DIM] = std::array::from_fn(|k| q.splat(self.yhat[k]));
        for c in 0..nc {
            let s = q.load(&ss[c]);
            let vk = q.sub(q.load(&ys[K][c]), yhat[K]);
            // `s v_ik` (the product is the same either way round).
            let sv = q.mul(s, vk);
            m = q.add(m, sv);
            for l in K..DIM {
                let vl = q.sub(q.load(&ys[l][c]), yhat[l]);
                row[l] = q.add(row[l], q.mul(sv, vl));
            }
        }
        self.m[K] = sum_lanes(q.lanes(m));
        for (l, x) in row.iter().enumerate().skip(K) {
            let x = sum_lanes(q.lanes(*x));
            self.vsv[(K, l)] = x;
            self.vsv[(l, K)] = x;
        }
    }

    /// `out_i = s_i (c_i . z - v_i . g)` (zero in the padding); returns their sum.
    #[inline(always)]
    fn weigh<Q: Quad>(&self, q: Q, z: [f64; 3], g: &[f64; DIM], out: &mut [f64]) -> f64 {
        // c_i . z - v_i . g = a0_i z0 + a1_i z1 + (z2 + yhat . g) - y_i . g.
        let z2 = z[2] + (0..DIM).map(|k| self.yhat[k] * g[k]).sum::<f64>();
        let (z0, z1, z2) = (q.splat(z[0]), q.splat(z[1]), q.splat(z2));
        let gv: [Q::V; DIM] = std::array::from_fn(|k| q.splat(g[k]));
        let mut sum = q.splat(0.0);
        let nc = self.s.len() / LANES;
        let (ss, a0, a1) = (quads(&self.s, nc), quads(&self.a0, nc), quads(&self.a1, nc));
        let out = quads_mut(out, nc);
        for c in 0..nc {
            let mut yg = q.splat(0.0);
            for (k, gk) in gv.iter().enumerate() {
                let y = &self.anchors.dim(k)[c * LANES..(c + 1) * LANES];
                yg = q.add(yg, q.mul(q.load(y.try_into().expect("LANES long")), *gk));
            }
            let cz = q.add(
                q.add(q.mul(q.load(&a0[c]), z0), q.mul(q.load(&a1[c]), z1)),
                z2,
            );
            let w = q.mul(q.load(&ss[c]), q.sub(cz, yg));
            q.store(w, &mut out[c]);
            sum = q.add(sum, w);
        }
        sum_lanes(q.lanes(sum))
    }

    fn weights_into(&self, lambda: f64, w: &mut Vec<f64>) -> Result<(), SolveError> {
        let solve3 = |gm: Matrix3<f64>| {
            gm.lu()
                .solve(&Vector3::new(0.0, 0.0, 1.0))
                .filter(|z| z.iter().all(|x| x.is_finite()))
                .ok_or(SolveError::DegenerateTangentPlane)
        };
        // The weights are w_i = s_i (c_i - U v_i) . z, with U = T^T (V S V^T + eps I)^-1
        // (`eps = 1 / mu`, the Woodbury identity: an 8x8 system) and z solving
        // (C S C^T - U T) z = (0, 0, 1). `weigh` takes them as the coefficients of
        // `Psi v_i` (two), a constant and `g` in w_i = s_i (a . Psi v_i + b - v_i . g).
        let mu = lambda / self.d_ref;
        let chol = (mu > 0.0)
            .then(|| {
                let mut m = self.vsv;
                for c in 0..DIM {
                    m[(c, c)] += 1.0 / mu;
                }
                m.cholesky()
            })
            .flatten();
        let (a, b, g) = match chol {
            // No penalty: U = 0.
            None => {
                let z = solve3(self.csc)?;
                ([z[0], z[1]], z[2], Vec8::zeros())
            }
            // With c_i = (Psi v_i, 1), `T`'s first two columns are `V S V^T Psi^T`, so
            // C S C^T - U T and c_i - U v_i lose their `Psi` parts in closed form (no
            // cancellation as eps -> 0). With X = M^-1 Psi^T, y = M^-1 m, m = sum s_i v_i:
            // the 2x2 block is eps Psi (I - eps M^-1) Psi^T, the column eps Psi y, the
            // corner sum s_i - m . y; w_i = s_i (z_2 - v_i . (z_2 y - eps X z_01)). Rows
            // and columns 0 and 1 are scaled by 1 / sqrt(eps) to balance the system.
            Some(chol) => {
                let eps = 1.0 / mu;
                let r = eps.sqrt();
                let pt = self.psi.transpose();
                let x = chol.solve(&pt);
                let m = self.m;
                let y = chol.solve(&m);
                let pp = self.psi * pt - (self.psi * x) * eps;
                let py = self.psi * y * r;
                let gm = Matrix3::new(
                    pp[(0, 0)],
                    pp[(0, 1)],
                    py[0],
                    pp[(1, 0)],
                    pp[(1, 1)],
                    py[1],
                    py[0],
                    py[1],
                    self.csc[(2, 2)] - m.dot(&y),
                );
                let z = solve3(gm)?;
                let g = y * z[2] - x * nalgebra::Vector2::new(z[0], z[1]) * r;
                ([0.0, 0.0], z[2], g)
            }
        };
        w.clear();
        w.resize(self.s.len(), 0.0);
        let sum = dispatch(Weigh {
            system: self,
            z: [a[0], a[1], b],
            g: std::array::from_fn(|k| g[k]),
            out: w,
        });
        if !(sum.is_finite() && sum.abs() > 1e-12) {
            return Err(SolveError::DegenerateTangentPlane);
        }
        w.truncate(self.anchors.len());
        for x in w.iter_mut() {
            *x /= sum;
        }
        Ok(())
    }
}

/// Weights minimising `sum (D_ii w_i)^2 + lambda d_ref |ybar - yhat|^2` under the paper's
/// constraints (`Psi (ybar - yhat) = 0`, `sum w = 1`); `lambda = 0` gives the paper's.
///
/// The penalty has rank at most 8, so the normal equations are solved with the Woodbury
/// identity in `O(n)` (an 8x8 and a 3x3 system), not as an `n x n` system. That 8x8
/// system grows ill-conditioned as `lambda` does: results are accurate up to `lambda`
/// around 1e6 (the ladder stops at 1e4).
///
/// ```
/// use wavg_solve::AnchorCoords;
/// use wavg_solve::internal::penalized_weights;
/// use wavg_solve::{Mat2x8, Vec8};
/// let mut psi = Mat2x8::zeros();
/// psi[(0, 0)] = 1.0;
/// psi[(1, 1)] = 1.0;
/// // Four anchors: three in the tangent plane, one above it.
/// let pts = [[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [0.0, 3.0, 0.0], [1.0, 1.0, 2.0]];
/// let ys = pts.map(|p| Vec8::from_fn(|k, _| p.get(k).copied().unwrap_or(0.0)));
/// let yhat = Vec8::from_fn(|k, _| if k < 2 { 1.0 } else { 0.0 });
/// let anchors = AnchorCoords::from_points(&ys);
/// let w = penalized_weights(&psi, &yhat, &anchors, 10.0, 1e6).unwrap();
/// let ybar: Vec8 = ys.iter().zip(&w).map(|(y, w)| y * *w).sum();
/// assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
/// assert!((ybar - yhat).norm() < 1e-3); // the penalty pulls the average onto the point
/// ```
pub fn penalized_weights(
    psi: &Mat2x8,
    yhat: &Vec8,
    anchors: &AnchorCoords,
    gamma: f64,
    lambda: f64,
) -> Result<Vec<f64>, SolveError> {
    if anchors.is_empty() {
        return Err(SolveError::NoAnchors);
    }
    if !(gamma.is_finite() && gamma > 0.0 && lambda.is_finite() && lambda >= 0.0) {
        return Err(SolveError::InvalidParameter(format!(
            "gamma must be finite and positive and lambda finite and non-negative, got \
             {gamma} and {lambda}"
        )));
    }
    PenaltySystem::new(psi, yhat, anchors, gamma)?.weights(lambda)
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector2;
    use rand::{Rng, SeedableRng};

    use super::*;

    /// The weights as solved from scratch for one `lambda` (the algebra before the system
    /// was split into its lambda-independent part and the rungs).
    fn from_scratch(
        psi: &Mat2x8,
        yhat: &Vec8,
        anchors: &AnchorCoords,
        gamma: f64,
        lambda: f64,
    ) -> Vec<f64> {
        let n = anchors.len();
        let gi = (psi * psi.transpose()).try_inverse().unwrap();
        let v: Vec<Vec8> = (0..n).map(|i| anchors.get(i) - yhat).collect();
        let a: Vec<Vector2<f64>> = v.iter().map(|v| psi * v).collect();
        let d: Vec<f64> = v
            .iter()
            .zip(&a)
            .map(|(v, a)| {
                let vv = v.norm_squared();
                let vt = (a.transpose() * gi * a)[0].clamp(0.0, vv);
                vt + gamma * (vv - vt)
            })
            .collect();
        let mut sorted = d.clone();
        let k = 3.min(n - 1);
        sorted.select_nth_unstable_by(k, f64::total_cmp);
        let d_ref = sorted[k];
        let dinv2: Vec<f64> = d.iter().map(|x| (d_ref / x).powi(2)).collect();
        let mu = lambda / d_ref;
        let s_chol = (mu > 0.0)
            .then(|| {
                let mut s = SMatrix::<f64, DIM, DIM>::identity() / mu;
                for (vi, &di) in v.iter().zip(&dinv2) {
                    for c in 0..DIM {
                        let x = vi[c] * di;
                        for r in 0..=c {
                            s[(r, c)] += vi[r] * x;
                        }
                    }
                }
                s.fill_lower_triangle_with_upper_triangle();
                s.cholesky()
            })
            .flatten();
        let c: Vec<Vector3<f64>> = a.iter().map(|a| Vector3::new(a[0], a[1], 1.0)).collect();
        let mut q: Vec<Vector3<f64>> = c.iter().zip(&dinv2).map(|(ci, &di)| ci * di).collect();
        if let Some(s_chol) = &s_chol {
            let mut t = SMatrix::<f64, DIM, 3>::zeros();
            for (vi, qi) in v.iter().zip(&q) {
                t += vi * qi.transpose();
            }
            let u = s_chol.solve(&t);
            for ((qi, vi), &di) in q.iter_mut().zip(&v).zip(&dinv2) {
                *qi -= (u.transpose() * vi) * di;
            }
        }
        let gm: nalgebra::Matrix3<f64> = c.iter().zip(&q).map(|(ci, qi)| ci * qi.transpose()).sum();
        let z = gm.lu().solve(&Vector3::new(0.0, 0.0, 1.0)).unwrap();
        let mut w: Vec<f64> = q.iter().map(|qi| qi.dot(&z)).collect();
        let sum: f64 = w.iter().sum();
        for x in &mut w {
            *x /= sum;
        }
        w
    }

    /// Every rung of one system gives the from-scratch weights, to rounding (the two
    /// reduce the penalty differently; up to 1e-12 of the largest weight seen, 6e-11
    /// with 4 anchors at lambda 1e4, where the 8x8 system has 4 directions of size
    /// `1 / mu` only and both solves lose digits).
    #[test]
    fn rungs_equal_the_from_scratch_solve() {
        let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for case in 0..200 {
            let n = 4 + case % 120;
            let mut g = || r.random_range(-1.0..1.0);
            let psi = Mat2x8::from_fn(|_, _| g());
            let yhat = Vec8::from_fn(|_, _| g());
            let ys: Vec<Vec8> = (0..n).map(|_| Vec8::from_fn(|_, _| 2.0 * g())).collect();
            let anchors = AnchorCoords::from_points(&ys);
            let system = PenaltySystem::new(&psi, &yhat, &anchors, 10.0).unwrap();
            for lambda in [0.0, 10.0, 100.0, 1e3, 1e4, 3.7] {
                let want = from_scratch(&psi, &yhat, &anchors, 10.0, lambda);
                let got = system.weights(lambda).unwrap();
                let scale = want.iter().fold(1.0f64, |m, x| m.max(x.abs()));
                let err = got
                    .iter()
                    .zip(&want)
                    .map(|(g, w)| (g - w).abs())
                    .fold(0.0f64, f64::max);
                assert!(
                    err <= 1e-10 * scale,
                    "case {case}, lambda {lambda}: {err:e}"
                );
            }
        }
    }

    /// The sums as one pass over the anchors holding all of them (the order each sum's
    /// products are added in, which the passes of `System::sums` keep).
    fn one_pass_sums(
        sys: &System<'_>,
    ) -> (SMatrix<f64, DIM, 3>, SMatrix<f64, DIM, DIM>, Matrix3<f64>) {
        let q = Plain;
        let zero = q.splat(0.0);
        let (mut t, mut vsv, mut csc) = ([[zero; 3]; DIM], [[zero; DIM]; DIM], [[zero; 3]; 3]);
        let nc = sys.s.len() / LANES;
        let (ss, a0, a1) = (quads(&sys.s, nc), quads(&sys.a0, nc), quads(&sys.a1, nc));
        for c in 0..nc {
            let v: [_; DIM] = std::array::from_fn(|k| {
                let y = &sys.anchors.dim(k)[c * LANES..(c + 1) * LANES];
                q.sub(q.load(y.try_into().unwrap()), q.splat(sys.yhat[k]))
            });
            let s = q.load(&ss[c]);
            let cr = [q.load(&a0[c]), q.load(&a1[c]), q.splat(1.0)];
            let sc = [q.mul(s, cr[0]), q.mul(s, cr[1]), s];
            for r in 0..3 {
                for j in r..3 {
                    csc[r][j] = q.add(csc[r][j], q.mul(cr[r], sc[j]));
                }
            }
            for k in 0..DIM {
                for j in 0..3 {
                    t[k][j] = q.add(t[k][j], q.mul(v[k], sc[j]));
                }
                let sv = q.mul(s, v[k]);
                for l in k..DIM {
                    vsv[k][l] = q.add(vsv[k][l], q.mul(sv, v[l]));
                }
            }
        }
        (
            SMatrix::from_fn(|k, j| sum_lanes(q.lanes(t[k][j]))),
            SMatrix::from_fn(|k, l| sum_lanes(q.lanes(vsv[k.min(l)][k.max(l)]))),
            Matrix3::from_fn(|r, j| sum_lanes(q.lanes(csc[r.min(j)][r.max(j)]))),
        )
    }

    #[test]
    fn the_sums_by_row_equal_one_pass_bitwise() {
        let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        for case in 0..50 {
            let n = 4 + case * 7 % 130;
            let mut g = || r.random_range(-1.0..1.0);
            let psi = Mat2x8::from_fn(|_, _| g());
            let yhat = Vec8::from_fn(|_, _| g());
            let ys: Vec<Vec8> = (0..n).map(|_| Vec8::from_fn(|_, _| 2.0 * g())).collect();
            let anchors = AnchorCoords::from_points(&ys);
            let PenaltySystem::Solve(sys) =
                PenaltySystem::new(&psi, &yhat, &anchors, 10.0).unwrap()
            else {
                panic!("case {case}: no anchor at the point");
            };
            let (t, vsv, csc) = one_pass_sums(&sys);
            let bits = |m: &[f64]| m.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            // `m` is the last column of the one pass's `V S C^T`.
            assert_eq!(
                bits(sys.m.as_slice()),
                bits(t.column(2).as_slice()),
                "case {case}"
            );
            assert_eq!(
                bits(sys.vsv.as_slice()),
                bits(vsv.as_slice()),
                "case {case}"
            );
            assert_eq!(
                bits(sys.csc.as_slice()),
                bits(csc.as_slice()),
                "case {case}"
            );
        }
    }

    #[test]
    fn nth_smallest_is_the_order_statistic() {
        let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for case in 0..300 {
            let n = 1 + case % 40;
            // Few distinct values, so ties are common.
            let xs: Vec<f64> = (0..n)
                .map(|_| f64::from(r.random_range(0..6u8)) * 0.5)
                .collect();
            for k in 0..4.min(n) {
                let mut sorted = xs.clone();
                sorted.sort_by(f64::total_cmp);
                assert_eq!(
                    nth_smallest(&xs, k),
                    sorted[k],
                    "case {case}, k {k}: {xs:?}"
                );
            }
        }
    }

    #[test]
    fn a_point_at_an_anchor_is_one_hot_on_every_rung_and_bad_lambdas_fail() {
        let ys: Vec<Vec8> = (0..6).map(|i| Vec8::from_element(i as f64)).collect();
        let mut psi = Mat2x8::zeros();
        psi[(0, 0)] = 1.0;
        psi[(1, 1)] = 1.0;
        let anchors = AnchorCoords::from_points(&ys);
        let system = PenaltySystem::new(&psi, &ys[2], &anchors, 10.0).unwrap();
        for lambda in [0.0, 10.0, 1e4] {
            assert_eq!(
                system.weights(lambda).unwrap(),
                [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
            );
        }
        for lambda in [-1.0, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                system.weights(lambda),
                Err(SolveError::InvalidParameter(_))
            ));
        }
    }
}
