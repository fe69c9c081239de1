//! Shared set-up of the solver tests.

use std::sync::Arc;

use wavg_mesh::{TriMesh, ValidMesh};
use wavg_solve::sampling::{FpsMetric, farthest_point_vertices};
use wavg_solve::{Anchor, EmbeddedMesh, Projector, Solver};

/// A solver on `mesh` (its 3-D positions as the embedding) with `k` farthest-point anchors.
pub fn solver_on(mesh: TriMesh, k: usize, seed: u64) -> Solver {
    let mesh = Arc::new(ValidMesh::new(mesh).unwrap());
    let proj =
        Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh.clone()))).unwrap());
    let a = farthest_point_vertices(&mesh, k, seed, FpsMetric::EdgeGraph).unwrap();
    Solver::new(proj, a.into_iter().map(Anchor::Vertex)).unwrap()
}
