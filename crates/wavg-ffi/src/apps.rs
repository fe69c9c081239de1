//! The applications through the C ABI: splines on surfaces.

use wavg::apps::{SplineKind, evaluate_spline};

use crate::boundary::optional;
use crate::boundary::{Failure, guard, handle, product, slice_mut};
use crate::solver::{wavg_solver, write_points};
use crate::types::{wavg_point, wavg_status};

/// Samples a curve on the surface whose control points are the solver's anchors, in
/// anchor order: with `bezier`, a Bézier curve of degree `n_anchors - 1` (`degree` and
/// `closed` are then ignored); otherwise a
/// uniform B-spline of `degree` (at least 1, with at least `degree + 1` anchors), clamped
/// (from the first anchor to the last) or, with `closed`, periodic (a loop). Each of the
/// `n_samples` samples (uniform in the curve parameter) is the weighted average of the
/// anchors with the curve's blending weights, warm-started from the previous sample.
/// Writes `out_points[i]` and, unless NULL, `out_xyz[3*i..3*i+3]` and `out_statuses[i]`;
/// a sample without an answer gets its own status, `face = UINT32_MAX` and NaN, while the
/// others are answered; the call returns the first failing sample's status, or
/// `WAVG_STATUS_OK`. Errors: `WAVG_STATUS_INVALID_ARGUMENT` (NULL solver or `out_points`,
/// `n_samples == 0`, a degree the anchors cannot support), writing nothing.
/// Thread-safe on a shared solver.
///
/// # Safety
/// `solver` must be NULL or live; every non-NULL array must hold the stated number of
/// elements (`out_points` and `out_statuses`: `n_samples`, `out_xyz`: `3 * n_samples`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_spline(
    solver: *const wavg_solver,
    degree: u32,
    closed: bool,
    bezier: bool,
    n_samples: usize,
    out_points: *mut wavg_point,
    out_xyz: *mut f64,
    out_statuses: *mut wavg_status,
) -> wavg_status {
    guard(|| {
        if n_samples == 0 {
            return Err(Failure::arg("n_samples is 0"));
        }
        // SAFETY: per this function's contract.
        let s = unsafe { handle(solver, "solver")? };
        let kind = SplineKind::from_options(degree as usize, closed, bezier);
        // Check the curve before touching any output.
        wavg::apps::spline_weights(kind, s.inner().n_anchors(), 1)
            .map_err(|e| Failure::from(wavg::Error::from(e)))?;
        // SAFETY: per this function's contract.
        let (points, xyz, statuses) = unsafe {
            (
                slice_mut(out_points, n_samples, "out_points")?,
                optional(out_xyz, product(n_samples, 3, "n_samples")?, "out_xyz")?,
                optional(out_statuses, n_samples, "out_statuses")?,
            )
        };
        let curve = evaluate_spline(s.inner(), kind, n_samples, wavg::apps::SPLINE_CHUNK)
            .map_err(|e| Failure::from(wavg::Error::from(e)))?;
        write_points(&curve.samples, points, xyz, statuses)
    })
}
