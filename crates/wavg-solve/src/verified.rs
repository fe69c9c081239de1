//! Inverse weights that are checked to round-trip: the paper's weights where the forward
//! problem brings them back to the point, otherwise weights with an extra penalty on how
//! far the average lies from the point.
//!
//! The paper's weights only make the point a *stationary* Phong projection of the average
//! `ybar`. On thin parts covered by few anchors (a pig's ears and feet with 27 anchors)
//! `ybar` lands about half the local thickness off the surface, another point of the
//! surface is closer, and the forward problem returns that point instead (4.5% of random
//! points on `pig.off`; the paper's Section 4.4 calls such weights meaningless and
//! detects them the same way, by solving the forward problem). Adding
//! `lambda * d_ref * |ybar - yhat|^2` to the objective (`d_ref` = the fourth smallest
//! `D_ii`) pulls the average onto the point; the smallest `lambda` of a ladder that
//! round-trips is used, so these weights stay as close to the paper's as possible, at the
//! price of more negative weights and a jump where the penalty switches on.

use wavg_mesh::SurfacePoint;

use wavg_project::Par;

use crate::batch::{BatchWeights, ForwardScratch};
use crate::error::SolveError;
use crate::kernel::AnchorCoords;
use crate::points::check_point;
use crate::solver::{ForwardOptions, ForwardResult, Solver};
use crate::{DIM, Mat2x8, Vec8};

/// The penalties tried, in order, after the paper's weights.
pub const PENALTY_LADDER: [f64; 4] = [10.0, 100.0, 1_000.0, 10_000.0];

/// Points one parallel task checks for their round trip.
const CHECK_CHUNK: usize = 256;
/// Points one parallel task gives penalized weights.
const PENALTY_CHUNK: usize = 16;

/// Default round-trip tolerance, in mean edge lengths of the mesh (the Table 1 bench's).
pub const DEFAULT_TOLERANCE: f64 = 1e-3;

/// How verified weights were obtained.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RoundTrip {
    /// The paper's weights round-trip.
    Paper,
    /// The paper's did not; these use the offset penalty `lambda`.
    Penalized(f64),
    /// No weights of the ladder round-trip; the paper's weights are returned (the point is
    /// not reached as a weighted average of these anchors: add anchors near it).
    NotReached,
}

/// Weights with their round-trip status.
#[derive(Clone, Debug, PartialEq)]
pub struct Verified {
    /// One weight per anchor, summing to 1.
    pub weights: Vec<f64>,
    /// How they were found.
    pub round_trip: RoundTrip,
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
    let n = anchors.len();
    if n == 0 {
        return Err(SolveError::NoAnchors);
    }
    if !(gamma.is_finite() && gamma > 0.0 && lambda.is_finite() && lambda >= 0.0) {
        return Err(SolveError::InvalidParameter(format!(
            "gamma must be finite and positive and lambda finite and non-negative, got \
             {gamma} and {lambda}"
        )));
    }
    let g = psi * psi.transpose();
    let gi = g
        .try_inverse()
        .filter(|m| m.iter().all(|x| x.is_finite()))
        .ok_or(SolveError::DegenerateTangentPlane)?;
    let v: Vec<Vec8> = (0..n).map(|i| anchors.get(i) - yhat).collect();
    let a: Vec<nalgebra::Vector2<f64>> = v.iter().map(|v| psi * v).collect();
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
        return Err(SolveError::InvalidParameter(
            "non-finite anchor or point coordinates".into(),
        ));
    }
    let mut sorted = d.clone();
    let k = 3.min(n - 1);
    sorted.select_nth_unstable_by(k, f64::total_cmp);
    if sorted[..=k].iter().any(|&x| x <= 0.0) {
        // The point is an anchor: the one-hot weight is exact (and has no offset).
        let i = d.iter().position(|&x| x <= 0.0).unwrap_or(0);
        return Ok((0..n).map(|j| if j == i { 1.0 } else { 0.0 }).collect());
    }
    // Scale-free: D / d_ref, and the penalty scaled the same way.
    let d_ref = sorted[k];
    let dinv2: Vec<f64> = d.iter().map(|x| (d_ref / x).powi(2)).collect();
    let mu = lambda / d_ref;
    // M = D^2 + mu V^T V; M^-1 x = z - D^-2 V^T S^-1 V z with z = D^-2 x and
    // S = I / mu + V D^-2 V^T (8x8).
    // S is symmetric positive definite for mu > 0: its upper triangle by rank-one updates
    // (a tenth of the flops of full outer products), then a Cholesky factor.
    let s_chol = (mu > 0.0)
        .then(|| {
            let mut s = nalgebra::SMatrix::<f64, DIM, DIM>::identity() / mu;
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
    // The constraint rows C = [a_0; a_1; 1] (3 x n) and Q = M^-1 C^T, row by row.
    use nalgebra::Vector3;
    let c: Vec<Vector3<f64>> = a.iter().map(|a| Vector3::new(a[0], a[1], 1.0)).collect();
    let mut q: Vec<Vector3<f64>> = c.iter().zip(&dinv2).map(|(ci, &di)| ci * di).collect();
    if let Some(s_chol) = &s_chol {
        // Woodbury: subtract D^-2 V^T S^-1 V z from z = D^-2 x, for the three columns.
        let mut t = nalgebra::SMatrix::<f64, DIM, 3>::zeros();
        for (vi, qi) in v.iter().zip(&q) {
            t += vi * qi.transpose();
        }
        let u = s_chol.solve(&t);
        for ((qi, vi), &di) in q.iter_mut().zip(&v).zip(&dinv2) {
            *qi -= (u.transpose() * vi) * di;
        }
    }
    let gm: nalgebra::Matrix3<f64> = c.iter().zip(&q).map(|(ci, qi)| ci * qi.transpose()).sum();
    let z = gm
        .lu()
        .solve(&nalgebra::Vector3::new(0.0, 0.0, 1.0))
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

impl Solver {
    /// The inverse problem, checked by the forward problem (default options: the paper's
    /// search from the highest-weight anchor, no initial guess): the paper's weights when
    /// they return to `point` within `tolerance` mean edge lengths, otherwise the first
    /// weights of [`PENALTY_LADDER`] that do (see the module docs), otherwise the paper's
    /// weights marked [`RoundTrip::NotReached`].
    ///
    /// ```
    /// use std::sync::Arc;
    /// use wavg_mesh::{SurfacePoint, ValidMesh, procedural};
    /// use wavg_solve::{DEFAULT_TOLERANCE, RoundTrip};
    /// use wavg_solve::{Anchor, EmbeddedMesh, Projector, Solver};
    /// let mesh = Arc::new(ValidMesh::new(procedural::icosphere(3)).unwrap());
    /// let proj = Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh))).unwrap());
    /// let solver = Solver::new(proj, (0..12).map(Anchor::Vertex)).unwrap();
    /// let v = solver
    ///     .inverse_verified(&SurfacePoint::new(100, [0.2, 0.3, 0.5]), DEFAULT_TOLERANCE)
    ///     .unwrap();
    /// assert_eq!(v.round_trip, RoundTrip::Paper);
    /// ```
    pub fn inverse_verified(
        &self,
        point: &SurfacePoint,
        tolerance: f64,
    ) -> Result<Verified, SolveError> {
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(SolveError::InvalidParameter(format!(
                "the round-trip tolerance must be finite and positive, got {tolerance}"
            )));
        }
        let p = check_point(self.mesh(), point)?;
        let paper = self.inverse(point)?;
        let target = p.position(self.mesh());
        let tol = tolerance * self.mean_edge_length();
        let returns = |w: &[f64]| {
            self.forward(w, &ForwardOptions::default())
                .is_ok_and(|r| (r.position - target).norm() <= tol)
        };
        if returns(&paper) {
            return Ok(Verified {
                weights: paper,
                round_trip: RoundTrip::Paper,
            });
        }
        let (psi, yhat) = self.tangent_plane(&p);
        for lambda in PENALTY_LADDER {
            let w = penalized_weights(&psi, &yhat, self.anchors().coords(), self.gamma(), lambda)?;
            if returns(&w) {
                return Ok(Verified {
                    weights: w,
                    round_trip: RoundTrip::Penalized(lambda),
                });
            }
        }
        Ok(Verified {
            weights: paper,
            round_trip: RoundTrip::NotReached,
        })
    }

    /// [`Solver::inverse_verified`] for many points in parallel on the current rayon pool
    /// (results in input order, equal to the one-by-one ones for any thread count); see
    /// [`Solver::inverse_verified_batch_into`].
    pub fn inverse_verified_batch(
        &self,
        points: &[SurfacePoint],
        tolerance: f64,
    ) -> Vec<Result<Verified, SolveError>> {
        let mut weights = BatchWeights::default();
        let mut trips = Vec::new();
        // `Par::Rayon` always starts.
        let _ = self.inverse_verified_batch_into(
            points,
            tolerance,
            &mut weights,
            &mut trips,
            Par::Rayon,
        );
        weights
            .iter()
            .zip(trips)
            .map(|(w, t)| {
                Ok(Verified {
                    weights: w.map_err(Clone::clone)?.to_vec(),
                    round_trip: t?,
                })
            })
            .collect()
    }

    /// [`Solver::inverse_verified_batch`] into existing buffers, with explicit parallelism
    /// (the results do not depend on it): row `i` of `weights` and `round_trips[i]` belong
    /// to `points[i]` (both carry the error when it failed). In stages, each a batch: the
    /// paper's weights for all points ([`Solver::inverse_batch_into`]) and their forward
    /// problems ([`Solver::forward_batch_into`], which orders them for cache locality);
    /// then, for the points still not returned, one rung of the penalty ladder at a time.
    /// Fails only when `par`'s threads cannot start.
    ///
    /// ```
    /// use std::sync::Arc;
    /// use wavg_mesh::{SurfacePoint, ValidMesh, procedural};
    /// use wavg_solve::{DEFAULT_TOLERANCE, RoundTrip};
    /// use wavg_solve::{Anchor, BatchWeights, EmbeddedMesh, Par, Projector, Solver};
    /// let mesh = Arc::new(ValidMesh::new(procedural::icosphere(3)).unwrap());
    /// let proj = Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh))).unwrap());
    /// let solver = Solver::new(proj, (0..12).map(Anchor::Vertex)).unwrap();
    /// let points = [SurfacePoint::new(100, [0.2, 0.3, 0.5]), SurfacePoint::new(9999, [1.0, 0.0, 0.0])];
    /// let (mut w, mut trips) = (BatchWeights::default(), Vec::new());
    /// solver
    ///     .inverse_verified_batch_into(&points, DEFAULT_TOLERANCE, &mut w, &mut trips, Par::Seq)
    ///     .unwrap();
    /// assert_eq!(trips[0], Ok(RoundTrip::Paper));
    /// assert!(w.get(1).is_err() && trips[1].is_err()); // no face 9999
    /// ```
    pub fn inverse_verified_batch_into(
        &self,
        points: &[SurfacePoint],
        tolerance: f64,
        weights: &mut BatchWeights,
        round_trips: &mut Vec<Result<RoundTrip, SolveError>>,
        par: Par,
    ) -> Result<(), SolveError> {
        self.inverse_batch_into(points, weights, par)?;
        round_trips.clear();
        if !(tolerance.is_finite() && tolerance > 0.0) {
            let e = SolveError::InvalidParameter(format!(
                "the round-trip tolerance must be finite and positive, got {tolerance}"
            ));
            for i in 0..points.len() {
                weights.set(i, Err(e.clone()));
            }
            round_trips.resize(points.len(), Err(e));
            return Ok(());
        }
        let mesh = self.mesh();
        let tol = tolerance * self.mean_edge_length();
        let returns = |p: &SurfacePoint, f: &Result<ForwardResult, SolveError>| {
            f.as_ref().is_ok_and(|f| {
                check_point(mesh, p).is_ok_and(|c| (f.position - c.position(mesh)).norm() <= tol)
            })
        };
        let opts = ForwardOptions::default();
        let (mut scratch, mut fwd) = (ForwardScratch::default(), Vec::new());
        let rows: Vec<&[f64]> = weights.iter().map(|r| r.unwrap_or(&[])).collect();
        self.forward_batch_into(&rows, &opts, &mut scratch, &mut fwd, par)?;
        let paper = &*weights;
        par.map_range(points.len(), CHECK_CHUNK, round_trips, |i| {
            match paper.get(i) {
                Err(e) => Err(e.clone()),
                Ok(_) if returns(&points[i], &fwd[i]) => Ok(RoundTrip::Paper),
                Ok(_) => Ok(RoundTrip::NotReached),
            }
        })?;
        let mut pending: Vec<usize> = (0..points.len())
            .filter(|&i| round_trips[i] == Ok(RoundTrip::NotReached))
            .collect();
        let mut tried = Vec::new();
        for lambda in PENALTY_LADDER {
            if pending.is_empty() {
                break;
            }
            par.map_range(pending.len(), PENALTY_CHUNK, &mut tried, |k| {
                let p = check_point(mesh, &points[pending[k]])?;
                let (psi, yhat) = self.tangent_plane(&p);
                penalized_weights(&psi, &yhat, self.anchors().coords(), self.gamma(), lambda)
            })?;
            let rows: Vec<&[f64]> = tried.iter().map(|r| r.as_deref().unwrap_or(&[])).collect();
            self.forward_batch_into(&rows, &opts, &mut scratch, &mut fwd, par)?;
            let mut still = Vec::new();
            for ((&i, w), f) in pending.iter().zip(&tried).zip(&fwd) {
                match w {
                    Err(e) => {
                        weights.set(i, Err(e.clone()));
                        round_trips[i] = Err(e.clone());
                    }
                    Ok(w) if returns(&points[i], f) => {
                        weights.set(i, Ok(w));
                        round_trips[i] = Ok(RoundTrip::Penalized(lambda));
                    }
                    Ok(_) => still.push(i),
                }
            }
            pending = still;
        }
        Ok(())
    }
}
