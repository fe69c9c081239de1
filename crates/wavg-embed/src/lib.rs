//! The 8-D embedding precomputation (paper Section 3.5): landmarks by decimation, geodesic
//! distances by fast marching, metric MDS, least-squares-mesh upsampling, and the `.wavg` file.

pub mod decimate;
pub mod error;
pub mod file;
pub mod geodesic;
pub mod lsmesh;
pub mod mds;
pub mod pipeline;
pub mod quality;
pub use error::{EmbedError, NoProgress, Progress, Stage};
pub use file::{Embedding, EmbeddingParams};
