//! wavg: weighted averages of points on triangle meshes (Panozzo, Baran, Diamanti and
//! Sorkine-Hornung, "Weighted Averages on Surfaces", SIGGRAPH 2013).
//!
//! This facade re-exports the public API of the workspace crates.
//!
//! ```
//! use wavg::mesh::{ValidMesh, procedural};
//! let m = ValidMesh::new(procedural::icosphere(2)).unwrap();
//! assert_eq!(m.n_vertices(), 162);
//! ```

pub use wavg_embed as embed;
pub use wavg_mesh as mesh;
pub use wavg_mesh::{MeshError, SurfacePoint, TriMesh, ValidMesh};
pub use wavg_project as project;
pub use wavg_solve as solve;
