//! `wavg_surface`: a mesh with its embedding (wraps `wavg::Surface`).

use std::ffi::{c_char, c_void};
use std::path::PathBuf;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::boundary::{
    Failure, Outcome, guard, guard_value, handle, handle_mut, product, slice, slice_mut,
};
use crate::options::wavg_precompute_options;
use crate::types::{wavg_point, wavg_progress_fn, wavg_stage, wavg_status};

/// A validated triangle mesh with its 8-D embedding. Create it with
/// `wavg_surface_open`, `wavg_surface_open_with_embedding` or `wavg_surface_from_arrays`,
/// free it with `wavg_surface_free`.
///
/// Thread safety: calls taking a `const wavg_surface *` may run on one surface from many
/// threads at once; `wavg_surface_precompute` and `wavg_surface_load_embedding` need the
/// surface to themselves. Solvers made from a surface stay valid after it is changed or
/// freed (they share its data).
pub struct wavg_surface {
    pub(crate) inner: wavg::Surface,
}

/// Reads a NUL-terminated path.
///
/// # Safety
/// `path` must be NULL or a NUL-terminated string.
unsafe fn path_arg(path: *const c_char) -> Result<PathBuf, Failure> {
    if path.is_null() {
        return Err(Failure::arg("path is NULL"));
    }
    // SAFETY: non-NULL and NUL-terminated by the caller's contract.
    let bytes = unsafe { std::ffi::CStr::from_ptr(path) }.to_bytes();
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        Ok(PathBuf::from(std::ffi::OsStr::from_bytes(bytes)))
    }
    #[cfg(not(unix))]
    {
        std::str::from_utf8(bytes)
            .map(PathBuf::from)
            .map_err(|_| Failure::arg("path is not UTF-8"))
    }
}

/// Stores a new handle in `*out`.
fn give(out: &mut *mut wavg_surface, surface: wavg::Surface) {
    *out = Box::into_raw(Box::new(wavg_surface { inner: surface }));
}

/// Loads a mesh file (`.obj`, `.off`, `.ply`, each optionally gzipped as `.gz`; `.gltf` or
/// `.glb`, `scene.glb#Name` for one of its meshes; `mesh_path` is a NUL-terminated path), or
/// a builtin mesh (`builtin:torus`, as the `wavg` command takes it), and validates it. On success `*out` is a new surface whose
/// embedding is the vertex positions until one is precomputed or loaded; on failure `*out`
/// is left unchanged. Errors: `WAVG_STATUS_IO` (missing or unreadable file),
/// `WAVG_STATUS_INVALID_MESH` (not an oriented manifold, degenerate faces...),
/// `WAVG_STATUS_INVALID_ARGUMENT` (an unknown builtin name).
///
/// # Safety
/// `mesh_path` must be NULL or NUL-terminated; `out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_surface_open(
    mesh_path: *const c_char,
    out: *mut *mut wavg_surface,
) -> wavg_status {
    guard(|| {
        // SAFETY: per this function's contract.
        let (path, out) = unsafe { (path_arg(mesh_path)?, handle_mut(out, "out")?) };
        give(out, wavg::Surface::open(path)?);
        Ok(())
    })
}

/// Loads a mesh file as `wavg_surface_open` does and, when `embedding_path` is not NULL,
/// the `.wavg` embedding file computed for that mesh, in one call: the surface is built
/// once, on the file's embedding, without first building one on the vertex positions as
/// `wavg_surface_open` followed by `wavg_surface_load_embedding` does (at 10M vertices that
/// first build costs seconds and gigabytes). `embedding_path` NULL gives the same surface
/// as `wavg_surface_open`. On success `*out` is a new surface; on failure it is left
/// unchanged. Errors: `WAVG_STATUS_IO` (a missing or unreadable file; an embedding file
/// that is corrupt or made for another mesh), `WAVG_STATUS_INVALID_MESH`.
///
/// # Safety
/// `mesh_path` must be NULL or NUL-terminated, `embedding_path` NULL or NUL-terminated;
/// `out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_surface_open_with_embedding(
    mesh_path: *const c_char,
    embedding_path: *const c_char,
    out: *mut *mut wavg_surface,
) -> wavg_status {
    guard(|| {
        // SAFETY: per this function's contract.
        let (path, out) = unsafe { (path_arg(mesh_path)?, handle_mut(out, "out")?) };
        let embedding = if embedding_path.is_null() {
            None
        } else {
            // SAFETY: non-NULL, NUL-terminated by this function's contract.
            Some(unsafe { path_arg(embedding_path)? })
        };
        give(
            out,
            wavg::Surface::open_with_embedding(path, embedding.as_deref())?,
        );
        Ok(())
    })
}

/// Makes a surface from arrays: `xyz` holds `3 * n_vertices` coordinates (x, y, z per
/// vertex), `triangles` holds `3 * n_triangles` 0-based vertex indices, counter-clockwise
/// seen from outside. The arrays are copied. On success `*out` is a new surface; on
/// failure it is unchanged. Errors: `WAVG_STATUS_INVALID_ARGUMENT` (NULL pointers, zero
/// counts), `WAVG_STATUS_INVALID_MESH` (indices out of range, non-finite coordinates,
/// non-manifold or degenerate triangles, unreferenced vertices).
///
/// # Safety
/// `xyz` and `triangles` must be NULL or hold the stated counts; `out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_surface_from_arrays(
    xyz: *const f64,
    n_vertices: usize,
    triangles: *const u32,
    n_triangles: usize,
    out: *mut *mut wavg_surface,
) -> wavg_status {
    guard(|| {
        if n_vertices == 0 || n_triangles == 0 {
            return Err(Failure::arg(format!(
                "a surface needs vertices and triangles ({n_vertices} vertices, \
                 {n_triangles} triangles given)"
            )));
        }
        let nx = product(n_vertices, 3, "n_vertices")?;
        let nt = product(n_triangles, 3, "n_triangles")?;
        // SAFETY: per this function's contract.
        let (xyz, tris, out) = unsafe {
            (
                slice(xyz, nx, "xyz")?,
                slice(triangles, nt, "triangles")?,
                handle_mut(out, "out")?,
            )
        };
        let positions: Vec<[f64; 3]> = xyz.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let tris: Vec<[u32; 3]> = tris.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        give(out, wavg::Surface::from_arrays(&positions, &tris)?);
        Ok(())
    })
}

/// Progress sink calling the C callback (one call at a time) and remembering a cancel.
struct CallbackProgress {
    callback: unsafe extern "C" fn(wavg_stage, f64, *mut c_void) -> bool,
    user_data: *mut c_void,
    lock: Mutex<()>,
    cancelled: AtomicBool,
}

// SAFETY: the callback contract (see `wavg_progress_fn`) allows calls from any thread;
// the mutex keeps them from overlapping, so `user_data` is never used concurrently.
unsafe impl Sync for CallbackProgress {}

impl wavg::Progress for CallbackProgress {
    fn report(&self, stage: wavg::Stage, fraction: f64) {
        let _one_at_a_time = self.lock.lock().unwrap_or_else(|e| e.into_inner());
        // SAFETY: the caller supplied a valid callback and user data for this call.
        let go_on = unsafe { (self.callback)(stage.into(), fraction, self.user_data) };
        if !go_on {
            self.cancelled.store(true, Ordering::Relaxed);
        }
    }

    fn cancelled(&self) -> bool {
        self.cancelled.load(Ordering::Relaxed)
    }
}

/// Computes the 8-D embedding (landmarks, geodesics, MDS, least-squares mesh) and uses it
/// from now on. `options` NULL means the defaults; `progress` (or NULL) is called with
/// `user_data` as stages advance and can cancel. On any failure the surface is unchanged.
/// Blocks until done (seconds to minutes: about 1-5 s for 10k-150k vertices with 1000
/// landmarks); uses all cores. Errors: `WAVG_STATUS_INVALID_ARGUMENT` (NULL surface, bad
/// options), `WAVG_STATUS_INVALID_MESH` (e.g. more than one connected component),
/// `WAVG_STATUS_CANCELLED`.
///
/// # Safety
/// `surface` must be NULL or a live surface not used by other threads during the call;
/// `options` NULL or valid for its `struct_size`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_surface_precompute(
    surface: *mut wavg_surface,
    options: *const wavg_precompute_options,
    progress: wavg_progress_fn,
    user_data: *mut c_void,
) -> wavg_status {
    guard(|| {
        // SAFETY: per this function's contract.
        let (s, opts) = unsafe {
            (
                handle_mut(surface, "surface")?,
                wavg_precompute_options::read(options)?,
            )
        };
        match progress {
            Some(callback) => {
                let sink = CallbackProgress {
                    callback,
                    user_data,
                    lock: Mutex::new(()),
                    cancelled: AtomicBool::new(false),
                };
                s.inner.precompute(&opts, &sink)?;
            }
            None => {
                s.inner.precompute(&opts, &wavg::NoProgress)?;
            }
        }
        Ok(())
    })
}

/// Reads a `.wavg` embedding file computed for this mesh (its fingerprint is checked)
/// and uses it from now on; on failure the surface is unchanged. Errors:
/// `WAVG_STATUS_IO` (missing, corrupt, or made for another mesh).
///
/// # Safety
/// `surface` must be NULL or a live surface not used by other threads during the call;
/// `path` NULL or NUL-terminated.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_surface_load_embedding(
    surface: *mut wavg_surface,
    path: *const c_char,
) -> wavg_status {
    guard(|| {
        // SAFETY: per this function's contract.
        let (s, path) = unsafe { (handle_mut(surface, "surface")?, path_arg(path)?) };
        s.inner.load_embedding(path)?;
        Ok(())
    })
}

/// Writes the embedding to a `.wavg` file (atomically: a temporary file renamed into
/// place). Fails with `WAVG_STATUS_INVALID_ARGUMENT` when the surface has none computed
/// or loaded, `WAVG_STATUS_IO` when the file cannot be written. Thread-safe.
///
/// # Safety
/// `surface` must be NULL or live; `path` NULL or NUL-terminated.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_surface_save_embedding(
    surface: *const wavg_surface,
    path: *const c_char,
) -> wavg_status {
    guard(|| {
        // SAFETY: per this function's contract.
        let (s, path) = unsafe { (handle(surface, "surface")?, path_arg(path)?) };
        if !s.inner.has_embedding() {
            return Err(Failure::arg(
                "the surface has no embedding to save: precompute or load one first",
            ));
        }
        s.inner.save_embedding(path)?;
        Ok(())
    })
}

/// Number of vertices (0 for NULL). Thread-safe.
///
/// # Safety
/// `surface` must be NULL or live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_surface_vertex_count(surface: *const wavg_surface) -> usize {
    // SAFETY: per this function's contract.
    guard_value(0, || {
        unsafe { surface.as_ref() }.map_or(0, |s| s.inner.n_vertices())
    })
}

/// Number of triangles (0 for NULL). Thread-safe.
///
/// # Safety
/// `surface` must be NULL or live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_surface_face_count(surface: *const wavg_surface) -> usize {
    // SAFETY: per this function's contract.
    guard_value(0, || {
        unsafe { surface.as_ref() }.map_or(0, |s| s.inner.n_faces())
    })
}

/// The surface point at `vertex` (a corner of one of its triangles) into `*out`.
/// Errors: `WAVG_STATUS_INVALID_ARGUMENT` (NULL, vertex out of range; `*out` unchanged).
/// Thread-safe.
///
/// # Safety
/// `surface` must be NULL or live; `out` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_surface_vertex_point(
    surface: *const wavg_surface,
    vertex: u32,
    out: *mut wavg_point,
) -> wavg_status {
    guard(|| {
        // SAFETY: per this function's contract.
        let (s, out) = unsafe { (handle(surface, "surface")?, handle_mut(out, "out")?) };
        let p = s.inner.vertex_point(vertex)?;
        *out = wavg_point {
            face: p.face,
            bary: p.bary,
        };
        Ok(())
    })
}

/// Copies `width` values per vertex from `rows` into `out` (at least that many long).
///
/// # Safety
/// `out` must be NULL or hold `len` writable doubles.
unsafe fn copy_rows<const W: usize>(
    rows: impl ExactSizeIterator<Item = [f64; W]>,
    out: *mut f64,
    len: usize,
) -> Outcome {
    let need = product(rows.len(), W, "the output")?;
    if len < need {
        return Err(Failure::arg(format!(
            "the output holds {len} values, {need} are needed"
        )));
    }
    // SAFETY: per this function's contract.
    let out = unsafe { slice_mut(out, need, "out")? };
    for (dst, src) in out.chunks_exact_mut(W).zip(rows) {
        dst.copy_from_slice(&src);
    }
    Ok(())
}

/// Copies the embedding into `out`: 8 doubles per vertex, vertex by vertex (`len` at
/// least `8 * vertex count`). Before a precomputation or load, the embedding is the
/// vertex positions followed by five zeros. Errors: `WAVG_STATUS_INVALID_ARGUMENT` (NULL,
/// `len` too small; `out` unchanged). Thread-safe.
///
/// # Safety
/// `surface` must be NULL or live; `out` NULL or `len` writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_surface_embedding(
    surface: *const wavg_surface,
    out: *mut f64,
    len: usize,
) -> wavg_status {
    guard(|| {
        // SAFETY: per this function's contract.
        let s = unsafe { handle(surface, "surface")? };
        let rows = s.inner.embedded_coords().iter().map(|c| {
            let mut r = [0.0; 8];
            r.copy_from_slice(c.as_slice());
            r
        });
        // SAFETY: per this function's contract.
        unsafe { copy_rows::<8>(rows, out, len) }
    })
}

/// Copies the vertex positions into `out`: x, y, z per vertex (`len` at least
/// `3 * vertex count`). Errors: `WAVG_STATUS_INVALID_ARGUMENT` (NULL, `len` too small;
/// `out` unchanged). Thread-safe.
///
/// # Safety
/// `surface` must be NULL or live; `out` NULL or `len` writable doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_surface_positions(
    surface: *const wavg_surface,
    out: *mut f64,
    len: usize,
) -> wavg_status {
    guard(|| {
        // SAFETY: per this function's contract.
        let s = unsafe { handle(surface, "surface")? };
        let rows = s.inner.mesh().positions.iter().map(|p| [p.x, p.y, p.z]);
        // SAFETY: per this function's contract.
        unsafe { copy_rows::<3>(rows, out, len) }
    })
}

/// Copies the triangles into `out`: three 0-based vertex indices per triangle, in the
/// surface's order (`len` at least `3 * face count`). Errors:
/// `WAVG_STATUS_INVALID_ARGUMENT` (NULL, `len` too small; `out` unchanged). Thread-safe.
///
/// # Safety
/// `surface` must be NULL or live; `out` NULL or `len` writable integers.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_surface_triangles(
    surface: *const wavg_surface,
    out: *mut u32,
    len: usize,
) -> wavg_status {
    guard(|| {
        // SAFETY: per this function's contract.
        let s = unsafe { handle(surface, "surface")? };
        let tris = &s.inner.mesh().triangles;
        let need = product(tris.len(), 3, "the output")?;
        if len < need {
            return Err(Failure::arg(format!(
                "the output holds {len} indices, {need} are needed"
            )));
        }
        // SAFETY: per this function's contract.
        let out = unsafe { slice_mut(out, need, "out")? };
        for (dst, t) in out.chunks_exact_mut(3).zip(tris) {
            dst.copy_from_slice(t);
        }
        Ok(())
    })
}

/// The landmark vertices of the embedding (none before a precomputation or load):
/// `*n` receives their count; when `len` is at least that count they are copied into
/// `out`. Call with `out = NULL, len = 0` to ask for the count only. Errors:
/// `WAVG_STATUS_INVALID_ARGUMENT` (NULL surface or `n`, `out` NULL with `len > 0`,
/// `len` too small; nothing written). Thread-safe.
///
/// # Safety
/// `surface` must be NULL or live; `out` NULL or `len` writable integers; `n` NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_surface_landmarks(
    surface: *const wavg_surface,
    out: *mut u32,
    len: usize,
    n: *mut usize,
) -> wavg_status {
    guard(|| {
        // SAFETY: per this function's contract.
        let (s, n) = unsafe { (handle(surface, "surface")?, handle_mut(n, "n")?) };
        let lm = s.inner.landmarks();
        if len == 0 && out.is_null() {
            *n = lm.len();
            return Ok(());
        }
        if out.is_null() {
            return Err(Failure::arg(format!(
                "out is NULL with len {len}: pass NULL and 0 to ask for the count"
            )));
        }
        if len < lm.len() {
            return Err(Failure::arg(format!(
                "the output holds {len} landmarks, there are {}",
                lm.len()
            )));
        }
        // SAFETY: per this function's contract.
        let dst = unsafe { slice_mut(out, lm.len(), "out")? };
        dst.copy_from_slice(lm);
        *n = lm.len();
        Ok(())
    })
}

/// Frees a surface (NULL is fine). Solvers made from it stay valid. Not to be called
/// while another thread uses the surface.
///
/// # Safety
/// `surface` must be NULL or a surface from this library not freed before.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn wavg_surface_free(surface: *mut wavg_surface) {
    if !surface.is_null() {
        // SAFETY: created by Box::into_raw in this library and not freed before.
        let _ = std::panic::catch_unwind(|| drop(unsafe { Box::from_raw(surface) }));
    }
}
