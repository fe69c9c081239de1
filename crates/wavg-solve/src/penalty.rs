//! The verified inverse's penalised weights: the paper's objective plus an offset penalty
//! `lambda * d_ref * |ybar - yhat|^2`, solved for a ladder of `lambda`s at one point.
//!
//! Everything that does not depend on `lambda` (the anchors' offsets, their `D_ii`, the
//! constraint rows, the off-diagonal part of the Woodbury system) is computed once per
//! point by [`PenaltySystem::new`]; each rung then costs an 8x8 Cholesky factor and a few
//! passes over the anchors. The arithmetic is the same, operation for operation, as
//! solving each rung from scratch, so the weights are too.

use nalgebra::{SMatrix, Vector2, Vector3};

use crate::error::SolveError;
use crate::kernel::AnchorCoords;
use crate::{DIM, Mat2x8, Vec8};

/// The lambda-independent part of the penalised problem at one point.
#[derive(Clone, Debug)]
pub(crate) enum PenaltySystem {
    /// The point is an anchor: every penalty gives the one-hot weight of anchor `i`.
    OneHot {
        /// Anchor count.
        n: usize,
        /// The anchor at the point.
        i: usize,
    },
    /// The general case.
    Solve(Box<System>),
}

/// Per-anchor data and lambda-independent sums of [`PenaltySystem::Solve`].
#[derive(Clone, Debug)]
pub(crate) struct System {
    /// `v_i = y_i - yhat`.
    v: Vec<Vec8>,
    /// `(d_ref / D_ii)^2`.
    dinv2: Vec<f64>,
    /// The constraint rows `c_i = (Psi v_i, 1)`.
    c: Vec<Vector3<f64>>,
    /// `c_i (d_ref / D_ii)^2`: the rows of `Q` before the Woodbury correction.
    q0: Vec<Vector3<f64>>,
    /// `sum v_i q0_i^T`.
    t: SMatrix<f64, DIM, 3>,
    /// The strict upper triangle of `V D^-2 V^T` (zero on and below the diagonal).
    upper: SMatrix<f64, DIM, DIM>,
    /// The fourth smallest `D_ii`.
    d_ref: f64,
}

impl PenaltySystem {
    /// The system at the point `yhat` with tangent plane `psi` (errors as
    /// [`penalized_weights`]'s, except for `lambda`'s).
    pub(crate) fn new(
        psi: &Mat2x8,
        yhat: &Vec8,
        anchors: &AnchorCoords,
        gamma: f64,
    ) -> Result<Self, SolveError> {
        let n = anchors.len();
        if n == 0 {
            return Err(SolveError::NoAnchors);
        }
        if !(gamma.is_finite() && gamma > 0.0) {
            return Err(SolveError::InvalidParameter(format!(
                "gamma must be finite and positive, got {gamma}"
            )));
        }
        let g = psi * psi.transpose();
        let gi = g
            .try_inverse()
            .filter(|m| m.iter().all(|x| x.is_finite()))
            .ok_or(SolveError::DegenerateTangentPlane)?;
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
        if d.iter().any(|x| !x.is_finite()) {
            return Err(crate::kernel::distance_overflow(
                d.iter().any(|x| x.is_nan()),
                gamma,
            ));
        }
        let mut sorted = d.clone();
        let k = 3.min(n - 1);
        sorted.select_nth_unstable_by(k, f64::total_cmp);
        if sorted[..=k].iter().any(|&x| x <= 0.0) {
            // The point is an anchor: the one-hot weight is exact (and has no offset).
            let i = d.iter().position(|&x| x <= 0.0).unwrap_or(0);
            return Ok(Self::OneHot { n, i });
        }
        // Scale-free: D / d_ref, and the penalty scaled the same way.
        let d_ref = sorted[k];
        let dinv2: Vec<f64> = d.iter().map(|x| (d_ref / x).powi(2)).collect();
        // S = I / mu + V D^-2 V^T is built by rank-one updates of its upper triangle, in
        // anchor order; off the diagonal the sums start at zero whatever mu is.
        let mut upper = SMatrix::<f64, DIM, DIM>::zeros();
        for (vi, &di) in v.iter().zip(&dinv2) {
            for c in 1..DIM {
                let x = vi[c] * di;
                for r in 0..c {
                    upper[(r, c)] += vi[r] * x;
                }
            }
        }
        let c: Vec<Vector3<f64>> = a.iter().map(|a| Vector3::new(a[0], a[1], 1.0)).collect();
        let q0: Vec<Vector3<f64>> = c.iter().zip(&dinv2).map(|(ci, &di)| ci * di).collect();
        let mut t = SMatrix::<f64, DIM, 3>::zeros();
        for (vi, qi) in v.iter().zip(&q0) {
            t += vi * qi.transpose();
        }
        Ok(Self::Solve(Box::new(System {
            v,
            dinv2,
            c,
            q0,
            t,
            upper,
            d_ref,
        })))
    }

    /// The weights for penalty `lambda` (finite, non-negative).
    pub(crate) fn weights(&self, lambda: f64) -> Result<Vec<f64>, SolveError> {
        if !(lambda.is_finite() && lambda >= 0.0) {
            return Err(SolveError::InvalidParameter(format!(
                "lambda must be finite and non-negative, got {lambda}"
            )));
        }
        match self {
            Self::OneHot { n, i } => Ok((0..*n).map(|j| if j == *i { 1.0 } else { 0.0 }).collect()),
            Self::Solve(s) => s.weights(lambda),
        }
    }
}

impl System {
    fn weights(&self, lambda: f64) -> Result<Vec<f64>, SolveError> {
        let mu = lambda / self.d_ref;
        // M = D^2 + mu V^T V; M^-1 x = z - D^-2 V^T S^-1 V z with z = D^-2 x and
        // S = I / mu + V D^-2 V^T (8x8), symmetric positive definite for mu > 0.
        let s_chol = (mu > 0.0)
            .then(|| {
                let mut s = self.upper;
                let diag = 1.0 / mu;
                for c in 0..DIM {
                    s[(c, c)] = diag;
                }
                for (vi, &di) in self.v.iter().zip(&self.dinv2) {
                    for c in 0..DIM {
                        let x = vi[c] * di;
                        s[(c, c)] += vi[c] * x;
                    }
                }
                s.fill_lower_triangle_with_upper_triangle();
                s.cholesky()
            })
            .flatten();
        // Q = M^-1 C^T, row by row, for the constraint rows C = [a_0; a_1; 1] (3 x n).
        let mut q = self.q0.clone();
        if let Some(s_chol) = &s_chol {
            // Woodbury: subtract D^-2 V^T S^-1 V z from z = D^-2 x, for the three columns.
            let ut = s_chol.solve(&self.t).transpose();
            for ((qi, vi), &di) in q.iter_mut().zip(&self.v).zip(&self.dinv2) {
                *qi -= (ut * vi) * di;
            }
        }
        let gm: nalgebra::Matrix3<f64> = self
            .c
            .iter()
            .zip(&q)
            .map(|(ci, qi)| ci * qi.transpose())
            .sum();
        let z = gm
            .lu()
            .solve(&Vector3::new(0.0, 0.0, 1.0))
            .filter(|z| z.iter().all(|x| x.is_finite()))
            .ok_or(SolveError::DegenerateTangentPlane)?;
        let mut w: Vec<f64> = q.iter().map(|qi| qi.dot(&z)).collect();
        let sum: f64 = w.iter().sum();
        if !(sum.is_finite() && sum.abs() > 1e-12) {
            return Err(SolveError::DegenerateTangentPlane);
        }
        for x in &mut w {
            *x /= sum;
        }
        Ok(w)
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

    /// Every rung of one system gives the from-scratch weights to the last bit.
    #[test]
    fn rungs_equal_the_from_scratch_solve_bit_for_bit() {
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
                assert_eq!(
                    got.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                    want.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                    "case {case}, lambda {lambda}"
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
        let system =
            PenaltySystem::new(&psi, &ys[2], &AnchorCoords::from_points(&ys), 10.0).unwrap();
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
