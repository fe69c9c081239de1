//! Applications of weighted averages on surfaces (paper Section 4), as library functions
//! over a [`wavg_solve::Solver`]: splines on surfaces (B-splines of any degree, open or
//! closed, and Bézier curves) whose samples are forward problems warm-started along the
//! curve; maps between surfaces (correspondence with a validity test, morphing) and on a
//! surface (decals), and their distortion (symmetrised L2 stretch, flipped faces);
//! semiregular remeshing of a coarse polygon mesh with Laplacian smoothing on the
//! surface ([`Remesher`]), every new point a forward problem over its own few points.
#![forbid(unsafe_code)]
#![deny(unreachable_pub)]

mod basis;
mod remesh;
mod spline;

pub use basis::{SplineKind, spline_weights, spline_weights_flat};
pub use remesh::{
    BaseMesh, DEFAULT_CAGE_VERTICES, DEFAULT_LEVELS, DEFAULT_MAX_BASE_DISTANCE,
    DEFAULT_SMOOTH_STEPS, MAX_CAGE_VERTICES, MAX_LEVELS, MAX_POLYGON, MAX_SMOOTH_STEPS,
    MIN_CAGE_VERTICES, RemeshError, RemeshReport, RemeshResult, Remesher, check_max_base_distance,
    default_cage_vertices, max_cage_vertices, polygons_to_obj,
};
pub use spline::{
    Curve, CurveReport, DEFAULT_SPLINE_DEGREE, DEFAULT_SPLINE_SAMPLES, SPLINE_CHUNK,
    evaluate_spline,
};

mod correspond;
mod ground_truth;
mod local_test;
mod metrics;

pub use correspond::{
    CorrespondOptions, CorrespondTimings, Correspondence, Mapped, ROUND_TRIP_TOLERANCE,
    ReasonCounts, Validity, ValidityTest, correspond_vertices, map_points, vertex_points,
};
pub use ground_truth::{ErrorStats, GroundTruthErrors, WRONG_ERROR};
pub use metrics::{Distortion, distortion};

/// Internals for the benchmarks and experiments of this workspace.
///
/// **Unstable**: not part of the public API; anything here may change or disappear in any
/// release.
#[doc(hidden)]
pub mod internal {
    pub use crate::local_test::{NEIGHBOURHOOD, NEIGHBOURHOOD_VERTICES, inconsistent_vertices};
}

mod decal;
mod decal_obj;
mod morph;

pub use decal::{
    DEFAULT_MAX_NEGATIVE, Decal, DecalReport, DecalUv, check_max_negative, decal_uv,
    decal_vertex_uv, decal_vertices,
};
pub use decal_obj::{DECAL_MATERIAL, PLAIN_MATERIAL, untextured_faces, write_decal_obj};
pub use morph::{MorphReport, harmonic_fill, morph_frames};
mod error;
mod gltf_out;
mod render;
mod transfer;

pub use error::AppError;
pub use gltf_out::{
    MAX_GLTF_FACE, correspondence_scene, curve_scene, curves_scene, decal_scene, morph_scene,
    polygons_scene, textured_scene, validity_code,
};
pub use render::{
    Camera, Colouring, FOV_DEGREES, Image, MAX_DECODED_BYTES, MAX_SIDE, Overlays, RenderOptions,
    RenderReport, View, render, viridis,
};
pub use transfer::{
    MAX_STRIDE, TextureTransfer, TransferOptions, check_uv, dilate, rasterize_uv, transfer_texture,
    transfer_texture_with_uv,
};
