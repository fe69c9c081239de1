//! The spline benchmark protocol (`wavg bench spline`): time per sample of a curve on the
//! surface ([`evaluate_spline`], the call of `wavg spline`), best of repeated runs, with
//! every sample checked against the closest valid projection of its average.
//!
//! ```
//! use std::sync::Arc;
//! use wavg::apps::SplineKind;
//! use wavg::{Anchor, EmbeddedMesh, Projector, Solver, ValidMesh, mesh::procedural};
//! use wavg_bench::{SplineBenchOptions, spline_bench};
//!
//! let mesh = Arc::new(ValidMesh::new(procedural::icosphere(2)).unwrap());
//! let proj = Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh))).unwrap());
//! let solver = Solver::new(proj, [0, 10, 20, 30, 40].map(Anchor::Vertex)).unwrap();
//! let kind = SplineKind::BSpline { degree: 3, closed: true };
//! let opts = SplineBenchOptions { kind, samples: 50, repeat: 2, chunk: 64, cpu_clock: None };
//! let r = spline_bench(&solver, &opts).unwrap();
//! assert_eq!((r.samples, r.controls, r.repeat), (50, 5, 2));
//! assert_eq!(r.agree_fraction, 1.0);
//! ```

use std::time::Instant;

use wavg::apps::{SplineKind, evaluate_spline, spline_weights_flat};
use wavg::{ForwardOptions, SearchMode, SolveError, Solver};

use crate::timing::{CpuClock, with_cpu};

/// Distance, in mean edge lengths, within which a curve sample agrees with the closest
/// valid projection of its average.
pub const AGREE: f64 = 1e-6;

/// Options of [`spline_bench`].
#[derive(Clone, Copy, Debug)]
pub struct SplineBenchOptions {
    /// The curve's kind (its control points are the solver's anchors).
    pub kind: SplineKind,
    /// Samples along the curve; at least 1.
    pub samples: usize,
    /// Timed runs; at least 1.
    pub repeat: usize,
    /// Samples per warm-started chain of [`evaluate_spline`] (`wavg spline`'s chunking).
    pub chunk: usize,
    /// A process CPU-time clock; when given, [`SplineBenchReport::cpu_us_per_sample`] is
    /// filled in.
    pub cpu_clock: Option<CpuClock>,
}

/// What the protocol measured; serialises to the keys of `wavg bench spline --json`, less
/// `mesh` and `load`.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SplineBenchReport {
    /// Control points (the solver's anchors).
    pub controls: usize,
    /// Samples along the curve.
    pub samples: usize,
    /// Samples that lie on the surface.
    pub ok_samples: usize,
    /// Threads of the rayon pool the curve was evaluated on.
    pub threads: usize,
    /// Timed runs.
    pub repeat: usize,
    /// Best wall time of a run divided by the samples, in microseconds.
    pub us_per_sample: f64,
    /// Median wall time of a run divided by the samples, in microseconds.
    pub us_per_sample_median: f64,
    /// Process CPU time of all runs divided by all samples, in microseconds; `None`
    /// without a clock.
    pub cpu_us_per_sample: Option<f64>,
    /// Fraction of samples within [`AGREE`] mean edge lengths of the closest valid
    /// projection of their average found on its own (or that both fail).
    pub agree_fraction: f64,
    /// Largest distance of a sample from that answer, in mean edge lengths (0 when all
    /// agree, infinite when only one of the two failed).
    pub max_disagreement: f64,
}

/// Runs the protocol on the current rayon pool: evaluates the curve `opts.repeat` times,
/// then solves every sample on its own with the certified search (no warm start) and
/// compares. Errors ([`SolveError::InvalidParameter`]) when `samples` or `repeat` is 0 or
/// the curve cannot be built on the solver's anchors (too few for the degree).
pub fn spline_bench(
    solver: &Solver,
    opts: &SplineBenchOptions,
) -> Result<SplineBenchReport, SolveError> {
    if opts.samples == 0 || opts.repeat == 0 {
        return Err(SolveError::InvalidParameter(
            "the spline benchmark needs at least one sample and one run".into(),
        ));
    }
    let ((times, curve), cpu) = with_cpu(opts.cpu_clock, || {
        let mut times = Vec::with_capacity(opts.repeat);
        let mut curve = None;
        for _ in 0..opts.repeat {
            let t = Instant::now();
            let c = evaluate_spline(solver, opts.kind, opts.samples, opts.chunk);
            times.push(t.elapsed().as_secs_f64());
            curve = Some(c);
        }
        (times, curve)
    });
    // `repeat >= 1`: there is a curve.
    let curve = curve.unwrap_or_else(|| Err(SolveError::InvalidParameter("no run".into())))?;

    // The reference: every sample on its own, the closest valid projection.
    let flat = spline_weights_flat(opts.kind, solver.n_anchors(), opts.samples)?;
    let mel = solver.mean_edge_length();
    let closest = ForwardOptions {
        mode: SearchMode::Certified,
        ..ForwardOptions::default()
    };
    let mut agree = 0usize;
    let mut worst = 0.0f64;
    for (w, got) in flat.chunks_exact(solver.n_anchors()).zip(&curve.samples) {
        match (got, solver.forward(w, &closest)) {
            (Ok(a), Ok(b)) => {
                let d = (a.position - b.position).norm() / mel;
                worst = worst.max(d);
                agree += usize::from(d <= AGREE);
            }
            (Err(_), Err(_)) => agree += 1,
            _ => worst = f64::INFINITY,
        }
    }
    let mut sorted = times;
    sorted.sort_by(f64::total_cmp);
    let n = opts.samples as f64;
    Ok(SplineBenchReport {
        controls: solver.n_anchors(),
        samples: opts.samples,
        ok_samples: curve.ok_samples(),
        threads: rayon::current_num_threads(),
        repeat: opts.repeat,
        us_per_sample: sorted[0] / n * 1e6,
        us_per_sample_median: sorted[sorted.len() / 2] / n * 1e6,
        cpu_us_per_sample: cpu.map(|c| c / (n * opts.repeat as f64) * 1e6),
        agree_fraction: agree as f64 / n,
        max_disagreement: worst,
    })
}
