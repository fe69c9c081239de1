//! Plain data shared with C: status codes, surface points, progress stages and callback.

use std::ffi::c_void;

/// Result of every fallible call. `WAVG_STATUS_OK` is 0; every other value is a failure
/// whose message `wavg_last_error()` returns on the same thread.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum wavg_status {
    /// Success.
    WAVG_STATUS_OK = 0,
    /// A NULL pointer, a wrong length, or a value out of range (a face or vertex index,
    /// NaN or infinite weights, weights not summing to 1, bad barycentric coordinates).
    WAVG_STATUS_INVALID_ARGUMENT = 1,
    /// The mesh is not an oriented 2-manifold without degenerate faces (or not suitable,
    /// e.g. not connected for the precomputation).
    WAVG_STATUS_INVALID_MESH = 2,
    /// A file could not be read, parsed or written (missing, corrupt, wrong mesh).
    WAVG_STATUS_IO = 3,
    /// The question is well-formed but has no answer (no valid projection onto the
    /// surface; a point not reached as a weighted average of the anchors).
    WAVG_STATUS_NO_SOLUTION = 4,
    /// The progress callback asked to stop.
    WAVG_STATUS_CANCELLED = 5,
    /// An internal error (a bug in the library); the handles involved stay valid.
    WAVG_STATUS_PANIC = 6,
    /// The computation would need more memory than the machine has available (the
    /// message gives the estimate and the available bytes); refused before it started.
    WAVG_STATUS_OUT_OF_MEMORY = 7,
}

/// A point on the surface: a triangle and barycentric coordinates with respect to its
/// corners, in the order the triangle lists them (non-negative, summing to 1 within 1e-6).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct wavg_point {
    /// 0-based triangle index; `UINT32_MAX` in outputs marks a query without an answer.
    pub face: u32,
    /// Barycentric coordinates (NaN in outputs of a query without an answer).
    pub bary: [f64; 3],
}

impl wavg_point {
    /// The marker written for a query without an answer.
    pub(crate) const NONE: Self = Self {
        face: u32::MAX,
        bary: [f64::NAN; 3],
    };
}

/// Stage of the precomputation, passed to the progress callback.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum wavg_stage {
    /// Landmark selection by decimation.
    WAVG_STAGE_DECIMATE = 0,
    /// Geodesic distances between landmarks.
    WAVG_STAGE_GEODESICS = 1,
    /// Multidimensional scaling of the landmarks.
    WAVG_STAGE_MDS = 2,
    /// Least-squares-mesh extension to every vertex.
    WAVG_STAGE_LSMESH = 3,
    /// Quality check of the embedding.
    WAVG_STAGE_QUALITY = 4,
}

impl From<wavg::Stage> for wavg_stage {
    fn from(s: wavg::Stage) -> Self {
        match s {
            wavg::Stage::Decimate => Self::WAVG_STAGE_DECIMATE,
            wavg::Stage::Geodesics => Self::WAVG_STAGE_GEODESICS,
            wavg::Stage::Mds => Self::WAVG_STAGE_MDS,
            wavg::Stage::LsMesh => Self::WAVG_STAGE_LSMESH,
            wavg::Stage::Quality => Self::WAVG_STAGE_QUALITY,
        }
    }
}

/// Progress callback: `fraction` (0 to 1) of `stage` is done. Return `true` to go on,
/// `false` to cancel (the call then returns `WAVG_STATUS_CANCELLED` soon after and changes
/// nothing). It may be called from any of the library's threads, but never by two at
/// once; it must not call back into the library on the same surface, and must not throw
/// (C++) or longjmp. Stages overlap, so their reports interleave: the quality check's
/// exact distances run alongside the decimation, the least-squares factorisation alongside
/// the geodesics; every stage that runs ends with a report of 1.
pub type wavg_progress_fn =
    Option<unsafe extern "C" fn(stage: wavg_stage, fraction: f64, user_data: *mut c_void) -> bool>;
