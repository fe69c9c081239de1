//! Maps through the C ABI: correspondence between two surfaces with paired anchors, and
//! decal coordinates on one surface.

use wavg::SurfacePoint;
use wavg::apps::{
    CorrespondOptions, Validity, ValidityTest, correspond_vertices, decal_uv, map_points,
};

use crate::boundary::optional;
use crate::boundary::{Failure, guard, handle, product, slice, slice_mut};
use crate::solver::{wavg_solver, write_image};
use crate::types::{wavg_point, wavg_status};

/// The status of an answered point that fails the validity test.
const REJECTED: wavg_status = crate::boundary::status_of(wavg::ErrorKind::NoSolution);

/// Writes per-point statuses and returns the first failure (with a message), or Ok.
fn finish(
    statuses: Option<&mut [wavg_status]>,
    each: impl Iterator<Item = Result<(), (wavg_status, String)>>,
) -> Result<(), Failure> {
    let mut first = None;
    let mut out = statuses;
    for (i, r) in each.enumerate() {
        let s = match r {
            Ok(()) => wavg_status::WAVG_STATUS_OK,
            Err((status, message)) => {
                if first.is_none() {
                    first = Some(Failure {
                        status,
                        message: format!("query {}: {message}", i + 1),
                    });
                }
                status
            }
        };
        if let Some(o) = out.as_deref_mut() {
            o[i] = s;
        }
    }
    first.map_or(Ok(()), Err)
}

/// The query points of a call (`n` of them, at least one).
///
/// # Safety
/// `points` must be NULL or hold `n` elements.
unsafe fn queries(points: *const wavg_point, n: usize) -> Result<Vec<SurfacePoint>, Failure> {
    if n == 0 {
        return Err(Failure::arg("n is 0"));
    }
    // SAFETY: per this function's contract.
    let pts = unsafe { slice(points, n, "points")? };
    Ok(pts
        .iter()
        .map(|p| SurfacePoint::new(p.face, p.bary))
        .collect())
}

fn solve_failure(e: &wavg::SolveError) -> (wavg_status, String) {
    let e = wavg::Error::from(e.clone());
    (crate::boundary::status_of(e.kind()), e.message())
}

/// Maps `n` points of the source surface onto the target: the inverse problem on
/// `source` (with `verified`, weights checked to return to the point, with an offset
/// penalty where the paper's do not), the forward problem on `target` with the same
/// weights. Anchor `i` of `source` is paired with anchor `i` of `target`. Writes the image
/// to `out[i]` and, unless NULL, its position to `out_xyz[3*i..3*i+3]` (target units) and
/// a status to `out_statuses[i]`: `WAVG_STATUS_OK` when the image passes the paper's test
/// (the weights return to the point and none is below `max_negative`, e.g. -0.1);
/// `WAVG_STATUS_NO_SOLUTION` when an image exists but fails it (the image is still
/// written: a per-point test cannot judge the image by its neighbours, see
/// `wavg_correspond_vertices`); another failure status with `face = UINT32_MAX` and NaN
/// where there is no image. Returns the first non-OK point's status (with its message) or
/// `WAVG_STATUS_OK`. Call-level errors (`WAVG_STATUS_INVALID_ARGUMENT`: NULL solvers,
/// points or `out`, `n == 0`, different anchor counts, a `max_negative` not finite or
/// above 0) write nothing. Runs in parallel; thread-safe on shared solvers.
///
/// # Safety
/// The solvers must be NULL or live; `points` and `out` must hold `n` elements,
/// `out_xyz` (unless NULL) `3 * n`, `out_statuses` (unless NULL) `n`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_correspond(
    source: *const wavg_solver,
    target: *const wavg_solver,
    points: *const wavg_point,
    n: usize,
    verified: bool,
    max_negative: f64,
    out: *mut wavg_point,
    out_xyz: *mut f64,
    out_statuses: *mut wavg_status,
) -> wavg_status {
    guard(|| {
        // SAFETY: per this function's contract.
        let query = unsafe { queries(points, n)? };
        wavg::apps::check_max_negative(max_negative)
            .map_err(|e| Failure::from(wavg::Error::from(e)))?;
        // SAFETY: per this function's contract.
        let (s, t) = unsafe { (handle(source, "source")?, handle(target, "target")?) };
        if s.inner().n_anchors() != t.inner().n_anchors() {
            return Err(Failure::arg(format!(
                "the source has {} anchors and the target {}",
                s.inner().n_anchors(),
                t.inner().n_anchors()
            )));
        }
        // SAFETY: per this function's contract.
        let (out, xyz, statuses) = unsafe {
            (
                slice_mut(out, n, "out")?,
                optional(out_xyz, product(n, 3, "n")?, "out_xyz")?,
                optional(out_statuses, n, "out_statuses")?,
            )
        };
        let mapped = map_points(s.inner(), t.inner(), &query, verified)
            .map_err(|e| Failure::from(wavg::Error::from(e)))?;
        let mut xyz = xyz;
        let each = mapped.iter().enumerate().map(|(i, m)| {
            write_image(out, xyz.as_deref_mut(), i, &m.target);
            match &m.target {
                Err(e) => Err(solve_failure(e)),
                Ok(_) if !m.round_trip => Err((
                    REJECTED,
                    "the weights do not return to the point".to_string(),
                )),
                Ok(_) if m.min_weight < max_negative => Err((
                    REJECTED,
                    format!("a weight ({}) is below {max_negative}", m.min_weight),
                )),
                Ok(_) => Ok(()),
            }
        });
        let r: Vec<_> = each.collect();
        finish(statuses, r.into_iter())
    })
}

/// Maps every vertex of the source surface onto the target (as `wavg_correspond`) and
/// judges each vertex: with `local`, by local consistency (its weights return to it and
/// most of its edges land stretched by at most 4 times the map's median edge stretch);
/// otherwise by the paper's test (round trip, no weight below `max_negative`). Writes
/// `out[v]`, and unless NULL `out_xyz[3*v..3*v+3]` and `out_statuses[v]`, for each of the source's
/// `n_vertices` vertices (the arrays must hold that many): `WAVG_STATUS_OK` for a kept
/// vertex, `WAVG_STATUS_NO_SOLUTION` for a rejected one (the image is still written when
/// it exists; `face = UINT32_MAX` and NaN otherwise). Returns the first non-OK vertex's
/// status or `WAVG_STATUS_OK`; call-level errors (`WAVG_STATUS_INVALID_ARGUMENT`) write
/// nothing. Runs in parallel; thread-safe on shared solvers.
///
/// # Safety
/// The solvers must be NULL or live; `out` must hold `n_vertices` elements of the source,
/// `out_xyz` (unless NULL) three times that, `out_statuses` (unless NULL) `n_vertices`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_correspond_vertices(
    source: *const wavg_solver,
    target: *const wavg_solver,
    verified: bool,
    local: bool,
    max_negative: f64,
    out: *mut wavg_point,
    out_xyz: *mut f64,
    out_statuses: *mut wavg_status,
) -> wavg_status {
    guard(|| {
        // SAFETY: per this function's contract.
        let (s, t) = unsafe { (handle(source, "source")?, handle(target, "target")?) };
        let opts = CorrespondOptions {
            verified,
            max_negative,
            test: if local {
                ValidityTest::Local
            } else {
                ValidityTest::Paper
            },
            ..Default::default()
        };
        let n = s.inner().mesh().n_vertices();
        if out.is_null() {
            return Err(Failure::arg("out is NULL"));
        }
        let c = correspond_vertices(s.inner(), t.inner(), &opts)
            .map_err(|e| Failure::from(wavg::Error::from(e)))?;
        // SAFETY: per this function's contract.
        let (out, mut xyz, statuses) = unsafe {
            (
                slice_mut(out, n, "out")?,
                optional(out_xyz, product(n, 3, "n_vertices")?, "out_xyz")?,
                optional(out_statuses, n, "out_statuses")?,
            )
        };
        let mut each = Vec::with_capacity(n);
        for (i, (m, v)) in c.mapped.iter().zip(&c.validity).enumerate() {
            write_image(out, xyz.as_deref_mut(), i, &m.target);
            each.push(match v {
                Validity::Valid => Ok(()),
                Validity::Unanswered(e) => Err(solve_failure(e)),
                v => Err((REJECTED, format!("rejected: {}", v.reason()))),
            });
        }
        finish(statuses, each.into_iter())
    })
}

/// Decal coordinates of `n` surface points: the anchors of `solver` carry
/// `anchor_uv[2*i], anchor_uv[2*i+1]` (one pair per anchor), and a point with the
/// paper's inverse weights `w` gets `(u, v) = sum_i w_i uv_i`, written to
/// `out_uv[2*k..2*k+2]`. `out_statuses[k]` (unless NULL): `WAVG_STATUS_OK`;
/// `WAVG_STATUS_NO_SOLUTION` where the weights are not meaningful (they do not return to
/// the point through the forward problem, or one is below `max_negative`), the
/// coordinates still written; another failure status, with NaN, where the inverse problem
/// fails. Returns the first non-OK point's status or `WAVG_STATUS_OK`. Call-level errors
/// (`WAVG_STATUS_INVALID_ARGUMENT`: NULL pointers, `n == 0`, non-finite coordinates, a
/// `max_negative` not finite or above 0) write nothing. Runs in parallel; thread-safe on a shared solver.
///
/// # Safety
/// `solver` must be NULL or live; `anchor_uv` must hold `2 * n_anchors` doubles,
/// `points` `n` points, `out_uv` `2 * n` doubles, `out_statuses` (unless NULL) `n`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_decal_uv(
    solver: *const wavg_solver,
    anchor_uv: *const f64,
    points: *const wavg_point,
    n: usize,
    max_negative: f64,
    out_uv: *mut f64,
    out_statuses: *mut wavg_status,
) -> wavg_status {
    guard(|| {
        // SAFETY: per this function's contract.
        let query = unsafe { queries(points, n)? };
        // SAFETY: per this function's contract.
        let s = unsafe { handle(solver, "solver")? };
        let k = s.inner().n_anchors();
        // SAFETY: per this function's contract.
        let uv = unsafe { slice(anchor_uv, product(k, 2, "anchors")?, "anchor_uv")? };
        let uv: Vec<[f64; 2]> = uv.chunks_exact(2).map(|c| [c[0], c[1]]).collect();
        // Checks the coordinates and max_negative before any output is touched.
        let d = decal_uv(s.inner(), &uv, &query, max_negative)
            .map_err(|e| Failure::from(wavg::Error::from(e)))?;
        // SAFETY: per this function's contract.
        let (out, statuses) = unsafe {
            (
                slice_mut(out_uv, product(n, 2, "n")?, "out_uv")?,
                optional(out_statuses, n, "out_statuses")?,
            )
        };
        // Which points failed outright: their inverse problem, asked again for the message.
        let mut each = Vec::with_capacity(n);
        for (i, (p, &marked)) in d.uv.iter().zip(&d.marked).enumerate() {
            let failed = if marked {
                s.inner().inverse(&query[i]).err()
            } else {
                None
            };
            match failed {
                Some(e) => {
                    out[2 * i..2 * i + 2].copy_from_slice(&[f64::NAN; 2]);
                    each.push(Err(solve_failure(&e)));
                }
                None => {
                    out[2 * i..2 * i + 2].copy_from_slice(p);
                    each.push(if marked {
                        Err((
                            REJECTED,
                            "the weights are not meaningful (no round trip or a weight below \
                             max_negative)"
                                .to_string(),
                        ))
                    } else {
                        Ok(())
                    });
                }
            }
        }
        finish(statuses, each.into_iter())
    })
}
