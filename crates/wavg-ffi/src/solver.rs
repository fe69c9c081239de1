//! `wavg_solver`: forward and inverse problems for one anchor set (wraps
//! `wavg::Solver`), answered in parallel batches.

use std::sync::Mutex;

use rayon::prelude::*;

use wavg::SolveError;
use wavg::{BatchWeights, ForwardOptions, RoundTrip, Solver, SurfacePoint};
use wavg::{ErrorKind, Par};

use crate::boundary::{
    Failure, Outcome, guard, guard_value, handle, handle_mut, optional, product, slice, slice_mut,
    status_of,
};
use crate::surface::wavg_surface;
use crate::types::{wavg_point, wavg_status};

/// A set of anchors on a surface, ready for forward and inverse problems. Create it with
/// `wavg_solver_new`, free it with `wavg_solver_free`.
///
/// Thread safety: `wavg_forward` and `wavg_inverse` (which take a `const wavg_solver *`)
/// may run on one solver from many threads at once and give the same results as one
/// thread; `wavg_solver_set_anchor` needs the solver to itself.
pub struct wavg_solver {
    solver: Solver,
    /// Reused output of the inverse batches (taken when free, so concurrent calls never
    /// wait for each other).
    scratch: Mutex<(BatchWeights, Vec<Result<RoundTrip, wavg::SolveError>>)>,
}

impl wavg_solver {
    /// The wrapped solver.
    pub(crate) fn inner(&self) -> &Solver {
        &self.solver
    }
}

/// Weights and round trips of a verified inverse batch.
type VerifiedScratch = (BatchWeights, Vec<Result<RoundTrip, SolveError>>);

fn point_in(p: &wavg_point) -> SurfacePoint {
    SurfacePoint::new(p.face, p.bary)
}

/// Makes a solver for `n_anchors` anchor points on `surface` (each a triangle and
/// barycentric coordinates; use `wavg_surface_vertex_point` for vertices). The anchors
/// are copied; the solver shares the surface's current embedding and stays valid after
/// the surface is changed or freed. On failure `*out` is unchanged. Errors:
/// `WAVG_STATUS_INVALID_ARGUMENT` (NULL pointers, no anchors, a face out of range, bad
/// barycentric coordinates).
///
/// # Safety
/// `surface` must be NULL or live; `anchors` NULL or `n_anchors` readable points; `out`
/// NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_solver_new(
    surface: *const wavg_surface,
    anchors: *const wavg_point,
    n_anchors: usize,
    out: *mut *mut wavg_solver,
) -> wavg_status {
    guard(|| {
        if n_anchors == 0 {
            return Err(Failure::arg("a solver needs at least one anchor"));
        }
        // SAFETY: per this function's contract.
        let (s, anchors, out) = unsafe {
            (
                handle(surface, "surface")?,
                slice(anchors, n_anchors, "anchors")?,
                handle_mut(out, "out")?,
            )
        };
        let solver = s.inner.solver(anchors.iter().map(point_in))?;
        *out = Box::into_raw(Box::new(wavg_solver {
            solver,
            scratch: Mutex::default(),
        }));
        Ok(())
    })
}

/// Number of anchors (0 for NULL). Thread-safe.
///
/// # Safety
/// `solver` must be NULL or live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_solver_anchor_count(solver: *const wavg_solver) -> usize {
    // SAFETY: per this function's contract.
    guard_value(0, || {
        unsafe { solver.as_ref() }.map_or(0, |s| s.solver.n_anchors())
    })
}

/// Replaces anchor `index` (0-based) by `anchor`; on failure the solver is unchanged.
/// Errors: `WAVG_STATUS_INVALID_ARGUMENT` (NULL, index out of range, bad point).
///
/// # Safety
/// `solver` must be NULL or live and not used by other threads during the call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_solver_set_anchor(
    solver: *mut wavg_solver,
    index: usize,
    anchor: wavg_point,
) -> wavg_status {
    guard(|| {
        // SAFETY: per this function's contract.
        let s = unsafe { handle_mut(solver, "solver")? };
        s.solver
            .anchors_mut()
            .set(index, wavg::Anchor::Point(point_in(&anchor)))
            .map_err(|e| Failure::from(wavg::Error::from(e)))
    })
}

/// Frees a solver (NULL is fine). Not to be called while another thread uses it.
///
/// # Safety
/// `solver` must be NULL or a solver from this library not freed before.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_solver_free(solver: *mut wavg_solver) {
    if !solver.is_null() {
        // SAFETY: created by Box::into_raw in this library and not freed before.
        let _ = std::panic::catch_unwind(|| drop(unsafe { Box::from_raw(solver) }));
    }
}

/// Per-query statuses: the first failure becomes the call's status and message.
struct Statuses<'a> {
    out: Option<&'a mut [wavg_status]>,
    first: Option<Failure>,
}

impl Statuses<'_> {
    fn set(&mut self, i: usize, r: Result<(), &SolveError>) {
        let status = match r {
            Ok(()) => wavg_status::WAVG_STATUS_OK,
            Err(e) => {
                let e = wavg::Error::from(e.clone());
                let status = status_of(e.kind());
                if self.first.is_none() {
                    self.first = Some(Failure {
                        status,
                        message: format!("query {}: {}", i + 1, e.message()),
                    });
                }
                status
            }
        };
        if let Some(out) = self.out.as_deref_mut() {
            out[i] = status;
        }
    }

    fn no_solution(&mut self, i: usize) {
        let message = format!(
            "query {}: the point is not reached as a weighted average of these anchors \
             (add anchors near it)",
            i + 1
        );
        let status = status_of(ErrorKind::NoSolution);
        if self.first.is_none() {
            self.first = Some(Failure { status, message });
        }
        if let Some(out) = self.out.as_deref_mut() {
            out[i] = status;
        }
    }

    fn finish(self) -> Outcome {
        self.first.map_or(Ok(()), Err)
    }
}

/// Forward problem for `n_queries` weight vectors, in parallel: `weights` holds
/// `n_queries * n_anchors` doubles, row-major (one row of anchor weights per query, each
/// summing to 1 within 1e-6). Writes `out_points[i]` (and, unless NULL, the 3-D position
/// `out_xyz[3*i..3*i+3]` and `out_statuses[i]`). A query without an answer gets its own
/// status, `face = UINT32_MAX` and NaN coordinates, while the others are answered; the
/// call returns the first failing query's status (and message), or `WAVG_STATUS_OK`.
/// Call-level errors (NULL solver, weights or `out_points`, `n_queries == 0`) return
/// `WAVG_STATUS_INVALID_ARGUMENT` and write nothing. Thread-safe on a shared solver.
///
/// # Safety
/// `solver` must be NULL or live; every non-NULL array must hold the stated number of
/// elements (`out_xyz`: `3 * n_queries`, `out_statuses` and `out_points`: `n_queries`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_forward(
    solver: *const wavg_solver,
    weights: *const f64,
    n_queries: usize,
    out_points: *mut wavg_point,
    out_xyz: *mut f64,
    out_statuses: *mut wavg_status,
) -> wavg_status {
    guard(|| {
        if n_queries == 0 {
            return Err(Failure::arg("n_queries is 0"));
        }
        // SAFETY: per this function's contract.
        let s = unsafe { handle(solver, "solver")? };
        let n = s.solver.n_anchors();
        let len = product(n_queries, n, "n_queries")?;
        // SAFETY: per this function's contract.
        let (weights, points, xyz, statuses) = unsafe {
            (
                slice(weights, len, "weights")?,
                slice_mut(out_points, n_queries, "out_points")?,
                optional(out_xyz, product(n_queries, 3, "n_queries")?, "out_xyz")?,
                optional(out_statuses, n_queries, "out_statuses")?,
            )
        };
        let rows: Vec<&[f64]> = weights.chunks_exact(n).collect();
        let results = s.solver.forward_batch(&rows, &ForwardOptions::default());
        write_points(&results, points, xyz, statuses)
    })
}

/// Writes the image of point `i` to `out[i]` and, when given, its position to
/// `xyz[3*i..3*i+3]`; `face = UINT32_MAX` and NaN where there is no image.
pub(crate) fn write_image(
    out: &mut [wavg_point],
    xyz: Option<&mut [f64]>,
    i: usize,
    image: &Result<wavg::ForwardResult, wavg::SolveError>,
) {
    let (p, x) = match image {
        Ok(r) => (
            wavg_point {
                face: r.point.face,
                bary: r.point.bary,
            },
            [r.position.x, r.position.y, r.position.z],
        ),
        Err(_) => (wavg_point::NONE, [f64::NAN; 3]),
    };
    out[i] = p;
    if let Some(xyz) = xyz {
        xyz[3 * i..3 * i + 3].copy_from_slice(&x);
    }
}

/// Writes forward answers: points (`wavg_point::NONE` and NaN positions where there is
/// none), positions and statuses; the first failure becomes the call's outcome.
pub(crate) fn write_points(
    results: &[Result<wavg::ForwardResult, SolveError>],
    points: &mut [wavg_point],
    mut xyz: Option<&mut [f64]>,
    statuses: Option<&mut [wavg_status]>,
) -> Outcome {
    let mut st = Statuses {
        out: statuses,
        first: None,
    };
    for (i, r) in results.iter().enumerate() {
        write_image(points, xyz.as_deref_mut(), i, r);
        st.set(i, r.as_ref().map(|_| ()));
    }
    st.finish()
}

/// How one inverse row ended.
enum Row {
    Ok,
    NotReached,
    Failed(SolveError),
}

/// Paper weights of each point straight into its row of `out` (NaN for failures), on the
/// current pool.
fn inverse_rows(solver: &Solver, points: &[wavg_point], out: &mut [f64]) -> Vec<Row> {
    match solver.inverse_rows_into_by(points, point_in, out, Par::Rayon) {
        Ok(status) => status
            .into_iter()
            .map(|r| r.map_or_else(Row::Failed, |()| Row::Ok))
            .collect(),
        // `Par::Rayon` always starts.
        Err(e) => points.iter().map(|_| Row::Failed(e.clone())).collect(),
    }
}

/// Verified weights of each point into its row of `out` (NaN when there are none),
/// through `Solver::inverse_verified_batch_into` with the solver's reusable buffers.
fn verified_rows(
    solver: &Solver,
    scratch: &Mutex<VerifiedScratch>,
    points: &[wavg_point],
    out: &mut [f64],
) -> Vec<Row> {
    let points: Vec<SurfacePoint> = points.iter().map(point_in).collect();
    // Taken when free, so concurrent calls never wait for each other.
    let mut owned = VerifiedScratch::default();
    let mut shared = scratch.try_lock().ok();
    let (batch, trips) = match shared.as_deref_mut() {
        Some(b) => (&mut b.0, &mut b.1),
        None => (&mut owned.0, &mut owned.1),
    };
    let tol = wavg::DEFAULT_TOLERANCE;
    // `Par::Rayon` always starts.
    let _ = solver.inverse_verified_batch_into(&points, tol, batch, trips, wavg::Par::Rayon);
    let n = solver.n_anchors();
    out.par_chunks_exact_mut(n)
        .enumerate()
        .with_min_len(1024)
        .map(|(i, row)| match (batch.get(i), &trips[i]) {
            (Ok(w), Ok(t)) if *t != RoundTrip::NotReached => {
                row.copy_from_slice(w);
                Row::Ok
            }
            (Ok(_), Ok(_)) => {
                row.fill(f64::NAN);
                Row::NotReached
            }
            (Err(e), _) | (_, Err(e)) => {
                row.fill(f64::NAN);
                Row::Failed(e.clone())
            }
        })
        .collect()
}

/// Inverse problem for `n_points` surface points, in parallel: writes each point's
/// anchor weights (a row of `n_anchors` doubles summing to 1) into `out_weights`
/// (`n_points * n_anchors` doubles, row-major) and, unless NULL, `out_statuses[i]`.
/// With `verified`, each row is checked to return to its point through the forward
/// problem (within 1e-3 mean edge lengths); when the paper's weights do not, weights
/// with an offset penalty are tried, and a point no weights return to gets
/// `WAVG_STATUS_NO_SOLUTION`. A point without an answer gets its own status and a row of
/// NaN, while the others are answered; the call returns the first failing point's status
/// (and message), or `WAVG_STATUS_OK`. Call-level errors (NULL solver, points or
/// `out_weights`, `n_points == 0`) return `WAVG_STATUS_INVALID_ARGUMENT` and write
/// nothing. Thread-safe on a shared solver.
///
/// # Safety
/// `solver` must be NULL or live; every non-NULL array must hold the stated number of
/// elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_inverse(
    solver: *const wavg_solver,
    points: *const wavg_point,
    n_points: usize,
    verified: bool,
    out_weights: *mut f64,
    out_statuses: *mut wavg_status,
) -> wavg_status {
    guard(|| {
        if n_points == 0 {
            return Err(Failure::arg("n_points is 0"));
        }
        // SAFETY: per this function's contract.
        let s = unsafe { handle(solver, "solver")? };
        let n = s.solver.n_anchors();
        // SAFETY: per this function's contract.
        let (points, out, statuses) = unsafe {
            (
                slice(points, n_points, "points")?,
                slice_mut(
                    out_weights,
                    product(n_points, n, "n_points")?,
                    "out_weights",
                )?,
                optional(out_statuses, n_points, "out_statuses")?,
            )
        };
        let rows = if verified {
            verified_rows(&s.solver, &s.scratch, points, out)
        } else {
            inverse_rows(&s.solver, points, out)
        };
        let mut st = Statuses {
            out: statuses,
            first: None,
        };
        for (i, r) in rows.into_iter().enumerate() {
            match r {
                Row::Ok => st.set(i, Ok(())),
                Row::NotReached => st.no_solution(i),
                Row::Failed(e) => st.set(i, Err(&e)),
            }
        }
        st.finish()
    })
}
