//! The validated mesh that every later stage takes.

use crate::analyze::{Analysis, MeshStats, analyze};
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
        Self::try_new(mesh).map_err(|r| MeshError::Invalid(Box::new(r.analysis.report)))
    }

    /// Validates `mesh` in one pass of [`analyze`]; a mesh that fails comes back with the
    /// whole analysis (statistics and defects), so that a caller explaining the failure
    /// need not analyse it again.
    ///
    /// ```
    /// use wavg_mesh::{ValidMesh, TriMesh, procedural};
    /// let mut raw = procedural::icosphere(1);
    /// raw.triangles.push(raw.triangles[0]);
    /// let rejected = ValidMesh::try_new(raw).unwrap_err();
    /// assert!(!rejected.analysis.report.is_valid());
    /// assert_eq!(rejected.mesh.n_faces(), rejected.analysis.stats.faces);
    /// ```
    pub fn try_new(mesh: TriMesh) -> Result<Self, Box<Rejected>> {
        let a = analyze(&mesh);
        match a.topology {
            Some(topology) => Ok(Self {
                mesh,
                topology,
                stats: a.stats,
            }),
            None => Err(Box::new(Rejected { mesh, analysis: a })),
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

/// A mesh that failed validation ([`ValidMesh::try_new`]), with its analysis.
#[derive(Clone, Debug)]
pub struct Rejected {
    /// The mesh as given.
    pub mesh: TriMesh,
    /// Its statistics and every defect found (no topology).
    pub analysis: Analysis,
}

impl std::ops::Deref for ValidMesh {
    type Target = TriMesh;
    fn deref(&self) -> &TriMesh {
        &self.mesh
    }
}
