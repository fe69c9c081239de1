//! The validated mesh that every later stage takes.

use crate::analyze::{MeshStats, analyze};
use crate::error::MeshError;
use crate::mesh::TriMesh;
use crate::topology::Topology;

/// A mesh that passed validation: an oriented 2-manifold (boundaries allowed) with
/// finite coordinates, no degenerate, duplicate or out-of-range faces and no unreferenced
/// vertices, together with its [`Topology`].
///
/// Later stages (projection, embedding, solvers) only accept this type, so a broken mesh
/// is never handed to them.
///
/// ```
/// use wavg_mesh::{ValidMesh, procedural};
/// let m = ValidMesh::new(procedural::icosphere(2)).unwrap();
/// assert_eq!(m.topology().genus(), 0);
/// ```
#[derive(Clone, Debug)]
pub struct ValidMesh {
    mesh: TriMesh,
    topology: Topology,
    stats: MeshStats,
}

impl ValidMesh {
    /// Validates `mesh`; the error lists every defect found.
    pub fn new(mesh: TriMesh) -> Result<Self, MeshError> {
        let a = analyze(&mesh);
        match a.topology {
            Some(topology) => Ok(Self {
                mesh,
                topology,
                stats: a.stats,
            }),
            None => Err(MeshError::Invalid(Box::new(a.report))),
        }
    }

    /// The underlying mesh.
    pub fn mesh(&self) -> &TriMesh {
        &self.mesh
    }

    /// The connectivity.
    pub fn topology(&self) -> &Topology {
        &self.topology
    }

    /// Counts computed during validation.
    pub fn stats(&self) -> &MeshStats {
        &self.stats
    }

    /// Gives back the mesh.
    pub fn into_mesh(self) -> TriMesh {
        self.mesh
    }

    /// Number of vertices.
    pub fn n_vertices(&self) -> usize {
        self.mesh.n_vertices()
    }

    /// Number of faces.
    pub fn n_faces(&self) -> usize {
        self.mesh.n_faces()
    }
}

impl std::ops::Deref for ValidMesh {
    type Target = TriMesh;
    fn deref(&self) -> &TriMesh {
        &self.mesh
    }
}
