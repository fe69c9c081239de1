//! One-off questions, answered without keeping a [`Solver`](crate::Solver): convenient
//! for a single query; for many queries on the same anchors make a solver once with
//! [`Surface::solver`] and use its batch calls.

use wavg_mesh::SurfacePoint;
use wavg_solve::{Anchor, ForwardOptions, ForwardResult, Normalization, validate_weights};

use crate::error::{Error, Result};
use crate::surface::Surface;

/// The weighted average of `anchors` with `weights` (one per anchor, summing to 1): the
/// forward problem.
///
/// ```
/// let surface = wavg::Surface::from_mesh(wavg::mesh::procedural::icosphere(3))?;
/// let mid = wavg::weighted_average(&surface, [0u32, 1], &[0.5, 0.5])?;
/// assert!(mid.position.norm() > 0.99); // on the unit sphere, not the chord
/// # Ok::<(), wavg::Error>(())
/// ```
pub fn weighted_average<A: Into<Anchor>>(
    surface: &Surface,
    anchors: impl IntoIterator<Item = A>,
    weights: &[f64],
) -> Result<ForwardResult> {
    let solver = surface.solver(anchors)?;
    Ok(solver.forward(weights, &ForwardOptions::default())?)
}

/// Generalised barycentric weights of `point` with respect to `anchors` (one per anchor,
/// summing to 1): the paper's inverse problem.
///
/// ```
/// let surface = wavg::Surface::from_mesh(wavg::mesh::procedural::icosphere(3))?;
/// let anchors = surface.spread_anchors(12, 0)?;
/// let w = wavg::barycentric_weights(&surface, anchors, &wavg::SurfacePoint::new(5, [0.2, 0.3, 0.5]))?;
/// assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-9);
/// # Ok::<(), wavg::Error>(())
/// ```
pub fn barycentric_weights<A: Into<Anchor>>(
    surface: &Surface,
    anchors: impl IntoIterator<Item = A>,
    point: &SurfacePoint,
) -> Result<Vec<f64>> {
    let solver = surface.solver(anchors)?;
    Ok(solver.inverse(point)?)
}

/// Checks every row of a batch of forward weights before any is solved, the rule every
/// door follows: weights that are malformed (not one per anchor, not finite, or not summing
/// to 1 without [`Normalization::Normalize`]) are the caller's error and refuse the whole
/// request, single query or batch, naming the first bad row (messages count rows and
/// weights from 1); a well-formed row without an answer (no weighted average) is a
/// per-row failure of a batch, and the error of a single query.
///
/// Returns the first bad row's 0-based index with its error.
///
/// ```
/// use wavg::Normalization::{Normalize, Reject};
/// let rows: [&[f64]; 2] = [&[0.5, 0.5], &[0.5, 0.1]];
/// let (row, e) = wavg::check_weight_rows(&rows, 2, Reject).unwrap_err();
/// assert_eq!(row, 1);
/// assert!(e.message().contains("weights sum to 0.6"), "{}", e.message());
/// assert!(wavg::check_weight_rows(&rows, 2, Normalize).is_ok());
/// ```
pub fn check_weight_rows(
    rows: &[&[f64]],
    n_anchors: usize,
    norm: Normalization,
) -> std::result::Result<(), (usize, Error)> {
    match rows
        .iter()
        .enumerate()
        .find_map(|(i, w)| validate_weights(w, n_anchors, norm).err().map(|e| (i, e)))
    {
        None => Ok(()),
        Some((i, e)) => Err((i, Error::from(e))),
    }
}
