//! The same mesh scaled by 1e-6 and 1e6 and translated by 1e6 gives the same quality as the
//! original: self-projection, round trips and the precomputation's geodesic errors are
//! relative figures and must not depend on units or placement.

use wavg::mesh::{TriMesh, procedural};
use wavg::solve::sampling::uniform_surface_points;
use wavg::{ForwardOptions, NoProgress, PrecomputeOptions, Surface, Vector3};

/// Relative quality figures of one mesh.
#[derive(Debug)]
struct Quality {
    self_projection: f64,
    round_trip: f64,
    rel_err_p50: f64,
    rel_err_p90: f64,
}

fn quality(mesh: TriMesh, landmarks: usize) -> Quality {
    let mut s = Surface::from_mesh(mesh).unwrap();
    let opts = PrecomputeOptions {
        landmarks,
        quality_pairs: 2048,
        quality_sources: 32,
        ..Default::default()
    };
    let report = s.precompute(&opts, &NoProgress).unwrap();
    let mesh = s.mesh().clone();
    let diag = mesh.bounding_box_diagonal();
    let tol = 1e-6 * diag;

    // Every 7th vertex's embedded point, projected from a far start, lands on the vertex.
    let n = s.n_vertices();
    let coords = s.embedded_coords();
    let vs: Vec<usize> = (0..n).step_by(7).collect();
    let back = vs
        .iter()
        .filter(|&&v| {
            let start = ((v * 7919 + 13) % n) as u32;
            s.projector()
                .project(&coords[v], start)
                .is_ok_and(|p| (p.point.position(&mesh) - mesh.positions[v]).norm() <= tol)
        })
        .count();

    // Inverse then forward on random points with 27 spread anchors.
    let solver = s.solver(s.spread_anchors(27, 0).unwrap()).unwrap();
    let points = uniform_surface_points(&mesh, 1000, 5).unwrap();
    let ok = points
        .iter()
        .filter(|x| {
            let Ok(w) = solver.inverse(x) else {
                return false;
            };
            solver
                .forward(&w, &ForwardOptions::default())
                .is_ok_and(|r| (r.position - x.position(&mesh)).norm() <= 1e-4 * diag)
        })
        .count();
    Quality {
        self_projection: back as f64 / vs.len() as f64,
        round_trip: ok as f64 / points.len() as f64,
        rel_err_p50: report.geodesic_rel_err_p50,
        rel_err_p90: report.geodesic_rel_err_p90,
    }
}

fn check_invariance(name: &str, mesh: &TriMesh, landmarks: usize) {
    let base = quality(mesh.clone(), landmarks);
    eprintln!("{name} original: {base:?}");
    let shift = Vector3::new(1e6, -1e6, 1e6);
    let variants: [(&str, TriMesh); 3] = [
        ("x1e-6", mesh.clone().map_positions(|p| p * 1e-6)),
        ("x1e6", mesh.clone().map_positions(|p| p * 1e6)),
        ("+1e6", mesh.clone().map_positions(|p| p + shift)),
    ];
    for (label, m) in variants {
        let q = quality(m, landmarks);
        eprintln!("{name} {label}: {q:?}");
        assert!(
            (q.self_projection - base.self_projection).abs() <= 0.01,
            "{name} {label}: self-projection {} vs {}",
            q.self_projection,
            base.self_projection
        );
        assert!(
            (q.round_trip - base.round_trip).abs() <= 0.02,
            "{name} {label}: round trip {} vs {}",
            q.round_trip,
            base.round_trip
        );
        for (a, b, what) in [
            (q.rel_err_p50, base.rel_err_p50, "p50"),
            (q.rel_err_p90, base.rel_err_p90, "p90"),
        ] {
            assert!(
                (a - b).abs() <= 0.1 * b + 1e-3,
                "{name} {label}: geodesic relative error {what} {a} vs {b}"
            );
        }
    }
    assert!(base.self_projection > 0.99, "{name}: {base:?}");
}

#[test]
fn generated_mesh_quality_is_scale_and_translation_invariant() {
    check_invariance("bump", &procedural::bump_sphere(4, 0.3), 200);
}

#[test]
fn real_mesh_quality_is_scale_and_translation_invariant() {
    let Some(path) = wavg_testdata::require_data_file("extreme_coords", "meshes/pig.off") else {
        return;
    };
    let mesh = wavg::mesh::io::load(&path).unwrap();
    check_invariance("pig", &mesh, 300);
}
