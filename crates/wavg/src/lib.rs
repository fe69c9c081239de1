//! wavg: weighted averages of points on triangle meshes (Panozzo, Baran, Diamanti and
//! Sorkine-Hornung, "Weighted Averages on Surfaces", SIGGRAPH 2013).
//!
//! This facade re-exports the public API of the workspace crates: [`mesh`] (load,
//! validate, repair, topology, geometry), [`embed`] (the 8-D embedding and `.wavg` files),
//! [`project`] (Phong projection) and [`solve`] (forward and inverse problems).
//!
//! The whole flow, from a mesh to weights and back:
//!
//! ```
//! use std::sync::Arc;
//! use wavg::embed::{NoProgress, pipeline::{PrecomputeOptions, precompute}};
//! use wavg::mesh::{SurfacePoint, ValidMesh, procedural};
//! use wavg::project::{EmbeddedMesh, Projector, Vec8};
//! use wavg::solve::sampling::{FpsMetric, farthest_point_vertices};
//! use wavg::solve::{Anchor, ForwardOptions, Solver};
//!
//! // A valid mesh (or `wavg::mesh::io::load(path)` then `ValidMesh::new`).
//! let mesh = Arc::new(ValidMesh::new(procedural::torus(48, 16, 1.0, 0.35)).unwrap());
//! // The 8-D embedding: landmarks, geodesics, MDS, least-squares mesh.
//! let opts = PrecomputeOptions { landmarks: 60, ..PrecomputeOptions::default() };
//! let (embedding, _report) = precompute(&mesh, &opts, &NoProgress).unwrap();
//! let coords = embedding.coords.iter().map(|c| Vec8::from(*c)).collect();
//! let emb = Arc::new(EmbeddedMesh::new(mesh.clone(), coords).unwrap());
//! let projector = Arc::new(Projector::new(emb).unwrap());
//! // 24 anchors spread over the surface by farthest-point sampling.
//! let anchors = farthest_point_vertices(&mesh, 24, 0, FpsMetric::EdgeGraph).unwrap();
//! let solver = Solver::new(projector, anchors.into_iter().map(Anchor::Vertex)).unwrap();
//! // Inverse: weights of a surface point; forward: back to the point.
//! let x = SurfacePoint::new(17, [0.2, 0.3, 0.5]);
//! let w = solver.inverse(&x).unwrap();
//! assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-9);
//! let back = solver.forward(&w, &ForwardOptions::default()).unwrap();
//! assert!((back.position - x.position(&mesh)).norm() < 1e-6);
//! ```

pub use wavg_embed as embed;
pub use wavg_mesh as mesh;
pub use wavg_mesh::{MeshError, SurfacePoint, TriMesh, ValidMesh};
pub use wavg_project as project;
pub use wavg_solve as solve;
