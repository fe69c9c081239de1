//! Applications of weighted averages on surfaces (paper Section 4), as library functions
//! over a [`wavg_solve::Solver`]: splines on surfaces (B-splines of any degree, open or
//! closed, and Bézier curves) whose samples are forward problems warm-started along the
//! curve; semiregular remeshing of a coarse polygon mesh with Laplacian smoothing on the
//! surface ([`Remesher`]), every new point a forward problem over its own few points.
#![forbid(unsafe_code)]
#![deny(unreachable_pub)]

mod basis;
mod remesh;
mod spline;

pub use basis::{SplineKind, spline_weights};
pub use remesh::{
    BaseMesh, DEFAULT_MAX_BASE_DISTANCE, MAX_LEVELS, MAX_POLYGON, RemeshError, RemeshResult,
    Remesher, polygons_to_obj,
};
pub use spline::{Curve, evaluate_spline};
