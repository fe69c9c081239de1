//! `wavg_remesher`: semiregular remeshing of a coarse polygon mesh on a surface, with
//! Laplacian smoothing, recomputed warm-started after a base vertex moves (wraps
//! `wavg::apps::Remesher`).

use wavg::SurfacePoint;
use wavg::Vector3;
use wavg::apps::{BaseMesh, RemeshResult, Remesher};

use crate::boundary::optional;
use crate::boundary::{Failure, guard, guard_value, handle, handle_mut, product, slice};
use crate::surface::wavg_surface;
use crate::types::{wavg_point, wavg_status};

/// A coarse polygon mesh put on a surface, refined on request. Create it with
/// `wavg_remesher_new`, run it with `wavg_remesher_run`, read the refined mesh with the
/// count functions and `wavg_remesher_get`, move base vertices with
/// `wavg_remesher_move_vertex` (the next run starts every search from the previous run's
/// answers), free it with `wavg_remesher_free`.
///
/// Thread safety: one remesher must not be used by two threads at once (runs already use
/// the library's worker threads); different remeshers are independent.
pub struct wavg_remesher {
    remesher: Remesher,
    last: Option<RemeshResult>,
}

/// Makes a remesher for a base mesh of `n_base` vertices (`base_xyz`: `3 * n_base`
/// doubles, in the surface's units) and `n_faces` polygons: `face_sizes[f]` corners each
/// (3 to 64), their 0-based vertex indices one after another in `face_indices`,
/// counter-clockwise. The base must be an oriented manifold along its edges with every
/// vertex used. Each base vertex is put at its closest point of the surface in 3-D;
/// one farther than `max_distance` bounding-box diagonals is refused (`max_distance <= 0`
/// means the default, 0.15). Everything is copied; the remesher shares the surface's
/// current embedding and stays valid after the surface is changed or freed. On failure
/// `*out` is unchanged. Errors: `WAVG_STATUS_INVALID_ARGUMENT` (NULL pointers, no
/// vertices or faces, non-finite coordinates, an index out of range, a vertex too far
/// from the surface), `WAVG_STATUS_INVALID_MESH` (a face with under 3 or over 64
/// corners or a repeated corner, an edge in more than two faces or two of the same
/// orientation, an unused vertex).
///
/// # Safety
/// `surface` must be NULL or live; `base_xyz` NULL or `3 * n_base` readable doubles;
/// `face_sizes` NULL or `n_faces` readable values; `face_indices` NULL or as many
/// readable values as the sizes add up to; `out` NULL or writable.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn wavg_remesher_new(
    surface: *const wavg_surface,
    base_xyz: *const f64,
    n_base: usize,
    face_sizes: *const u32,
    n_faces: usize,
    face_indices: *const u32,
    max_distance: f64,
    out: *mut *mut wavg_remesher,
) -> wavg_status {
    guard(|| {
        if n_base == 0 || n_faces == 0 {
            return Err(Failure::arg(format!(
                "the base mesh is empty ({n_base} vertices, {n_faces} faces)"
            )));
        }
        // SAFETY: per this function's contract.
        let (s, xyz, sizes, out) = unsafe {
            (
                handle(surface, "surface")?,
                slice(base_xyz, product(n_base, 3, "n_base")?, "base_xyz")?,
                slice(face_sizes, n_faces, "face_sizes")?,
                handle_mut(out, "out")?,
            )
        };
        let total = sizes.iter().try_fold(0usize, |a, &n| {
            a.checked_add(n as usize)
                .ok_or_else(|| Failure::arg("the face sizes add up to too many indices"))
        })?;
        // SAFETY: per this function's contract (`total` indices).
        let idx = unsafe { slice(face_indices, total, "face_indices")? };
        let mut faces = Vec::with_capacity(n_faces);
        let mut at = 0;
        for &n in sizes {
            faces.push(idx[at..at + n as usize].to_vec());
            at += n as usize;
        }
        let base = BaseMesh {
            positions: xyz
                .chunks_exact(3)
                .map(|c| Vector3::new(c[0], c[1], c[2]))
                .collect(),
            faces,
        };
        let max = if max_distance > 0.0 {
            max_distance
        } else {
            wavg::apps::DEFAULT_MAX_BASE_DISTANCE
        };
        let remesher = Remesher::with_max_distance(s.inner.projector().clone(), &base, max)?;
        *out = Box::into_raw(Box::new(wavg_remesher {
            remesher,
            last: None,
        }));
        Ok(())
    })
}

/// Refines the base `levels` times (0 to 8) and smooths `smooth` steps (0 to 1000); the
/// result is kept for the count functions and `wavg_remesher_get`. With the same `levels`
/// and `smooth` as the previous successful run, every search starts from that run's answer
/// (the interactive case). Errors: `WAVG_STATUS_INVALID_ARGUMENT` (NULL, `levels > 8`,
/// `smooth > 1000`),
/// `WAVG_STATUS_NO_SOLUTION` (an average without a projection; the previous result is
/// kept).
///
/// # Safety
/// `remesher` must be NULL or live and not used by other threads during the call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_remesher_run(
    remesher: *mut wavg_remesher,
    levels: u32,
    smooth: u32,
) -> wavg_status {
    guard(|| {
        // SAFETY: per this function's contract.
        let r = unsafe { handle_mut(remesher, "remesher")? };
        let out = r.remesher.remesh(levels as usize, smooth as usize)?;
        r.last = Some(out);
        Ok(())
    })
}

/// Moves base vertex `index` (0-based) to the surface point `point`; on failure nothing
/// changes. Call `wavg_remesher_run` to recompute. Errors: `WAVG_STATUS_INVALID_ARGUMENT`
/// (NULL, index out of range, a face out of range or bad barycentric coordinates).
///
/// # Safety
/// `remesher` must be NULL or live and not used by other threads during the call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_remesher_move_vertex(
    remesher: *mut wavg_remesher,
    index: usize,
    point: wavg_point,
) -> wavg_status {
    guard(|| {
        // SAFETY: per this function's contract.
        let r = unsafe { handle_mut(remesher, "remesher")? };
        r.remesher
            .move_base_vertex(index, SurfacePoint::new(point.face, point.bary))
            .map_err(Failure::from)
    })
}

/// Base vertex `index` (0-based) on the surface: where `wavg_remesher_new` put it, or
/// where it was moved. Errors: `WAVG_STATUS_INVALID_ARGUMENT` (NULL, index out of
/// range).
///
/// # Safety
/// `remesher` must be NULL or live; `out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_remesher_base_point(
    remesher: *const wavg_remesher,
    index: usize,
    out: *mut wavg_point,
) -> wavg_status {
    guard(|| {
        // SAFETY: per this function's contract.
        let (r, out) = unsafe { (handle(remesher, "remesher")?, handle_mut(out, "out")?) };
        let pts = r.remesher.base_points();
        let p = pts.get(index).ok_or_else(|| {
            Failure::arg(format!(
                "base vertex {index} does not exist ({} base vertices)",
                pts.len()
            ))
        })?;
        *out = wavg_point {
            face: p.face,
            bary: p.bary,
        };
        Ok(())
    })
}

/// Counts of the last run's refined mesh: `what` 0 = vertices, 1 = faces, 2 = face
/// corner indices (the length of `wavg_remesher_get`'s `out_face_indices`). 0 for NULL,
/// before the first successful run, or another `what`. Thread-safe with other reads.
///
/// # Safety
/// `remesher` must be NULL or live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_remesher_count(remesher: *const wavg_remesher, what: u32) -> usize {
    guard_value(0, || {
        // SAFETY: per this function's contract.
        let Some(out) = unsafe { remesher.as_ref() }.and_then(|r| r.last.as_ref()) else {
            return 0;
        };
        match what {
            0 => out.positions.len(),
            1 => out.faces.len(),
            2 => out.faces.iter().map(Vec::len).sum(),
            _ => 0,
        }
    })
}

/// Copies the last run's refined mesh into the non-NULL arrays: `out_points` (one
/// surface point per vertex), `out_xyz` (`3 *` vertices doubles), `out_face_sizes` (one
/// per face: 4 for quads, 3 for triangles) and `out_face_indices` (0-based,
/// counter-clockwise, face after face); sizes from `wavg_remesher_count`. Base vertices
/// come first, in base order. Errors: `WAVG_STATUS_INVALID_ARGUMENT` (NULL remesher, no
/// successful run yet), writing nothing.
///
/// # Safety
/// `remesher` must be NULL or live; every non-NULL array must hold the number of
/// elements `wavg_remesher_count` gives.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_remesher_get(
    remesher: *const wavg_remesher,
    out_points: *mut wavg_point,
    out_xyz: *mut f64,
    out_face_sizes: *mut u32,
    out_face_indices: *mut u32,
) -> wavg_status {
    guard(|| {
        // SAFETY: per this function's contract.
        let r = unsafe { handle(remesher, "remesher")? };
        let out = r
            .last
            .as_ref()
            .ok_or_else(|| Failure::arg("the remesher has not run yet"))?;
        let (nv, nf) = (out.positions.len(), out.faces.len());
        let ni: usize = out.faces.iter().map(Vec::len).sum();
        // SAFETY: per this function's contract.
        let (points, xyz, sizes, idx) = unsafe {
            (
                optional(out_points, nv, "out_points")?,
                optional(out_xyz, 3 * nv, "out_xyz")?,
                optional(out_face_sizes, nf, "out_face_sizes")?,
                optional(out_face_indices, ni, "out_face_indices")?,
            )
        };
        if let Some(points) = points {
            for (o, p) in points.iter_mut().zip(&out.points) {
                *o = wavg_point {
                    face: p.face,
                    bary: p.bary,
                };
            }
        }
        if let Some(xyz) = xyz {
            for (o, p) in xyz.chunks_exact_mut(3).zip(&out.positions) {
                o.copy_from_slice(&[p.x, p.y, p.z]);
            }
        }
        if let Some(sizes) = sizes {
            for (o, f) in sizes.iter_mut().zip(out.faces.iter()) {
                *o = f.len() as u32;
            }
        }
        if let Some(idx) = idx {
            for (o, &v) in idx.iter_mut().zip(out.faces.iter().flatten()) {
                *o = v;
            }
        }
        Ok(())
    })
}

/// Frees a remesher (NULL is fine). Not to be called while another thread uses it.
///
/// # Safety
/// `remesher` must be NULL or a remesher from this library not freed before.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_remesher_free(remesher: *mut wavg_remesher) {
    if !remesher.is_null() {
        // SAFETY: created by Box::into_raw in this library and not freed before.
        let _ = std::panic::catch_unwind(|| drop(unsafe { Box::from_raw(remesher) }));
    }
}
