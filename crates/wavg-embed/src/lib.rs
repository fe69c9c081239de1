//! The 8-D embedding precomputation (paper Section 3.5): landmarks by decimation, geodesic
//! distances by fast marching, metric MDS, least-squares-mesh upsampling, and the `.wavg` file.
//!
//! ```
//! use wavg_embed::{NoProgress, PrecomputeOptions, file, precompute};
//! use wavg_mesh::{ValidMesh, procedural};
//! let mesh = ValidMesh::new(procedural::torus(40, 20, 1.0, 0.4)).unwrap();
//! let opts = PrecomputeOptions { landmarks: 60, ..Default::default() };
//! let (embedding, report) = precompute(&mesh, &opts, &NoProgress).unwrap();
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("torus.wavg");
//! file::save(&path, &embedding, &mesh).unwrap();
//! let back = file::load(&path, &mesh).unwrap();
//! assert_eq!(back.coords, embedding.coords);
//! assert_eq!(report.dim, 8);
//! ```

#![deny(unreachable_pub)]
#![forbid(unsafe_code)]

mod checksum;
mod decimate;
mod embedding;
mod error;
pub mod file;
mod geodesic;
mod lsmesh;
mod mds;
pub mod memtrace;
mod pipeline;
mod quality;
mod report;
mod scaled;
mod simd;
mod thin;

// The precomputation and its settings.
pub use decimate::{
    Bounds, DecimateOptions, Decimated, FIRST_PASS_VERTICES, decimate, select_landmarks,
};
pub use mds::MdsOptions;
pub use pipeline::{LANDMARK_ASPECT_RATIO, PrecomputeOptions, THIN_PART_ROUNDS};
pub use report::{Report, StageSeconds};
pub use scaled::precompute;

/// The revision of the precomputation's algorithm: raised whenever a change makes it give
/// other embeddings for the same mesh and options, so that caches keyed on the mesh and the
/// options ([`PrecomputeOptions`]) do not return embeddings of an earlier algorithm.
pub const PRECOMPUTE_REVISION: u32 = 7;

// Its result (saved and loaded by the `file` module).
pub use embedding::{Embedding, EmbeddingParams};

// Geodesic distances.
pub use geodesic::{FastMarching, GeodesicOptions, Workspace, distances_from, landmark_distances};

// Progress, cancellation and errors.
pub use error::{EmbedError, NoProgress, Progress, Stage};

/// The precomputation's individual stages, for this workspace's experiments, benchmarks and
/// tests.
///
/// **Unstable**: not part of the public API; anything here may change or disappear in any
/// release.
#[doc(hidden)]
pub mod internal {
    pub use crate::decimate::decimate_with_snapshots;
    pub use crate::geodesic::near_field::NEAR_FIELD_EDGES;
    pub use crate::lsmesh::{bilaplacian, least_squares_mesh};
    pub use crate::mds::{MdsResult, classical_mds, metric_mds, relative_stress, smacof};
    pub use crate::quality::{Quality, QualityOptions, QualityPairs, geodesic_quality, percentile};
}
