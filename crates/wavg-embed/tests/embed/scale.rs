//! The precomputation at extreme scales: the same embedding, up to the scale, as at unit
//! size; embeddings outside the projector's range refused up front.

use wavg_embed::{NoProgress, PrecomputeOptions, precompute};
use wavg_mesh::{TriMesh, ValidMesh, procedural};

fn scaled(mesh: &TriMesh, s: f64) -> ValidMesh {
    let positions = mesh.positions.iter().map(|p| p * s).collect();
    ValidMesh::new(TriMesh::new(positions, mesh.triangles.clone())).unwrap()
}

/// A torus scaled by powers of two far below and above unit size (2^-150 is about 7e-46,
/// where the MDS eigen-solver used to loop without end): exactly the unit embedding,
/// scaled; and decimal scales give the same quality.
#[test]
fn extreme_scales_give_the_unit_embedding_scaled() {
    let torus = procedural::torus(40, 20, 1.0, 0.35);
    let opts = PrecomputeOptions {
        landmarks: 120,
        ..Default::default()
    };
    let (unit, unit_report) =
        precompute(&ValidMesh::new(torus.clone()).unwrap(), &opts, &NoProgress).unwrap();
    for k in [-150, -60, 60, 100] {
        let s = 2f64.powi(k);
        let (e, report) = precompute(&scaled(&torus, s), &opts, &NoProgress).unwrap();
        assert_eq!(e.landmarks, unit.landmarks, "2^{k}");
        for (a, b) in e.coords.iter().zip(&unit.coords) {
            for (x, y) in a.iter().zip(b) {
                assert_eq!(*x, y * s, "2^{k}");
            }
        }
        assert_eq!(
            report.geodesic_rel_err_p50,
            unit_report.geodesic_rel_err_p50
        );
    }
    for s in [1e-45, 1e-59, 1e30] {
        let (_, report) = precompute(&scaled(&torus, s), &opts, &NoProgress).unwrap();
        assert!(
            (report.geodesic_rel_err_p50 - unit_report.geodesic_rel_err_p50).abs() < 1e-3,
            "scale {s:e}: {} against {}",
            report.geodesic_rel_err_p50,
            unit_report.geodesic_rel_err_p50
        );
    }
}

/// A mesh within range whose embedding would not be (its geodesic distances exceed its
/// coordinates) is refused with the remedy, as is a mesh out of range.
#[test]
fn embeddings_beyond_the_projectors_range_are_refused() {
    let torus = procedural::torus(24, 12, 1.0, 0.35);
    let largest = torus.positions.iter().map(|p| p.amax()).fold(0.0, f64::max);
    let opts = PrecomputeOptions {
        landmarks: 60,
        ..Default::default()
    };
    for (s, remedy) in [
        (9.9e36 / largest, "scale the mesh down"),
        (1e-61, "scale the mesh up"),
    ] {
        let err = precompute(&scaled(&torus, s), &opts, &NoProgress).unwrap_err();
        assert!(err.to_string().contains(remedy), "{err}");
    }
}
