//! The C ABI of wavg (`libwavg.so`, `libwavg.a`, header `include/wavg.h`).
//!
//! Every entry point is `extern "C"`, checks its pointers and lengths, runs inside a panic
//! boundary (a panic becomes [`wavg_status::WAVG_STATUS_PANIC`], never an abort) and
//! reports failures as a [`wavg_status`] plus a per-thread message ([`wavg_last_error`]).
//! Handles are opaque and owned by the caller from creation to their `_free` call. No Rust
//! type crosses the boundary.
#![allow(non_camel_case_types)]
#![deny(unreachable_pub)]

mod anchors;
mod apps;
mod boundary;
mod decimate;
mod maps;
mod options;
mod remesh;
mod solver;
mod surface;
mod transfer;
mod types;

pub use anchors::wavg_surface_spread_anchors;
pub use apps::wavg_spline;
pub use boundary::{wavg_abi_version, wavg_last_error, wavg_version};
pub use decimate::wavg_surface_decimate;
pub use maps::{wavg_correspond, wavg_correspond_vertices, wavg_decal_uv};
pub use options::{wavg_precompute_options, wavg_precompute_options_default};
pub use remesh::{
    wavg_remesher, wavg_remesher_base_point, wavg_remesher_count, wavg_remesher_free,
    wavg_remesher_get, wavg_remesher_move_vertex, wavg_remesher_new, wavg_remesher_run,
};
pub use solver::{
    wavg_forward, wavg_inverse, wavg_solver, wavg_solver_anchor_count, wavg_solver_free,
    wavg_solver_new, wavg_solver_set_anchor,
};
pub use surface::{
    wavg_surface, wavg_surface_embedding, wavg_surface_face_count, wavg_surface_free,
    wavg_surface_from_arrays, wavg_surface_landmarks, wavg_surface_load_embedding,
    wavg_surface_open, wavg_surface_open_with_embedding, wavg_surface_positions,
    wavg_surface_precompute, wavg_surface_save_embedding, wavg_surface_triangles,
    wavg_surface_vertex_count, wavg_surface_vertex_point,
};
pub use transfer::wavg_transfer_texture;
pub use types::{wavg_point, wavg_progress_fn, wavg_stage, wavg_status};

/// Major version of the library (incompatible API changes).
pub const WAVG_VERSION_MAJOR: u32 = 0;
/// Minor version of the library (additions).
pub const WAVG_VERSION_MINOR: u32 = 1;
/// Patch version of the library (fixes).
pub const WAVG_VERSION_PATCH: u32 = 0;
/// Version of the binary interface, the number in the library's soname
/// (`libwavg.so.0`); compare it with `wavg_abi_version()` at run time.
pub const WAVG_ABI_VERSION: u32 = 0;
