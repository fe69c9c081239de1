//! The paper's Table 1 round-trip protocol: random surface points, their weights by the
//! inverse problem, back to points by the forward problem, compared with the originals.
//!
//! For each query point the inverse problem gives weights, and the forward problem with
//! those weights and no initial guess gives a point; the round trip is ok when that point is
//! within [`ROUND_TRIP_TOLERANCE`] mean edge lengths of the original. Times are wall time of
//! a whole batch on the current rayon pool divided by the number of queries (amortised over
//! the threads, as in the paper), best of [`RoundTripOptions::repeat`] runs. The same
//! forward problems are also run in spatial (Morton) order, each warm-started from the
//! previous answer. Optionally the verified inverse ([`Solver::inverse_verified`]) runs
//! through the same protocol. The verified inverse's own round-trip check is algorithm and
//! stays in the library; this is its measurement.
//!
//! ```
//! use std::sync::Arc;
//! use wavg::{Anchor, EmbeddedMesh, Projector, Solver, ValidMesh, mesh::procedural};
//! use wavg_bench::{RoundTripOptions, round_trip};
//!
//! let mesh = Arc::new(ValidMesh::new(procedural::icosphere(2)).unwrap());
//! let proj = Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh))).unwrap());
//! let anchors = wavg::sampling::farthest_point_vertices(
//!     proj.embedded().mesh(), 12, 0, wavg::sampling::FpsMetric::EdgeGraph).unwrap();
//! let solver = Solver::new(proj, anchors.into_iter().map(Anchor::Vertex)).unwrap();
//! let opts = RoundTripOptions { queries: 50, repeat: 1, ..Default::default() };
//! let report = round_trip(&solver, &opts).unwrap();
//! assert_eq!(report.queries, 50);
//! assert!(report.roundtrip_ok_fraction > 0.9);
//! ```

use wavg::mesh::geometry::mean_edge_length;
use wavg::sampling::{spatial_order, uniform_surface_points};
use wavg::solve::check_point;
use wavg::{
    BatchWeights, ForwardOptions, ForwardResult, Par, ProjectionPath, RoundTrip, SearchMode,
    SolveError, Solver, SurfacePoint,
};

use crate::timing::{CpuClock, best_of, with_cpu};

/// A forward result within this many mean edge lengths of the original point counts as a
/// successful round trip (the paper's Table 1 threshold).
pub const ROUND_TRIP_TOLERANCE: f64 = 1e-3;
/// A query "has negative weights" when some weight is below this.
pub const NEGATIVE_WEIGHT: f64 = -0.1;
/// Queries per warm-started chain (fixed, so results do not depend on the thread count).
pub const WARM_CHUNK: usize = 1024;

/// Options of [`round_trip`].
#[derive(Clone, Copy, Debug)]
pub struct RoundTripOptions {
    /// Number of random query points (uniform by area); at least 1.
    pub queries: usize,
    /// Seed of the query points.
    pub seed: u64,
    /// Timed runs of each batch; the best is reported (0 counts as 1).
    pub repeat: usize,
    /// Search of the forward problem.
    pub search: SearchMode,
    /// Also run the verified inverse through the protocol.
    pub verified: bool,
    /// A process CPU-time clock in seconds (the standard library has none); when given, the
    /// report's CPU figures are filled in.
    pub cpu_clock: Option<CpuClock>,
}

impl Default for RoundTripOptions {
    fn default() -> Self {
        Self {
            queries: 100_000,
            seed: 0,
            repeat: 3,
            search: SearchMode::Fast,
            verified: false,
            cpu_clock: None,
        }
    }
}

/// What the protocol measured. It serialises to the keys of `wavg bench roundtrip --json`
/// (the field names); the fields marked "not serialised" are
/// the extra figures of its text output.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct RoundTripReport {
    /// Inverse problem: wall microseconds per query (batch time / queries, best run).
    pub inverse_us: f64,
    /// Forward problem without initial guess: wall microseconds per query.
    pub forward_us: f64,
    /// Forward problem in spatial order, warm-started: wall microseconds per query.
    pub forward_warm_us: f64,
    /// Inverse problem: CPU microseconds per query, mean over the runs, summed over
    /// threads; `None` without a CPU clock. Not serialised.
    #[serde(skip)]
    pub inverse_cpu_us: Option<f64>,
    /// Forward problem: CPU microseconds per query, as `inverse_cpu_us`. Not serialised.
    #[serde(skip)]
    pub forward_cpu_us: Option<f64>,
    /// Warm-started forward problem: CPU microseconds per query. Not serialised.
    #[serde(skip)]
    pub forward_warm_cpu_us: Option<f64>,
    /// Fraction of queries whose round trip is ok (a failed inverse or forward is not).
    pub roundtrip_ok_fraction: f64,
    /// The same fraction for the warm-started forward problems. Not serialised.
    #[serde(skip)]
    pub roundtrip_warm_ok_fraction: f64,
    /// Median round-trip distance in mean edge lengths (infinite when more than half
    /// failed; `null` in JSON).
    pub roundtrip_err_p50: f64,
    /// 99th percentile of the round-trip distance (nearest rank), as the median.
    pub roundtrip_err_p99: f64,
    /// Fraction of queries whose weights have some weight below [`NEGATIVE_WEIGHT`].
    pub negative_weight_fraction: f64,
    /// Forward answers found by the local search (certified or not). Not serialised.
    #[serde(skip)]
    pub forward_local: usize,
    /// Forward answers found by the certified fallback. Not serialised.
    #[serde(skip)]
    pub forward_fallback: usize,
    /// Forward problems without an answer, including those of failed inverses. Not
    /// serialised.
    #[serde(skip)]
    pub forward_failed: usize,
    /// Inverse problems without an answer. Not serialised.
    #[serde(skip)]
    pub inverse_failed: usize,
    /// Vertices of the mesh.
    pub vertices: usize,
    /// Faces of the mesh.
    pub faces: usize,
    /// Number of anchors.
    pub anchors: usize,
    /// Number of query points.
    pub queries: usize,
    /// Threads of the rayon pool the batches ran on.
    pub threads: usize,
    /// Timed runs of each batch. Not serialised.
    #[serde(skip)]
    pub repeat: usize,
    /// The verified inverse's figures, when requested.
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub verified: Option<VerifiedRoundTripReport>,
}

/// The verified inverse through the protocol (its weights, then the same forward problem).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct VerifiedRoundTripReport {
    /// Verified inverse: wall microseconds per query, its forward checks included.
    pub verified_inverse_us: f64,
    /// Fraction of ok round trips with the verified weights.
    pub verified_roundtrip_ok_fraction: f64,
    /// Fraction of verified weight vectors with some weight below [`NEGATIVE_WEIGHT`].
    pub verified_negative_weight_fraction: f64,
    /// Fraction of queries that needed an offset penalty.
    pub verified_penalized_fraction: f64,
    /// Fraction of queries no rung of the penalty ladder brought back.
    pub verified_not_reached_fraction: f64,
}

/// Runs the protocol on `opts.queries` points uniform by area (seed `opts.seed`): see
/// [`round_trip_at`].
pub fn round_trip(solver: &Solver, opts: &RoundTripOptions) -> Result<RoundTripReport, SolveError> {
    if opts.queries == 0 {
        return Err(SolveError::InvalidParameter(
            "the round trip needs at least one query".into(),
        ));
    }
    let points = uniform_surface_points(solver.mesh(), opts.queries, opts.seed)?;
    round_trip_at(solver, &points, opts)
}

/// Runs the protocol on the given points (`opts.queries` and `opts.seed` unused), on the
/// current rayon pool. Errors when `points` is empty or a point is not on the mesh.
pub fn round_trip_at(
    solver: &Solver,
    points: &[SurfacePoint],
    opts: &RoundTripOptions,
) -> Result<RoundTripReport, SolveError> {
    if points.is_empty() {
        return Err(SolveError::InvalidParameter(
            "the round trip needs at least one query".into(),
        ));
    }
    for p in points {
        check_point(solver.mesh(), p)?;
    }
    let mesh = solver.mesh();
    let n = points.len();
    let repeat = opts.repeat.max(1);
    let fwd_opts = ForwardOptions {
        mode: opts.search,
        ..Default::default()
    };
    let per_query = |t: f64| t / n as f64 * 1e6;
    let cpu_per_query = |c: Option<f64>| c.map(|c| c / (n * repeat) as f64 * 1e6);

    // The result buffers are reused across the repeats, as an application would.
    let mut weights = BatchWeights::default();
    let ((t_inv, ()), cpu_inv) = with_cpu(opts.cpu_clock, || {
        best_of(repeat, || {
            // `Par::Rayon` always starts.
            let _ = solver.inverse_batch_into(points, &mut weights, Par::Rayon);
        })
    });
    // Failed inverses get a placeholder that fails validation, so forward reports it.
    let rows: Vec<&[f64]> = weights.iter().map(|r| r.unwrap_or(&[])).collect();
    let ((t_fwd, fwd), cpu_fwd) = with_cpu(opts.cpu_clock, || {
        best_of(repeat, || solver.forward_batch(&rows, &fwd_opts))
    });
    let order = spatial_order(&points.iter().map(|p| p.position(mesh)).collect::<Vec<_>>());
    let ordered: Vec<&[f64]> = order.iter().map(|&i| rows[i]).collect();
    let ((t_warm, warm), cpu_warm) = with_cpu(opts.cpu_clock, || {
        best_of(repeat, || {
            solver.forward_batch_warm(&ordered, &fwd_opts, WARM_CHUNK)
        })
    });

    let mel = mean_edge_length(mesh);
    let err = |p: &SurfacePoint, r: &Result<ForwardResult, SolveError>| match r {
        Ok(r) => (r.position - p.position(mesh)).norm() / mel,
        Err(_) => f64::INFINITY,
    };
    let mut errs: Vec<f64> = points.iter().zip(&fwd).map(|(p, r)| err(p, r)).collect();
    errs.sort_by(f64::total_cmp);
    let ok = errs.iter().filter(|&&e| e < ROUND_TRIP_TOLERANCE).count();
    let warm_ok = order
        .iter()
        .zip(&warm)
        .filter(|(i, r)| err(&points[**i], r) < ROUND_TRIP_TOLERANCE)
        .count();
    let negative = weights
        .iter()
        .filter(|r| r.is_ok_and(|w| w.iter().any(|&x| x < NEGATIVE_WEIGHT)))
        .count();
    let path_count = |p: &[ProjectionPath]| {
        fwd.iter()
            .filter(|r| r.as_ref().is_ok_and(|r| p.contains(&r.path)))
            .count()
    };
    let verified = if opts.verified {
        Some(verified_round_trip(solver, points, repeat, &fwd_opts, mel))
    } else {
        None
    };
    Ok(RoundTripReport {
        inverse_us: per_query(t_inv),
        forward_us: per_query(t_fwd),
        forward_warm_us: per_query(t_warm),
        inverse_cpu_us: cpu_per_query(cpu_inv),
        forward_cpu_us: cpu_per_query(cpu_fwd),
        forward_warm_cpu_us: cpu_per_query(cpu_warm),
        roundtrip_ok_fraction: ok as f64 / n as f64,
        roundtrip_warm_ok_fraction: warm_ok as f64 / n as f64,
        roundtrip_err_p50: quantile(&errs, 0.5),
        roundtrip_err_p99: quantile(&errs, 0.99),
        negative_weight_fraction: negative as f64 / n as f64,
        forward_local: path_count(&[ProjectionPath::Local, ProjectionPath::Certified]),
        forward_fallback: path_count(&[ProjectionPath::Fallback]),
        forward_failed: fwd.iter().filter(|r| r.is_err()).count(),
        inverse_failed: weights.iter().filter(|r| r.is_err()).count(),
        vertices: mesh.n_vertices(),
        faces: mesh.n_faces(),
        anchors: solver.n_anchors(),
        queries: n,
        threads: rayon::current_num_threads(),
        repeat,
        verified,
    })
}

/// The verified inverse (timed, buffers reused), then the forward problem on its weights.
fn verified_round_trip(
    solver: &Solver,
    points: &[SurfacePoint],
    repeat: usize,
    opts: &ForwardOptions,
    mel: f64,
) -> VerifiedRoundTripReport {
    let n = points.len() as f64;
    let mut weights = BatchWeights::default();
    let mut trips = Vec::new();
    let (t, ()) = best_of(repeat, || {
        // `Par::Rayon` always starts.
        let _ = solver.inverse_verified_batch_into(
            points,
            ROUND_TRIP_TOLERANCE,
            &mut weights,
            &mut trips,
            Par::Rayon,
        );
    });
    let rows: Vec<&[f64]> = weights.iter().map(|r| r.unwrap_or(&[])).collect();
    let fwd = solver.forward_batch(&rows, opts);
    let mesh = solver.mesh();
    let ok = points
        .iter()
        .zip(&fwd)
        .filter(|(p, r)| {
            r.as_ref()
                .is_ok_and(|r| (r.position - p.position(mesh)).norm() / mel < ROUND_TRIP_TOLERANCE)
        })
        .count();
    let fraction = |f: &dyn Fn(&[f64], RoundTrip) -> bool| {
        rows.iter()
            .zip(&trips)
            .filter(|(w, t)| t.as_ref().is_ok_and(|t| f(w, *t)))
            .count() as f64
            / n
    };
    VerifiedRoundTripReport {
        verified_inverse_us: t / n * 1e6,
        verified_roundtrip_ok_fraction: ok as f64 / n,
        verified_negative_weight_fraction: fraction(&|w, _| w.iter().any(|&x| x < NEGATIVE_WEIGHT)),
        verified_penalized_fraction: fraction(&|_, t| matches!(t, RoundTrip::Penalized(_))),
        verified_not_reached_fraction: fraction(&|_, t| t == RoundTrip::NotReached),
    }
}

/// Value at quantile `q` of sorted, non-empty `xs` (nearest rank).
fn quantile(xs: &[f64], q: f64) -> f64 {
    let i = ((q * xs.len() as f64).ceil() as usize).clamp(1, xs.len()) - 1;
    xs[i]
}
