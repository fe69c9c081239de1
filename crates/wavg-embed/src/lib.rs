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

pub mod decimate;
pub mod error;
pub mod file;
pub mod geodesic;
pub mod lsmesh;
pub mod mds;
pub mod near_field;
pub mod pipeline;
pub mod quality;
pub use decimate::{DecimateOptions, Decimated, decimate, select_landmarks};
pub use error::{EmbedError, NoProgress, Progress, Stage};
pub use file::{Embedding, EmbeddingParams};
pub use geodesic::{FastMarching, distances_from, landmark_distances};
pub use pipeline::{PrecomputeOptions, Report, StageSeconds, precompute};
