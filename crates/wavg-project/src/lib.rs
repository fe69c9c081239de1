//! Phong projection onto meshes embedded in R^8 (paper Sections 3.2-3.3).
//!
//! The pipeline: an [`EmbeddedMesh`] (a valid mesh with per-vertex coordinates in R^8),
//! per-vertex tangent frames ([`vertex_frames`]), per-triangle interpolated tangent planes
//! `Psi` ([`Projector::psi`]), and a [`Projector`] that finds the closest valid Phong projection of a
//! point of R^8 onto the mesh: a fast local search that is certified against a bounding
//! volume hierarchy (or, for the paper's forward problem, returns its first valid hit:
//! [`SearchGoal`]), an exhaustive (branch and bound) search, a literal brute force, and
//! the Euclidean closest point as a baseline.
//!
//! ```
//! use std::sync::Arc;
//! use wavg_mesh::{SurfacePoint, ValidMesh, procedural};
//! use wavg_project::{EmbeddedMesh, Projector};
//!
//! let mesh = Arc::new(ValidMesh::new(procedural::icosphere(2)).unwrap());
//! let emb = Arc::new(EmbeddedMesh::from_positions(mesh));
//! let proj = Projector::new(emb.clone()).unwrap();
//! let p = SurfacePoint::new(7, [0.2, 0.3, 0.5]);
//! let y = emb.point(&p);
//! let hit = proj.project(&y, 0).unwrap();
//! assert!((emb.point(&hit.point) - y).norm() < 1e-6);
//! ```

// `!(x > tol)` is used on purpose throughout: it is also true for NaN, which must take the
// degenerate branch.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// The small fixed-size kernels index several arrays in step; explicit indices read better.
#![allow(clippy::needless_range_loop)]
#![deny(unreachable_pub)]
#![deny(unsafe_code)]

// The only module allowed `unsafe` (prefetch hints, SSE2, huge-page advice).
#[allow(unsafe_code)]
mod arch;
mod bvh;
mod embedded;
mod error;
mod euclid;
mod frames;
mod hugepage;
mod ort;
mod par;
mod projector;
mod triangle;

// The embedded mesh and its projector.
pub use embedded::EmbeddedMesh;
pub use projector::{
    FACE_WALK, HINT_STEPS, LOCAL_BUDGET, ProjectScratch, Projection, ProjectionPath, Projector,
    SearchGoal,
};

// How batches run.
pub use par::Par;

// Tangent frames and geometry in R^8.
pub use euclid::closest_point_barycentric;
pub use frames::{FrameKind, vertex_frame, vertex_frames};
pub use triangle::BARY_EPS;

// Errors.
pub use error::ProjectError;

/// Batching hooks of the projector for this workspace's solvers and C ABI.
///
/// **Unstable**: not part of the public API; anything here may change or disappear in any
/// release.
#[doc(hidden)]
pub mod internal {
    use wavg_mesh::{FaceId, VertexId};

    use crate::{Projector, Vec8};

    pub use crate::projector::{FaceOrder, WALK_GROUP, ZERO_DISTANCE};

    /// Starts loading what [`Projector::psi_and_point`] reads of face `f`: its record
    /// (`corners == false`) or its corners' records (`corners == true`). For software
    /// pipelining over batches; no effect on results.
    #[inline]
    pub fn prefetch_point_data(proj: &Projector, f: FaceId, corners: bool) {
        proj.prefetch_point_data(f, corners);
    }

    /// A 30-bit Morton key of `y`'s cell in the walk grid: nearby points get nearby keys,
    /// so sorting a batch by it improves cache locality.
    #[inline]
    pub fn locality_key(proj: &Projector, y: &Vec8) -> u32 {
        proj.locality_key(y)
    }

    /// Hints the processor to load the first KiB (or less) of `r` into cache; no effect on
    /// results.
    #[inline(always)]
    pub fn prefetch<T>(r: &T) {
        crate::arch::prefetch_lines(r, std::mem::size_of::<T>().min(1024).div_ceil(64));
    }

    /// [`Projector::start_near`] (with `locate`, replacing `starts[k]`) and then
    /// [`Projector::project_with`] without a hint for up to [`WALK_GROUP`] queries, their
    /// memory waits overlapped; results pushed to `out` in order, equal to the one-query
    /// calls'.
    #[inline]
    pub fn project_group(
        proj: &Projector,
        ys: &[Vec8],
        starts: &mut [VertexId],
        locate: bool,
        goal: crate::SearchGoal,
        out: &mut Vec<Result<crate::Projection, crate::ProjectError>>,
    ) {
        proj.project_group(ys, starts, locate, goal, out);
    }

    /// The faces around vertex `v`, most promising for `y` first.
    #[inline]
    pub fn faces_by_promise(proj: &Projector, y: &Vec8, v: VertexId) -> FaceOrder {
        proj.faces_by_promise(y, v)
    }
}

/// Dimension of the embedding space.
pub const DIM: usize = 8;
/// A point or vector of the embedding space R^8.
pub type Vec8 = nalgebra::SVector<f64, 8>;
/// Two rows spanning a plane of R^8 (a tangent frame or an interpolated tangent plane).
pub type Mat2x8 = nalgebra::SMatrix<f64, 2, 8>;
