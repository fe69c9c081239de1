//! `wavg_surface_spread_anchors`: the anchors `wavg anchors` chooses.

use crate::boundary::{guard, handle, slice_mut};
use crate::surface::wavg_surface;
use crate::types::wavg_status;

/// `k` vertices spread over the surface by farthest-point sampling in its embedding (the
/// vertex positions before a precomputation or load), the first drawn from `seed`, each
/// next one the vertex farthest from those chosen: the vertices `wavg anchors --count k
/// --seed seed` writes for this embedding, in the same order, into `out_vertices` (`k`
/// integers). Errors: `WAVG_STATUS_INVALID_ARGUMENT` (NULL, `k` above the vertex count;
/// `out_vertices` unchanged). `k = 0` writes nothing. Thread-safe.
///
/// # Safety
/// `surface` must be NULL or live; `out_vertices` NULL or `k` writable integers.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_surface_spread_anchors(
    surface: *const wavg_surface,
    k: usize,
    seed: u64,
    out_vertices: *mut u32,
) -> wavg_status {
    guard(|| {
        // SAFETY: per this function's contract.
        let s = unsafe { handle(surface, "surface")? };
        let dst: &mut [u32] = match k {
            0 => &mut [],
            // SAFETY: per this function's contract.
            _ => unsafe { slice_mut(out_vertices, k, "out_vertices")? },
        };
        let anchors = wavg::anchors::spread(s.inner.mesh(), s.inner.embedded_coords(), k, seed)?;
        dst.copy_from_slice(&anchors);
        Ok(())
    })
}
