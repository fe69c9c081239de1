//! wavg: weighted averages of points on triangle meshes (Panozzo, Baran, Diamanti and
//! Sorkine-Hornung, "Weighted Averages on Surfaces", SIGGRAPH 2013).
//!
//! Start from a [`Surface`]: a validated mesh with its 8-D embedding. Make a [`Solver`]
//! for a set of anchors, then ask the forward problem (weights to a point) or the inverse
//! problem (a point to weights), one at a time or in parallel batches. Every batch comes
//! in two layers: `*_batch` allocates and runs on the current rayon pool; `*_batch_into`
//! reuses the caller's buffers and takes a [`Par`] (one thread, the current pool, or a
//! pool of `n` threads; [`Par::install`] runs any closure that way).
//!
//! ```
//! use wavg::{ForwardOptions, NoProgress, PrecomputeOptions, Surface, SurfacePoint};
//!
//! // A mesh file (`Surface::open("bunny.obj")`) or, here, one generated in code.
//! let mut surface = Surface::from_mesh(wavg::mesh::procedural::torus(48, 16, 1.0, 0.35))?;
//! // The 8-D embedding: landmarks, geodesics, MDS, least-squares mesh.
//! surface.precompute(&PrecomputeOptions { landmarks: 60, ..Default::default() }, &NoProgress)?;
//! // 24 anchors spread over the surface.
//! let solver = surface.solver(surface.spread_anchors(24, 0)?)?;
//! // Inverse: the weights of a surface point; forward: back to the point.
//! let x = SurfacePoint::new(17, [0.2, 0.3, 0.5]);
//! let w = solver.inverse(&x)?;
//! let back = solver.forward(&w, &ForwardOptions::default())?;
//! assert!((back.position - surface.position(&x)?).norm() < 1e-6);
//! # Ok::<(), wavg::Error>(())
//! ```
//!
//! The workspace crates stay reachable as modules ([`mesh`], [`embed`], [`project`],
//! [`solve`], [`apps`]) for what the front door does not cover: mesh files
//! ([`mesh::io`]), procedural meshes, repair and subdivision ([`mesh::procedural`],
//! [`mesh::repair`], [`mesh::subdivide`]), `.wavg` files ([`embed::file`]) and the
//! applications ([`apps`]); the file formats are [`text`] and [`npy`] (the `wavg-io` crate),
//! and [`lines`] writes answers as their lines.

#![deny(unreachable_pub)]
#![forbid(unsafe_code)]

pub mod anchors;
pub mod cache;
mod decimate;
mod error;
pub mod lines;
mod memory;
mod oneoff;
mod precompute;
mod source;
mod surface;
mod texture;

pub use decimate::Decimation;
pub use error::{Error, ErrorKind, Result};
pub use memory::{
    MEMORY_AVAILABLE_VAR, MemoryShortfall, PEAK_BYTES_BASE, PEAK_BYTES_PER_VERTEX,
    available_memory, precompute_peak_bytes,
};
pub use nalgebra::Vector3;
pub use oneoff::{barycentric_weights, check_weight_rows, weighted_average};
pub use precompute::{
    CacheOutcome, DEFAULT_LANDMARKS, Provenance, check_embeddable, default_precompute_options,
    embedding_cached, precompute, resolve_landmarks,
};
pub use source::{BUILTIN_PREFIX, builtin_name, load_mesh, load_mesh_with_notes};
pub use surface::{EmbeddingSummary, Surface};
pub use texture::mesh_texture;

/// The crate's README (its page on the registry) compiles and runs as written.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeQuickstart;
pub use wavg_embed::{Embedding, NoProgress, PrecomputeOptions, Progress, Report, Stage};
/// The file formats: plain-text surface points and weights, NumPy `.npy` arrays.
pub use wavg_io::{npy, text};
pub use wavg_mesh::{SurfacePoint, TriMesh, ValidMesh, VertexId};
pub use wavg_solve::{
    Anchor, BatchWeights, ForwardOptions, ForwardResult, ForwardScratch, Normalization, Par,
    ProjectionPath, RoundTrip, SearchGoal, SearchMode, Solver, Verified,
};

// The layers' own errors, for callers that tell failures apart before they become an
// [`Error`].
pub use wavg_embed::EmbedError;
pub use wavg_mesh::MeshError;
pub use wavg_solve::SolveError;

// The layer under a [`Solver`]: the mesh embedded in R^8 and its Phong projector.
pub use wavg_solve::{EmbeddedMesh, Projector, Vec8};

// Defaults and checks of the forward and inverse problems' inputs.
pub use wavg_solve::{DEFAULT_GAMMA, DEFAULT_TOLERANCE, resolve_anchor, validate_weights};

// Reports and options of the mesh tools (inspection, repair, subdivision, decimation) and
// texture coordinates.
pub use wavg_embed::DecimateOptions;
/// Renamed to [`DefectKind`] ("problem" names the paper's forward and inverse problems).
#[allow(deprecated)]
pub use wavg_mesh::ProblemKind;
pub use wavg_mesh::{
    DefectKind, LoadNotes, MeshInfo, RepairOptions, RepairReport, SubdivisionReport, TexCoords,
};

/// Seeded sampling of surface points and anchor vertices, as the benchmarks (`wavg-bench`,
/// outside the library) and the demo draw them.
pub use wavg_solve::sampling;

pub use wavg_apps as apps;
pub use wavg_embed as embed;
pub use wavg_mesh as mesh;
pub use wavg_project as project;
pub use wavg_solve as solve;
