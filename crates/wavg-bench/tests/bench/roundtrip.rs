//! The Table 1 round-trip protocol: its report against the definitions, recomputed one
//! query at a time, and its invariants.

use std::sync::Arc;

use proptest::prelude::*;
use wavg::mesh::geometry::mean_edge_length;
use wavg::mesh::procedural;
use wavg::sampling::{FpsMetric, farthest_point_vertices, uniform_surface_points};
use wavg::solve::vertex_point;
use wavg::{
    Anchor, EmbeddedMesh, ForwardOptions, Projector, SolveError, Solver, SurfacePoint, TriMesh,
    ValidMesh,
};
use wavg_bench::roundtrip::{NEGATIVE_WEIGHT, ROUND_TRIP_TOLERANCE};
use wavg_bench::{RoundTripOptions, RoundTripReport, round_trip, round_trip_at};
use wavg_testdata::json_keys::{BENCH_ROUNDTRIP, BENCH_ROUNDTRIP_VERIFIED, sorted};

fn solver_on(mesh: TriMesh, k: usize) -> Solver {
    let mesh = Arc::new(ValidMesh::new(mesh).unwrap());
    let proj =
        Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh.clone()))).unwrap());
    let a = farthest_point_vertices(&mesh, k, 0, FpsMetric::EdgeGraph).unwrap();
    Solver::new(proj, a.into_iter().map(Anchor::Vertex)).unwrap()
}

fn opts(verified: bool) -> RoundTripOptions {
    RoundTripOptions {
        queries: 200,
        seed: 5,
        repeat: 1,
        verified,
        ..Default::default()
    }
}

/// The report's invariants whatever the mesh and points.
fn check_invariants(r: &RoundTripReport, solver: &Solver, n: usize) {
    let fractions = [
        r.roundtrip_ok_fraction,
        r.roundtrip_warm_ok_fraction,
        r.negative_weight_fraction,
    ];
    for f in fractions {
        assert!((0.0..=1.0).contains(&f), "{f} in {r:?}");
    }
    assert_eq!(r.queries, n);
    assert_eq!(r.vertices, solver.mesh().n_vertices());
    assert_eq!(r.faces, solver.mesh().n_faces());
    assert_eq!(r.anchors, solver.n_anchors());
    assert_eq!(r.repeat, 1);
    assert_eq!(r.threads, rayon::current_num_threads());
    // Every forward problem has one answer or fails; a failed inverse fails forward.
    assert_eq!(r.forward_local + r.forward_fallback + r.forward_failed, n);
    assert!(r.inverse_failed <= r.forward_failed);
    // An ok round trip needs a forward answer.
    let ok = (r.roundtrip_ok_fraction * n as f64).round() as usize;
    assert!(ok <= n - r.forward_failed);
    assert!(r.roundtrip_err_p50 >= 0.0 && r.roundtrip_err_p50 <= r.roundtrip_err_p99);
    for t in [r.inverse_us, r.forward_us, r.forward_warm_us] {
        assert!(t.is_finite() && t >= 0.0);
    }
    // No clock given: no CPU figures.
    assert_eq!(r.inverse_cpu_us, None);
    if let Some(v) = &r.verified {
        let fractions = [
            v.verified_roundtrip_ok_fraction,
            v.verified_negative_weight_fraction,
            v.verified_penalized_fraction,
            v.verified_not_reached_fraction,
        ];
        for f in fractions {
            assert!((0.0..=1.0).contains(&f), "{f} in {v:?}");
        }
        // The verified inverse never does worse than the paper's weights.
        assert!(v.verified_roundtrip_ok_fraction >= r.roundtrip_ok_fraction);
        assert!(v.verified_inverse_us.is_finite() && v.verified_inverse_us >= 0.0);
    }
}

/// Every vertex of the mesh as a query point comes back to itself.
#[test]
fn vertices_round_trip_to_themselves() {
    let solver = solver_on(procedural::icosphere(2), 12);
    let mesh = solver.mesh();
    let points: Vec<SurfacePoint> = (0..mesh.n_vertices() as u32)
        .map(|v| vertex_point(mesh, v).unwrap())
        .collect();
    let r = round_trip_at(&solver, &points, &opts(true)).unwrap();
    check_invariants(&r, &solver, points.len());
    assert_eq!(r.roundtrip_ok_fraction, 1.0, "{r:?}");
    assert_eq!(r.roundtrip_warm_ok_fraction, 1.0, "{r:?}");
    assert!(r.roundtrip_err_p99 < ROUND_TRIP_TOLERANCE, "{r:?}");
    assert_eq!((r.inverse_failed, r.forward_failed), (0, 0));
    let v = r.verified.unwrap();
    assert_eq!(v.verified_roundtrip_ok_fraction, 1.0);
    assert_eq!(v.verified_not_reached_fraction, 0.0);
    // The paper's weights already return every vertex: no penalty needed.
    assert_eq!(v.verified_penalized_fraction, 0.0);
}

/// The batch figures equal the definitions evaluated one query at a time.
#[test]
fn figures_match_single_queries() {
    let solver = solver_on(procedural::torus(32, 12, 1.0, 0.35), 10);
    let mesh = solver.mesh();
    let o = opts(false);
    let r = round_trip(&solver, &o).unwrap();
    check_invariants(&r, &solver, o.queries);
    let points = uniform_surface_points(mesh, o.queries, o.seed).unwrap();
    let mel = mean_edge_length(mesh);
    let mut errs = Vec::new();
    let mut negative = 0;
    for p in &points {
        let e = match solver.inverse(p) {
            Ok(w) => {
                negative += usize::from(w.iter().any(|&x| x < NEGATIVE_WEIGHT));
                match solver.forward(&w, &ForwardOptions::default()) {
                    Ok(f) => (f.position - p.position(mesh)).norm() / mel,
                    Err(_) => f64::INFINITY,
                }
            }
            Err(_) => f64::INFINITY,
        };
        errs.push(e);
    }
    let n = points.len() as f64;
    let ok = errs.iter().filter(|&&e| e < ROUND_TRIP_TOLERANCE).count();
    assert_eq!(r.roundtrip_ok_fraction, ok as f64 / n);
    assert_eq!(r.negative_weight_fraction, negative as f64 / n);
    errs.sort_by(f64::total_cmp);
    // Nearest rank: the 100th and 198th of 200.
    assert_eq!(r.roundtrip_err_p50, errs[99]);
    assert_eq!(r.roundtrip_err_p99, errs[197]);
    // The paper's weights miss some points on a torus with its 3-D positions as embedding.
    assert!(r.roundtrip_ok_fraction > 0.7, "{r:?}");
}

/// A CPU clock fills the CPU figures.
#[test]
fn cpu_clock_fills_cpu_figures() {
    fn clock() -> Option<f64> {
        Some(0.0)
    }
    let solver = solver_on(procedural::icosphere(1), 6);
    let o = RoundTripOptions {
        cpu_clock: Some(clock),
        ..opts(false)
    };
    let r = round_trip(&solver, &o).unwrap();
    assert_eq!(r.inverse_cpu_us, Some(0.0));
    assert_eq!(r.forward_cpu_us, Some(0.0));
    assert_eq!(r.forward_warm_cpu_us, Some(0.0));
}

/// No queries, or a point off the mesh: a typed error.
#[test]
fn bad_input_is_an_error() {
    let solver = solver_on(procedural::icosphere(1), 6);
    let o = RoundTripOptions {
        queries: 0,
        ..opts(false)
    };
    assert!(matches!(
        round_trip(&solver, &o),
        Err(SolveError::InvalidParameter(_))
    ));
    assert!(round_trip_at(&solver, &[], &opts(false)).is_err());
    let off = SurfacePoint::new(1_000_000, [1.0, 0.0, 0.0]);
    assert!(matches!(
        round_trip_at(&solver, &[off], &opts(false)),
        Err(SolveError::FaceOutOfRange { .. })
    ));
}

/// The JSON keys are those of `wavg bench roundtrip --json` (less the mesh argument).
#[test]
fn serialises_to_the_documented_keys() {
    let solver = solver_on(procedural::icosphere(2), 12);
    let keys = |verified| {
        let r = round_trip(&solver, &opts(verified)).unwrap();
        let v = serde_json::to_value(&r).unwrap();
        let mut k: Vec<String> = v.as_object().unwrap().keys().cloned().collect();
        k.sort();
        k
    };
    assert_eq!(keys(false), sorted(BENCH_ROUNDTRIP, &[]));
    assert_eq!(
        keys(true),
        sorted(BENCH_ROUNDTRIP, BENCH_ROUNDTRIP_VERIFIED)
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]

    /// Any seed and query count on a coarse torus: the invariants hold.
    #[test]
    fn invariants_hold(seed in 0u64..1000, queries in 1usize..60, verified: bool) {
        let solver = solver_on(procedural::torus(16, 8, 1.0, 0.4), 8);
        let o = RoundTripOptions { queries, seed, repeat: 1, verified, ..Default::default() };
        let r = round_trip(&solver, &o).unwrap();
        check_invariants(&r, &solver, queries);
        prop_assert_eq!(r.verified.is_some(), verified);
    }
}
