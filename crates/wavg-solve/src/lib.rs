//! Forward and inverse weighted-average problems (paper Sections 3.3-3.4).
//!
//! * [`kernel`]: the inverse problem's linear algebra given a tangent plane.
//! * [`weights`]: validation of forward-problem weights.
//! * [`sampling`]: seeded uniform surface points and farthest-point anchors.

pub mod error;
pub mod kernel;
pub mod sampling;
pub mod weights;

pub use error::SolveError;

/// Embedding dimension.
pub const DIM: usize = 8;
/// A point in R^8.
pub type Vec8 = nalgebra::SVector<f64, 8>;
/// A 2 x 8 matrix (tangent plane rows).
pub type Mat2x8 = nalgebra::SMatrix<f64, 2, 8>;
