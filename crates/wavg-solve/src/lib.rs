//! Forward and inverse weighted-average problems (paper Sections 3.3-3.4).
//!
//! * Forward problem (weights -> surface point): average the anchors' embedded points in
//!   R^8, then Phong-project the average back onto the embedded mesh
//!   ([`Solver::forward`]).
//! * Inverse problem (surface point -> weights): the minimum-norm weights that make the
//!   point the Phong projection of the average, penalising far anchors
//!   ([`Solver::inverse`], linear algebra in [`inverse_weights`]).
//!
//! Also: [`AnchorSet`] (editable anchor sets), [`resolve_anchor`] and [`check_point`]
//! (validating user locations), [`validate_weights`], [`inverse_weights`] (the inverse
//! problem's kernel on its own), [`sampling`] (seeded anchors and query points) and
//! [`spread`] (anchor sets judged by their largest gap, and a closed tour through points).
//! The benchmark protocols that measure all this live outside the library, in `wavg-bench`.
//!
//! ```
//! use std::sync::Arc;
//! use wavg_mesh::{SurfacePoint, ValidMesh, procedural};
//! use wavg_solve::{Anchor, EmbeddedMesh, ForwardOptions, Projector, Solver};
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

#![deny(unreachable_pub)]
#![forbid(unsafe_code)]

mod aim;
mod anchors;
mod batch;
mod error;
mod kernel;
mod penalty;
mod points;
pub mod sampling;
mod simd;
mod solver;
pub mod spread;
mod verified;
mod weights;

// The solver and its problems.
pub use aim::CurveAim;
pub use batch::{BatchWeights, ForwardScratch};
pub use solver::{ForwardOptions, ForwardResult, SearchMode, Solver, Start};
pub use verified::{DEFAULT_TOLERANCE, PENALTY_LADDER, RoundTrip, Verified};

// Anchors, points and weights.
pub use anchors::AnchorSet;
pub use kernel::{AnchorCoords, DEFAULT_GAMMA, InverseScratch, inverse_weights};
pub use points::{
    Anchor, BARY_TOLERANCE, check_barycentrics, check_point, nearest_corner, resolve_anchor,
    vertex_point,
};
pub use weights::{Normalization, WEIGHT_SUM_TOLERANCE, validate_weights};

// The embedded mesh and projector the solver works on.
pub use wavg_project::{
    DIM, EmbeddedMesh, Mat2x8, Par, ProjectError, ProjectionPath, Projector, SearchGoal, Vec8,
};

// Errors.
pub use error::SolveError;

/// The verified inverse's penalised weights, for this workspace's tests, experiments and
/// C ABI.
///
/// **Unstable**: not part of the public API; anything here may change or disappear in any
/// release.
#[doc(hidden)]
pub mod internal {
    pub use crate::penalty::penalized_weights;
}
