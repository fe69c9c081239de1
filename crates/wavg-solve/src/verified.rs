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

use crate::batch::{BatchWeights, PREPARE_CHUNK};
use crate::error::SolveError;
use crate::penalty::PenaltySystem;
use crate::points::check_point;
use crate::solver::{ForwardOptions, Solver};

/// The penalties tried, in order, after the paper's weights.
pub const PENALTY_LADDER: [f64; 4] = [10.0, 100.0, 1_000.0, 10_000.0];

/// Points one parallel task checks for their round trip.
const CHECK_CHUNK: usize = 256;
/// Points one parallel task takes up the penalty ladder.
const PENALTY_CHUNK: usize = 4;

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
        let opts = ForwardOptions::default();
        if self
            .forward(&paper, &opts)
            .is_ok_and(|r| (r.position - target).norm() <= tol)
        {
            return Ok(Verified {
                weights: paper,
                round_trip: RoundTrip::Paper,
            });
        }
        Ok(match self.ladder(&p, tol)? {
            Some((weights, lambda)) => Verified {
                weights,
                round_trip: RoundTrip::Penalized(lambda),
            },
            None => Verified {
                weights: paper,
                round_trip: RoundTrip::NotReached,
            },
        })
    }

    /// The first rung of [`PENALTY_LADDER`] whose weights return to the (checked) point
    /// `p` within `tol`, with its `lambda`; `None` when none does. The lambda-independent
    /// part of the problem is set up once for all rungs.
    fn ladder(&self, p: &SurfacePoint, tol: f64) -> Result<Option<(Vec<f64>, f64)>, SolveError> {
        let target = p.position(self.mesh());
        let (psi, yhat) = self.tangent_plane(p);
        let system = PenaltySystem::new(&psi, &yhat, self.anchors().coords(), self.gamma())?;
        let opts = ForwardOptions::default();
        let mut w = Vec::with_capacity(self.anchors().coords().padded());
        for lambda in PENALTY_LADDER {
            system.weights_into(lambda, &mut w)?;
            if self
                .forward(&w, &opts)
                .is_ok_and(|r| (r.position - target).norm() <= tol)
            {
                return Ok(Some((w, lambda)));
            }
        }
        Ok(None)
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
    /// paper's weights for all points, then each row prepared for its forward problem; the
    /// forward problems in the Morton order of their averages (as
    /// [`Solver::forward_batch_into`]), each reduced to whether it returns to its point;
    /// then the points still not returned, each up the penalty ladder on its own (the
    /// lambda-independent part of its problem set up once).
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
        round_trips.clear();
        if !(tolerance.is_finite() && tolerance > 0.0) {
            self.inverse_batch_into(points, weights, par)?;
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
        let opts = ForwardOptions::default();
        // The paper's weights, then each row prepared for its forward problem, as
        // `inverse_batch_into` and `forward_batch_into` do: per-point results stay small
        // (a prepared query carried along with its inverse's outcome costs a copy of a few
        // hundred bytes per point through the parallel collection).
        self.inverse_batch_into(points, weights, par)?;
        let paper = &*weights;
        let mut prepared = Vec::new();
        par.map_range(
            points.len(),
            PREPARE_CHUNK,
            &mut prepared,
            |i| match paper.get(i) {
                Ok(row) => self.prepare_keyed(row, &opts),
                Err(e) => (u64::MAX, Err(e.clone())),
            },
        )?;
        // Their forward problems, reduced to whether each returns to its point.
        let (mut order, mut pos, mut done, mut back) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        self.search_prepared(
            &prepared,
            &opts,
            &mut order,
            &mut pos,
            &mut done,
            &mut back,
            par,
            |i, f| {
                f.is_ok_and(|f| {
                    check_point(mesh, &points[i])
                        .is_ok_and(|c| (f.position - c.position(mesh)).norm() <= tol)
                })
            },
        )?;
        let paper = &*weights;
        par.map_range(points.len(), CHECK_CHUNK, round_trips, |i| {
            match paper.get(i) {
                Err(e) => Err(e.clone()),
                Ok(_) if back[i] => Ok(RoundTrip::Paper),
                Ok(_) => Ok(RoundTrip::NotReached),
            }
        })?;
        // The rest climb the penalty ladder, each point on its own.
        let pending: Vec<usize> = (0..points.len())
            .filter(|&i| round_trips[i] == Ok(RoundTrip::NotReached))
            .collect();
        let mut tried = Vec::new();
        par.map_range(pending.len(), PENALTY_CHUNK, &mut tried, |k| {
            self.ladder(&check_point(mesh, &points[pending[k]])?, tol)
        })?;
        for (&i, t) in pending.iter().zip(tried) {
            match t {
                Err(e) => {
                    weights.set(i, Err(e.clone()));
                    round_trips[i] = Err(e);
                }
                Ok(Some((w, lambda))) => {
                    weights.set(i, Ok(&w));
                    round_trips[i] = Ok(RoundTrip::Penalized(lambda));
                }
                Ok(None) => {}
            }
        }
        Ok(())
    }
}
