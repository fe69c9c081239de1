//! `wavg_surface_decimate`: the coarse mesh of the landmark decimation.

use crate::boundary::{Failure, guard, handle, handle_mut, slice_mut};
use crate::surface::wavg_surface;
use crate::types::wavg_status;

/// Decimates the surface's mesh to `target_vertices` vertices by halfedge collapses
/// (quadric error priority, collapses that turn a triangle's normal by more than 45
/// degrees refused; genus and boundaries preserved). Every coarse vertex is an original
/// vertex at its original position: `out_original` (unless NULL) receives the original
/// index of each of the `target_vertices` coarse vertices, ascending. On success `*out` is
/// a new surface (free it with `wavg_surface_free`); `surface` is unchanged. Errors:
/// `WAVG_STATUS_INVALID_ARGUMENT` (NULL, `target_vertices` 0 or above the vertex count).
/// Thread-safe.
///
/// # Safety
/// `surface` must be NULL or live; `out_original` NULL or `target_vertices` writable
/// integers; `out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_surface_decimate(
    surface: *const wavg_surface,
    target_vertices: usize,
    out_original: *mut u32,
    out: *mut *mut wavg_surface,
) -> wavg_status {
    guard(|| {
        // SAFETY: per this function's contract.
        let (s, out) = unsafe { (handle(surface, "surface")?, handle_mut(out, "out")?) };
        let n = s.inner.n_vertices();
        if target_vertices == 0 || target_vertices > n {
            return Err(Failure::arg(format!(
                "target_vertices = {target_vertices} is not in 1..={n}"
            )));
        }
        let opts = wavg::DecimateOptions {
            target: target_vertices,
            ..Default::default()
        };
        let d = s.inner.decimate(&opts, &wavg::NoProgress)?;
        if !out_original.is_null() {
            // SAFETY: per this function's contract.
            let dst = unsafe { slice_mut(out_original, target_vertices, "out_original")? };
            dst.copy_from_slice(&d.original);
        }
        *out = Box::into_raw(Box::new(wavg_surface { inner: d.surface }));
        Ok(())
    })
}
