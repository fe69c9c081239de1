//! A valid mesh together with its embedding in R^8 (linear inside each face).

use std::sync::Arc;

use wavg_mesh::{SurfacePoint, ValidMesh};

use crate::{ProjectError, Vec8};

/// A valid mesh with per-vertex coordinates in R^8.
///
/// ```
/// use std::sync::Arc;
/// use wavg_mesh::{SurfacePoint, ValidMesh, procedural};
/// use wavg_project::EmbeddedMesh;
/// let mesh = Arc::new(ValidMesh::new(procedural::grid(2, 2, 1.0, 1.0)).unwrap());
/// let emb = EmbeddedMesh::from_positions(mesh.clone());
/// let p = SurfacePoint::at_corner(0, 1);
/// assert_eq!(emb.point(&p).fixed_rows::<3>(0), p.position(&mesh));
/// ```
#[derive(Clone, Debug)]
pub struct EmbeddedMesh {
    mesh: Arc<ValidMesh>,
    coords: Vec<Vec8>,
}

impl EmbeddedMesh {
    /// Checks that there is one finite point per vertex.
    pub fn new(mesh: Arc<ValidMesh>, coords: Vec<Vec8>) -> Result<Self, ProjectError> {
        if coords.len() != mesh.n_vertices() {
            return Err(ProjectError::CoordinateCount {
                expected: mesh.n_vertices(),
                got: coords.len(),
            });
        }
        if let Some(v) = coords.iter().position(|c| !c.iter().all(|x| x.is_finite())) {
            return Err(ProjectError::NonFinite { vertex: v as u32 });
        }
        Ok(Self { mesh, coords })
    }

    /// The 3-D positions, zero-padded to R^8 (a valid embedding: distances are 3-D ones).
    pub fn from_positions(mesh: Arc<ValidMesh>) -> Self {
        let coords = mesh
            .positions
            .iter()
            .map(|p| {
                let mut c = Vec8::zeros();
                c.fixed_rows_mut::<3>(0).copy_from(p);
                c
            })
            .collect();
        Self { mesh, coords }
    }

    /// The mesh.
    pub fn mesh(&self) -> &Arc<ValidMesh> {
        &self.mesh
    }

    /// Embedded coordinates, one per vertex.
    pub fn coords(&self) -> &[Vec8] {
        &self.coords
    }

    /// The three embedded corners of face `f`.
    #[inline]
    pub fn corners(&self, f: usize) -> [Vec8; 3] {
        self.mesh.triangles[f].map(|v| self.coords[v as usize])
    }

    /// Embedded position of a surface point (barycentric interpolation of its corners).
    #[inline]
    pub fn point(&self, p: &SurfacePoint) -> Vec8 {
        let [a, b, c] = self.corners(p.face as usize);
        a * p.bary[0] + b * p.bary[1] + c * p.bary[2]
    }

    /// Mean length of the embedded edges (each interior edge counted twice).
    pub fn mean_edge_length(&self) -> f64 {
        let tris = &self.mesh.triangles;
        if tris.is_empty() {
            return 0.0;
        }
        let mut s = 0.0;
        for f in 0..tris.len() {
            let c = self.corners(f);
            for i in 0..3 {
                s += (c[(i + 1) % 3] - c[i]).norm();
            }
        }
        s / (3 * tris.len()) as f64
    }
}
