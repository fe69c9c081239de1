//! Errors of the projection crate.

use wavg_mesh::{FaceId, VertexId};

/// Why an embedding could not be used or a point could not be projected.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum ProjectError {
    /// The embedding has a different number of points than the mesh has vertices.
    #[error("embedding has {got} coordinates but the mesh has {expected} vertices")]
    CoordinateCount {
        /// Vertices of the mesh.
        expected: usize,
        /// Coordinates given.
        got: usize,
    },
    /// A vertex's embedded coordinates are NaN or infinite.
    #[error("embedded coordinates of vertex {vertex} are not finite")]
    NonFinite {
        /// The offending vertex.
        vertex: VertexId,
    },
    /// A vertex's embedded coordinates are beyond [`wavg_mesh::MAX_COORDINATE`] in magnitude
    /// (the hierarchy's boxes and bounds are stored in single precision).
    #[error(
        "embedded coordinates of vertex {vertex} reach {value:e}, beyond the supported \
         magnitude of 1e37: scale the mesh down"
    )]
    OutOfRange {
        /// The offending vertex.
        vertex: VertexId,
        /// Its largest coordinate in magnitude.
        value: f64,
    },
    /// The embedded mesh spans less than [`wavg_mesh::MIN_EXTENT`], but not zero (its
    /// squared lengths and areas would leave double precision).
    #[error(
        "the embedded mesh spans only {extent:e}, below the supported size of 1e-60: scale \
         the mesh up"
    )]
    TooSmall {
        /// The longest side of the embedding's bounding box.
        extent: f64,
    },
    /// The mesh has no faces to project onto.
    #[error("the mesh has no faces")]
    EmptyMesh,
    /// The query point is NaN or infinite.
    #[error("the query point is not finite")]
    NonFiniteQuery,
    /// The start vertex is not a vertex of the mesh.
    #[error("start vertex {vertex} is out of range (the mesh has {n_vertices} vertices)")]
    StartOutOfRange {
        /// The given vertex.
        vertex: VertexId,
        /// Vertices of the mesh.
        n_vertices: usize,
    },
    /// A hint face is not a face of the mesh.
    #[error("hint face {face} is out of range (the mesh has {n_faces} faces)")]
    FaceOutOfRange {
        /// The given face.
        face: FaceId,
        /// Faces of the mesh.
        n_faces: usize,
    },
    /// A thread count of zero.
    #[error("the thread count must be at least 1")]
    InvalidThreads,
    /// The threads of a batch could not start.
    #[error("{0}")]
    ThreadPool(String),
    /// No triangle of the mesh has a valid Phong projection of the point.
    #[error("no triangle has a valid Phong projection of the point")]
    NoProjection,
}
