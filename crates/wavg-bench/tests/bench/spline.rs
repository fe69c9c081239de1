//! The spline protocol: its report against the curve evaluated directly, the CPU clock,
//! bad input and the serialised keys.

use std::sync::Arc;

use wavg::apps::{SplineKind, evaluate_spline};
use wavg::mesh::procedural;
use wavg::{Anchor, EmbeddedMesh, Projector, SolveError, Solver, ValidMesh};
use wavg_bench::{SplineBenchOptions, spline_bench};
use wavg_testdata::json_keys::{BENCH_SPLINE, sorted};

fn solver(anchors: &[u32]) -> Solver {
    let mesh = Arc::new(ValidMesh::new(procedural::icosphere(3)).unwrap());
    let proj = Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh))).unwrap());
    Solver::new(proj, anchors.iter().map(|&v| Anchor::Vertex(v))).unwrap()
}

fn opts(samples: usize) -> SplineBenchOptions {
    SplineBenchOptions {
        kind: SplineKind::BSpline {
            degree: 3,
            closed: true,
        },
        samples,
        repeat: 3,
        chunk: 16,
        cpu_clock: None,
    }
}

/// The figures count what the curve holds, and every sample agrees with its cold answer.
#[test]
fn report_counts_the_curve() {
    let s = solver(&[0, 100, 200, 300, 400, 500]);
    let o = opts(77);
    let r = spline_bench(&s, &o).unwrap();
    let curve = evaluate_spline(&s, o.kind, o.samples, o.chunk).unwrap();
    assert_eq!(r.controls, 6);
    assert_eq!(r.samples, 77);
    assert_eq!(r.repeat, 3);
    assert_eq!(r.ok_samples, curve.ok_samples());
    assert_eq!(r.threads, rayon::current_num_threads());
    assert_eq!(r.agree_fraction, 1.0, "{r:?}");
    assert!(r.max_disagreement <= 1e-6, "{r:?}");
    assert!(r.us_per_sample > 0.0 && r.us_per_sample <= r.us_per_sample_median);
    assert_eq!(r.cpu_us_per_sample, None);
}

/// A CPU clock fills the CPU figure: a clock that advances one second per call gives one
/// second over all runs and samples.
#[test]
fn cpu_clock_fills_the_cpu_figure() {
    fn clock() -> Option<f64> {
        use std::sync::atomic::{AtomicU64, Ordering};
        static CALLS: AtomicU64 = AtomicU64::new(0);
        Some(CALLS.fetch_add(1, Ordering::Relaxed) as f64)
    }
    let s = solver(&[0, 100, 200, 300, 400]);
    let o = SplineBenchOptions {
        cpu_clock: Some(clock),
        ..opts(10)
    };
    let r = spline_bench(&s, &o).unwrap();
    assert_eq!(r.cpu_us_per_sample, Some(1.0 / 30.0 * 1e6));
}

/// No samples, no runs, or too few anchors for the degree: a typed error.
#[test]
fn bad_input_is_an_error() {
    let s = solver(&[0, 100, 200]);
    let bad = |o: SplineBenchOptions| {
        matches!(spline_bench(&s, &o), Err(SolveError::InvalidParameter(_)))
    };
    assert!(bad(opts(0)));
    assert!(bad(SplineBenchOptions {
        repeat: 0,
        ..opts(5)
    }));
    assert!(bad(SplineBenchOptions {
        kind: SplineKind::BSpline {
            degree: 0,
            closed: false
        },
        ..opts(5)
    }));
}

/// The JSON keys are those of `wavg bench spline --json` less `mesh` and `load`.
#[test]
fn serialises_to_the_documented_keys() {
    let s = solver(&[0, 100, 200, 300, 400]);
    let r = spline_bench(&s, &opts(5)).unwrap();
    let v = serde_json::to_value(&r).unwrap();
    let mut keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
    keys.sort();
    assert_eq!(keys, sorted(BENCH_SPLINE, &[]));
}
