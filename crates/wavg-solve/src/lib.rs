//! Forward and inverse weighted-average problems (paper Sections 3.3-3.4).
//!
//! * Forward problem (weights -> surface point): average the anchors' embedded points in
//!   R^8, then Phong-project the average back onto the embedded mesh
//!   ([`Solver::forward`]).
//! * Inverse problem (surface point -> weights): the minimum-norm weights that make the
//!   point the Phong projection of the average, penalising far anchors
//!   ([`Solver::inverse`], linear algebra in [`kernel`]).
//!
//! Modules: [`anchors`] (editable anchor sets), [`points`] (validating user locations),
//! [`weights`] (validating weights), [`solver`] (single and batched problems),
//! [`search`] (the paper's local search for the forward problem), [`sampling`] (seeded
//! anchors and query points for benchmarks and tests).
//!
//! ```
//! use std::sync::Arc;
//! use wavg_mesh::{SurfacePoint, ValidMesh, procedural};
//! use wavg_solve::{EmbeddedMesh, ForwardOptions, Projector, Solver, points::Anchor};
//!
//! let mesh = Arc::new(ValidMesh::new(procedural::icosphere(3)).unwrap());
//! let proj = Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh))).unwrap());
//! let anchors = wavg_solve::sampling::farthest_point_vertices(
//!     proj.embedded().mesh(), 12, 0, wavg_solve::sampling::FpsMetric::EdgeGraph).unwrap();
//! let solver = Solver::new(proj, anchors.iter().map(|&v| Anchor::Vertex(v))).unwrap();
//! // One-hot weights give back the anchor.
//! let mut w = vec![0.0; 12];
//! w[3] = 1.0;
//! let p = solver.forward(&w, &ForwardOptions::default()).unwrap();
//! assert!((p.position - solver.mesh().positions[anchors[3] as usize]).norm() < 1e-9);
//! ```

pub mod anchors;
pub mod error;
pub mod kernel;
pub mod points;
pub mod sampling;
pub mod search;
pub mod solver;
pub mod verified;
pub mod weights;

pub use anchors::AnchorSet;
pub use error::SolveError;
pub use points::Anchor;
pub use solver::{BatchWeights, ForwardOptions, ForwardResult, SearchMode, Solver, Start};
pub use verified::{RoundTrip, Verified};
pub use wavg_project::{DIM, EmbeddedMesh, Mat2x8, ProjectError, ProjectionPath, Projector, Vec8};
pub use weights::Normalization;
