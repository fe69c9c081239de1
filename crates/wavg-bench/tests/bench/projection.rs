//! The projection protocol: its accuracy figures, reproducibility from the seed, bad input
//! and the serialised keys.

use std::sync::Arc;

use wavg::mesh::procedural;
use wavg::{EmbeddedMesh, SolveError, ValidMesh};
use wavg_bench::projection::BRUTE_FORCE_CHECKS;
use wavg_bench::{ProjectionBenchOptions, ProjectionBenchReport, projection_bench};
use wavg_testdata::json_keys::{BENCH_PROJECT, sorted};

fn torus() -> Arc<EmbeddedMesh> {
    let mesh = Arc::new(ValidMesh::new(procedural::torus(40, 14, 1.0, 0.35)).unwrap());
    Arc::new(EmbeddedMesh::from_positions(mesh))
}

fn run(queries: usize, seed: u64, normal: bool) -> ProjectionBenchReport {
    let opts = ProjectionBenchOptions {
        queries,
        seed,
        offset_along_normal: normal,
        ..Default::default()
    };
    projection_bench(torus(), &opts).unwrap()
}

/// On a torus with its positions as embedding the points on the surface come back to
/// themselves and the offset answers equal the brute force's.
#[test]
fn figures_on_a_torus() {
    for normal in [true, false] {
        let r = run(400, 3, normal);
        assert!(r.batch_agrees, "{r:?}");
        assert!(r.onsurface_self_fraction >= 0.99, "{r:?}");
        assert!(r.offset_bruteforce_agree_fraction >= 0.99, "{r:?}");
        assert_eq!(r.bruteforce_checked, 400.min(BRUTE_FORCE_CHECKS));
        assert_eq!(r.onsurface_paths.iter().sum::<usize>(), 400);
        assert_eq!(r.offset_paths.iter().sum::<usize>(), 400);
        assert_eq!((r.vertices, r.faces, r.queries), (560, 1120, 400));
        assert!(r.bytes_per_face > 0.0 && r.init_s >= 0.0);
        // No clock: the CPU figures are wall time.
        assert_eq!(r.onsurface_us, r.onsurface_wall_us);
        assert_eq!(r.fallback_queries == 0, r.fallback_us.is_none());
    }
}

/// Everything but the times depends on the seed alone.
#[test]
fn reproducible_from_the_seed() {
    let strip = |r: ProjectionBenchReport| {
        (
            r.onsurface_self_fraction,
            r.onsurface_paths,
            r.offset_paths,
            r.offset_bruteforce_agree_fraction,
            r.onsurface_fallback_fraction,
            r.offset_fallback_fraction,
            r.fallback_queries,
        )
    };
    assert_eq!(strip(run(300, 9, false)), strip(run(300, 9, false)));
}

/// No queries: a typed error.
#[test]
fn zero_queries_is_an_error() {
    let opts = ProjectionBenchOptions {
        queries: 0,
        ..Default::default()
    };
    assert!(matches!(
        projection_bench(torus(), &opts),
        Err(SolveError::InvalidParameter(_))
    ));
}

/// The JSON keys are those of `wavg bench project --json` less `mesh`.
#[test]
fn serialises_to_the_documented_keys() {
    let v = serde_json::to_value(run(50, 1, true)).unwrap();
    let mut keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
    keys.sort();
    assert_eq!(keys, sorted(BENCH_PROJECT, &[]));
}
