//! Texture transfer through the C ABI, over RGBA8 buffers and UV arrays.

use wavg::TexCoords;
use wavg::apps::{Image, TransferOptions, transfer_texture_with_uv};

use crate::boundary::{Failure, guard, handle, product, slice, slice_mut};
use crate::solver::wavg_solver;
use crate::types::wavg_status;

/// Texture coordinates from C arrays: `n_uv` (u, v) pairs and one index triple per face.
///
/// # Safety
/// `uv` must hold `2 * n_uv` doubles and `faces` `3 * n_faces` indices (or be NULL).
unsafe fn tex_coords(
    uv: *const f64,
    n_uv: usize,
    faces: *const u32,
    n_faces: usize,
    what: &str,
) -> Result<TexCoords, Failure> {
    let faces_name = format!("{what}_faces");
    // SAFETY: per this function's contract.
    let (uv, faces) = unsafe {
        (
            slice(uv, product(n_uv, 2, what)?, what)?,
            slice(faces, product(n_faces, 3, &faces_name)?, &faces_name)?,
        )
    };
    Ok(TexCoords {
        coords: uv.chunks_exact(2).map(|c| [c[0], c[1]].into()).collect(),
        faces: faces.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
    })
}

/// Carries a texture from the source surface to the target surface through their
/// solvers' anchors (anchor `i` of one corresponds to anchor `i` of the other; the counts
/// must match). For every texel of the `out_width` x `out_height` target atlas covered by
/// a target triangle in the target's UV layout: the verified inverse on the target, the
/// forward problem on the source, and the source image sampled bilinearly at the source
/// UV. Texels on every `stride`-th row and column are solved exactly and the texels
/// between four of them inside one source chart interpolate them (`stride` 1 solves every
/// texel). Uncovered texels and texels without a source point get alpha 0; 4 rings of
/// seam dilation follow. UVs: `n_*_uv` (u, v) pairs (v = 0 is the image's bottom row) and
/// one index triple per face of each solver's mesh (`*_uv_faces`, `3 * n_faces`). Images
/// are RGBA8, rows from the top (`source_rgba`: `4 * source_width * source_height` bytes,
/// `out_rgba`: `4 * out_width * out_height`). Writes `out_rgba` and, unless NULL,
/// `*out_valid` (covered texels with a source point) and `*out_covered`. Errors:
/// `WAVG_STATUS_INVALID_ARGUMENT` (NULL inputs, zero sizes, anchor counts that differ, UV
/// arrays that do not fit the meshes), writing nothing. Thread-safe on shared solvers.
///
/// # Safety
/// `source` and `target` must be NULL or live; every non-NULL array must hold the stated
/// number of elements (faces: the solver's mesh's face count).
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn wavg_transfer_texture(
    source: *const wavg_solver,
    source_uv: *const f64,
    n_source_uv: usize,
    source_uv_faces: *const u32,
    source_rgba: *const u8,
    source_width: u32,
    source_height: u32,
    target: *const wavg_solver,
    target_uv: *const f64,
    n_target_uv: usize,
    target_uv_faces: *const u32,
    out_width: u32,
    out_height: u32,
    stride: u32,
    out_rgba: *mut u8,
    out_valid: *mut usize,
    out_covered: *mut usize,
) -> wavg_status {
    guard(|| {
        // SAFETY: per this function's contract.
        let (s, t) = unsafe { (handle(source, "source")?, handle(target, "target")?) };
        let (s, t) = (s.inner(), t.inner());
        if source_width == 0 || source_height == 0 || out_width == 0 || out_height == 0 {
            return Err(Failure::arg("image sizes must be positive"));
        }
        if stride == 0 {
            return Err(Failure::arg("stride is 0"));
        }
        let n_src = product(source_width as usize, source_height as usize, "source size")?;
        let n_out = product(out_width as usize, out_height as usize, "output size")?;
        // SAFETY: per this function's contract.
        let (suv, tuv, pixels) = unsafe {
            (
                tex_coords(
                    source_uv,
                    n_source_uv,
                    source_uv_faces,
                    s.mesh().n_faces(),
                    "source_uv",
                )?,
                tex_coords(
                    target_uv,
                    n_target_uv,
                    target_uv_faces,
                    t.mesh().n_faces(),
                    "target_uv",
                )?,
                slice(
                    source_rgba,
                    product(n_src, 4, "source size")?,
                    "source_rgba",
                )?,
            )
        };
        let image = Image {
            width: source_width,
            height: source_height,
            pixels: pixels
                .chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect(),
        };
        let opts = TransferOptions {
            width: out_width,
            height: out_height,
            stride,
            ..Default::default()
        };
        // Check the output pointer before the work.
        // SAFETY: per this function's contract.
        let out = unsafe { slice_mut(out_rgba, product(n_out, 4, "output size")?, "out_rgba")? };
        let r = transfer_texture_with_uv(s, &suv, &image, t, &tuv, &opts, &|_, _| {})?;
        out.copy_from_slice(r.image.pixels.as_flattened());
        // SAFETY: per this function's contract (NULL or one writable element each).
        unsafe {
            if let Some(v) = out_valid.as_mut() {
                *v = r.valid;
            }
            if let Some(c) = out_covered.as_mut() {
                *c = r.covered;
            }
        }
        Ok(())
    })
}
