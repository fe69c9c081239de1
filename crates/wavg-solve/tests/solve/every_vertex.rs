//! Weights exist at every vertex of a valid mesh, also where the embedding folds a thin
//! extremity so that a triangle's interpolated tangent plane `Psi` loses rank at a corner.

use std::sync::Arc;

use rand::SeedableRng;
use rand::seq::index::sample;
use wavg_mesh::ValidMesh;
use wavg_solve::{Anchor, EmbeddedMesh, Projector, Solver, Vec8};

#[test]
fn armadillo_has_weights_at_every_vertex() {
    let Some(path) = wavg_testdata::require_data_file(
        "armadillo_has_weights_at_every_vertex",
        "meshes/armadillo.obj.gz",
    ) else {
        return;
    };
    let mesh = Arc::new(ValidMesh::new(wavg_mesh::io::load(&path).unwrap()).unwrap());
    let (e, _) = wavg_embed::precompute(
        &mesh,
        // Without the landmarks around thin parts: the armadillo's folded extremities are
        // the case under test.
        &wavg_embed::PrecomputeOptions {
            quality_pairs: 0,
            cover_thin_parts: false,
            ..Default::default()
        },
        &wavg_embed::NoProgress,
    )
    .unwrap();
    let coords = e.coords.iter().map(|c| Vec8::from(*c)).collect();
    let proj = Arc::new(
        Projector::new(Arc::new(EmbeddedMesh::new(mesh.clone(), coords).unwrap())).unwrap(),
    );
    let n = mesh.n_vertices();
    let points: Vec<_> = (0..n as u32)
        .map(|v| wavg_solve::vertex_point(&mesh, v).unwrap())
        .collect();

    // Corners where the interpolated plane is (nearly) rank one: the case under test.
    let folded = points
        .iter()
        .filter(|p| {
            let psi = proj.psi(p);
            let (g00, g11) = (psi.row(0).norm_squared(), psi.row(1).norm_squared());
            let g01 = psi.row(0).dot(&psi.row(1));
            g00 * g11 - g01 * g01 <= 1e-4 * g00.max(g11).powi(2)
        })
        .count();
    eprintln!("armadillo: {folded} of {n} vertex points with a rank-deficient Psi");
    assert!(
        folded > 0,
        "no folded corner: the test no longer covers the fallback"
    );

    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let anchors = sample(&mut rng, n, 60)
        .into_iter()
        .map(|v| Anchor::Vertex(v as u32));
    let solver = Solver::new(proj, anchors).unwrap();
    let batch = solver.inverse_batch(&points);
    let failed: Vec<usize> = (0..n).filter(|&i| batch.get(i).is_err()).collect();
    assert!(failed.is_empty(), "no weights at vertices {failed:?}");
    for i in (0..n).step_by(97) {
        let w = batch.get(i).unwrap();
        assert!(w.iter().all(|x| x.is_finite()));
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-9);
    }
}
