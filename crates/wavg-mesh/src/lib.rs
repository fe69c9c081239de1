//! Triangle meshes for wavg: storage, connectivity, validation, repair, I/O and geometry.
//!
//! The flow is: load or generate a [`TriMesh`] (any file can be parsed into one, however
//! broken), [`analyze`] it to see its problems and statistics, optionally repair it, then
//! make a [`ValidMesh`] (oriented manifold plus [`Topology`]), the only type later stages take.
//!
//! ```
//! use wavg_mesh::{ValidMesh, procedural};
//! let mesh = ValidMesh::new(procedural::torus(32, 16, 1.0, 0.3)).unwrap();
//! assert_eq!(mesh.topology().genus(), 1);
//! ```

pub mod analyze;
pub mod data;
pub mod error;
pub mod geometry;
pub mod io;
pub mod mesh;
pub mod problem;
pub mod procedural;
pub mod repair;
pub mod topology;
pub mod valid;

pub use analyze::{Analysis, MeshStats, analyze};
pub use error::MeshError;
pub use geometry::SurfacePoint;
pub use mesh::{FaceId, NONE, TexCoords, TriMesh, VertexId};
pub use problem::{Problem, ProblemKind, ValidationReport};
pub use topology::Topology;
pub use valid::ValidMesh;
