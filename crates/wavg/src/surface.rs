//! [`Surface`]: a validated mesh with its embedding and projector, the one object every
//! question about weighted averages on that mesh starts from.

use std::path::Path;
use std::sync::{Arc, OnceLock};

use nalgebra::Vector3;
use wavg_embed::{Embedding, PrecomputeOptions, Progress, Report};
use wavg_mesh::{SurfacePoint, TriMesh, ValidMesh, VertexId};
use wavg_project::{EmbeddedMesh, Projector, Vec8};
use wavg_solve::{Anchor, Solver};

use crate::error::Result;

/// A validated triangle mesh with its embedding in R^8 and the projector built on it.
///
/// A freshly opened surface embeds every vertex at its own 3-D position (Phong projection
/// onto the mesh itself: useful for tests and for meshes without a precomputed embedding).
/// [`Surface::precompute`] or [`Surface::load_embedding`] replace that by the geodesic
/// embedding the method is about.
///
/// `Surface` is `Send + Sync` and cheap to clone: clones share the mesh, embedding and
/// projector. Changing the embedding of one clone does not affect the others.
///
/// ```
/// use wavg::{NoProgress, PrecomputeOptions, Surface, SurfacePoint};
/// let mut surface = Surface::from_mesh(wavg::mesh::procedural::torus(40, 16, 1.0, 0.35))?;
/// surface.precompute(&PrecomputeOptions { landmarks: 60, ..Default::default() }, &NoProgress)?;
/// let solver = surface.solver(surface.spread_anchors(16, 0)?)?;
/// let w = solver.inverse(&SurfacePoint::new(17, [0.2, 0.3, 0.5]))?;
/// assert_eq!(w.len(), 16);
/// # Ok::<(), wavg::Error>(())
/// ```
#[derive(Clone)]
pub struct Surface {
    inner: Arc<Inner>,
}

/// What an embedding says of itself, without its coordinates
/// ([`Surface::embedding_summary`]): the figures a cached embedding is reported with
/// (serialised with these names).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct EmbeddingSummary {
    /// Number of landmark vertices.
    pub landmarks: usize,
    /// Dimension in use.
    pub dim: usize,
    /// Final MDS stress of the landmark embedding.
    pub stress: f64,
    /// Median relative error of embedding vs geodesic distance (NaN if not measured).
    pub geodesic_rel_err_p50: f64,
    /// 90th percentile of the same (NaN if not measured).
    pub geodesic_rel_err_p90: f64,
}

struct Inner {
    mesh: Arc<ValidMesh>,
    /// The embedding's landmarks and parameters, its coordinates left empty: they are kept
    /// once, in the projector (64 bytes a vertex: 660 MB at 10M vertices). `None` while
    /// the 3-D positions are the embedding.
    embedding: Option<Embedding>,
    /// The whole embedding, its coordinates copied from the projector's when first asked
    /// for ([`Surface::embedding`]).
    whole: OnceLock<Embedding>,
    projector: Arc<Projector>,
}

impl Inner {
    fn new(mesh: Arc<ValidMesh>, embedding: Option<Embedding>, projector: Projector) -> Self {
        Self {
            mesh,
            embedding: embedding.map(|e| Embedding {
                coords: Vec::new(),
                ..e
            }),
            whole: OnceLock::new(),
            projector: Arc::new(projector),
        }
    }
}

/// An embedding's coordinates as the projector keeps them (the same numbers; the
/// allocation is reused, not copied).
fn to_vec8(coords: Vec<[f64; 8]>) -> Vec<Vec8> {
    coords.into_iter().map(Vec8::from).collect()
}

impl Surface {
    /// Loads a mesh file (`.obj`, `.off`, `.ply`, each optionally gzipped as `.gz`; `.gltf`
    /// or `.glb`, `scene.glb#Name` for one of its meshes: [`wavg_mesh::io::load`]) or a
    /// builtin mesh (`builtin:torus`: [`crate::load_mesh`]) and validates it. The
    /// embedding is the 3-D positions until one is computed or loaded.
    pub fn open(path: impl AsRef<Path>) -> Result<Self> {
        Self::from_mesh(crate::load_mesh(path)?)
    }

    /// Reads the mesh file (or builtin mesh) `path`, validates it and builds a surface on
    /// it with the embedding of the `.wavg` file `embedding` when one is given, the
    /// projector built once, on that embedding ([`Surface::from_valid_and_file`]): the
    /// one-call open of a large surface whose embedding was computed before.
    pub fn open_with_embedding(path: impl AsRef<Path>, embedding: Option<&Path>) -> Result<Self> {
        let mesh = ValidMesh::new(crate::load_mesh(path)?)?;
        Self::from_valid_and_file(mesh, embedding)
    }

    /// Validates `mesh` (an oriented manifold without degenerate faces or unreferenced
    /// vertices; see [`ValidMesh::new`]) and builds a surface on it.
    pub fn from_mesh(mesh: TriMesh) -> Result<Self> {
        Self::from_valid(ValidMesh::new(mesh)?)
    }

    /// A surface on an already validated mesh.
    pub fn from_valid(mesh: impl Into<Arc<ValidMesh>>) -> Result<Self> {
        let mesh = mesh.into();
        let projector = Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh.clone())))?;
        Ok(Self {
            inner: Arc::new(Inner::new(mesh, None, projector)),
        })
    }

    /// A surface on an already validated mesh with an embedding computed for it (one
    /// projector build, where [`Surface::from_valid`] then [`Surface::set_embedding`]
    /// build two: the start-up time of a run that reads a cached embedding). The
    /// embedding's coordinates move into the projector: one copy is kept, not two.
    pub fn from_valid_with_embedding(
        mesh: impl Into<Arc<ValidMesh>>,
        mut embedding: Embedding,
    ) -> Result<Self> {
        let mesh = mesh.into();
        embedding
            .validate(mesh.n_vertices())
            .map_err(wavg_embed::EmbedError::InvalidArgument)?;
        let coords = to_vec8(std::mem::take(&mut embedding.coords));
        let emb = EmbeddedMesh::new(mesh.clone(), coords)?;
        let projector = Projector::new(Arc::new(emb))?;
        Ok(Self {
            inner: Arc::new(Inner::new(mesh, Some(embedding), projector)),
        })
    }

    /// A surface on an already validated mesh, with the embedding read from the `.wavg`
    /// file `embedding` when one is given: the projector is built once, on the embedding,
    /// never first on the 3-D positions (at 10M vertices that would be gigabytes).
    pub fn from_valid_and_file(
        mesh: impl Into<Arc<ValidMesh>>,
        embedding: Option<&Path>,
    ) -> Result<Self> {
        let mesh = mesh.into();
        match embedding {
            None => Self::from_valid(mesh),
            Some(path) => {
                let e = wavg_embed::file::load(path, &mesh)?;
                Self::from_valid_with_embedding(mesh, e)
            }
        }
    }

    /// A surface from flat arrays: vertex positions and counter-clockwise triangles
    /// (0-based vertex indices). Out-of-range indices and non-finite coordinates are
    /// reported as an invalid mesh.
    pub fn from_arrays(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<Self> {
        let positions = positions.iter().map(|p| Vector3::from(*p)).collect();
        Self::from_mesh(TriMesh::new(positions, triangles.to_vec()))
    }

    /// Computes the 8-D embedding (landmarks, geodesics, MDS, least-squares mesh) and
    /// uses it from now on. `progress` receives per-stage fractions and can cancel
    /// ([`crate::ErrorKind::Cancelled`]); on any error the surface is unchanged.
    pub fn precompute(
        &mut self,
        options: &PrecomputeOptions,
        progress: &dyn Progress,
    ) -> Result<Report> {
        let (embedding, report) = crate::precompute(&self.inner.mesh, options, progress)?;
        self.set_embedding(embedding)?;
        Ok(report)
    }

    /// [`Surface::precompute`] through an embedding cache ([`crate::embedding_cached`]):
    /// the cache's entry for this mesh and these options when it has one, else computed
    /// and stored there (`cache` `None`: computed in memory). A landmark count of 0 means
    /// the choice of [`crate::default_precompute_options`]. On any error the surface is
    /// unchanged.
    pub fn precompute_cached(
        &mut self,
        options: &PrecomputeOptions,
        cache: Option<&crate::cache::Cache>,
        info: &crate::cache::EntryInfo,
        progress: &dyn Progress,
    ) -> Result<crate::CacheOutcome> {
        let (embedding, outcome) =
            crate::embedding_cached(&self.inner.mesh, options, cache, info, progress)?;
        self.set_embedding(embedding)?;
        Ok(outcome)
    }

    /// Reads a `.wavg` file computed for this mesh (its fingerprint is checked) and uses
    /// it from now on; on any error the surface is unchanged.
    pub fn load_embedding(&mut self, path: impl AsRef<Path>) -> Result<()> {
        let embedding = wavg_embed::file::load(path.as_ref(), &self.inner.mesh)?;
        self.set_embedding(embedding)
    }

    /// Writes the embedding to a `.wavg` file (atomically: a temporary file renamed into
    /// place). Fails when the surface has no computed or loaded embedding.
    pub fn save_embedding(&self, path: impl AsRef<Path>) -> Result<()> {
        let embedding = self.embedding().ok_or_else(|| {
            wavg_embed::EmbedError::InvalidArgument(
                "the surface has no embedding to save: precompute or load one first".into(),
            )
        })?;
        wavg_embed::file::save(path.as_ref(), embedding, &self.inner.mesh)?;
        Ok(())
    }

    /// Uses `embedding` (one point per vertex) from now on; on any error the surface is
    /// unchanged.
    pub fn set_embedding(&mut self, mut embedding: Embedding) -> Result<()> {
        embedding
            .validate(self.inner.mesh.n_vertices())
            .map_err(wavg_embed::EmbedError::InvalidArgument)?;
        let coords = to_vec8(std::mem::take(&mut embedding.coords));
        let emb = EmbeddedMesh::new(self.inner.mesh.clone(), coords)?;
        let projector = Projector::new(Arc::new(emb))?;
        self.inner = Arc::new(Inner::new(
            self.inner.mesh.clone(),
            Some(embedding),
            projector,
        ));
        Ok(())
    }

    /// The validated mesh.
    pub fn mesh(&self) -> &Arc<ValidMesh> {
        &self.inner.mesh
    }

    /// The computed or loaded embedding; `None` while the 3-D positions serve as one.
    /// Its coordinates are kept once, by the projector ([`Surface::embedded_coords`]):
    /// the first call copies them into the [`Embedding`] returned (64 bytes a vertex),
    /// later calls return the same one. [`Surface::has_embedding`] asks without copying.
    pub fn embedding(&self) -> Option<&Embedding> {
        let meta = self.inner.embedding.as_ref()?;
        Some(self.inner.whole.get_or_init(|| Embedding {
            coords: self.embedded_coords().iter().map(|&c| c.into()).collect(),
            ..meta.clone()
        }))
    }

    /// Whether the surface has a computed or loaded embedding (without
    /// [`Surface::embedding`]'s copy of its coordinates).
    pub fn has_embedding(&self) -> bool {
        self.inner.embedding.is_some()
    }

    /// The computed or loaded embedding's landmark count, dimension and quality figures,
    /// without [`Surface::embedding`]'s copy of its coordinates; `None` while the 3-D
    /// positions serve as one.
    pub fn embedding_summary(&self) -> Option<EmbeddingSummary> {
        self.inner.embedding.as_ref().map(|e| EmbeddingSummary {
            landmarks: e.landmarks.len(),
            dim: e.dim,
            stress: e.stress,
            geodesic_rel_err_p50: e.geodesic_rel_err_p50,
            geodesic_rel_err_p90: e.geodesic_rel_err_p90,
        })
    }

    /// Every vertex's point in R^8 (3-D positions padded with zeros when there is no
    /// embedding).
    pub fn embedded_coords(&self) -> &[Vec8] {
        self.inner.projector.embedded().coords()
    }

    /// The landmark vertices of the embedding (empty when there is none).
    pub fn landmarks(&self) -> &[u32] {
        self.inner
            .embedding
            .as_ref()
            .map_or(&[], |e| e.landmarks.as_slice())
    }

    /// The Phong projector over the embedding (for projecting arbitrary points of R^8).
    pub fn projector(&self) -> &Arc<Projector> {
        &self.inner.projector
    }

    /// Number of vertices.
    pub fn n_vertices(&self) -> usize {
        self.inner.mesh.n_vertices()
    }

    /// Number of triangles.
    pub fn n_faces(&self) -> usize {
        self.inner.mesh.n_faces()
    }

    /// The surface point at vertex `v` (a corner of one of its faces).
    pub fn vertex_point(&self, v: VertexId) -> Result<SurfacePoint> {
        Ok(wavg_solve::vertex_point(&self.inner.mesh, v)?)
    }

    /// The 3-D position of a surface point (its face and barycentrics are checked).
    pub fn position(&self, p: &SurfacePoint) -> Result<Vector3<f64>> {
        let p = wavg_solve::check_point(&self.inner.mesh, p)?;
        Ok(p.position(&self.inner.mesh))
    }

    /// The Euclidean distance in the embedding from `source` (a vertex id or a surface
    /// point, checked) to every vertex: an approximation of the geodesic distance, the
    /// distance field of `wavg serve`'s `/api/distance`.
    pub fn embedding_distances(&self, source: impl Into<Anchor>) -> Result<Vec<f64>> {
        let p = wavg_solve::resolve_anchor(&self.inner.mesh, &source.into())?;
        let coords = self.embedded_coords();
        let tri = self.inner.mesh.triangles[p.face as usize];
        let at = (0..3).fold(Vec8::zeros(), |acc, k| {
            acc + coords[tri[k] as usize] * p.bary[k]
        });
        Ok(coords.iter().map(|c| (c - at).norm()).collect())
    }

    /// A solver of forward and inverse problems for these anchors (vertex ids, surface
    /// points or [`Anchor`]s; each is validated). The solver shares this surface's
    /// projector and keeps working if the surface later changes its embedding.
    pub fn solver<A: Into<Anchor>>(&self, anchors: impl IntoIterator<Item = A>) -> Result<Solver> {
        Ok(Solver::new(
            self.inner.projector.clone(),
            anchors.into_iter().map(Into::into),
        )?)
    }
}

impl std::fmt::Debug for Surface {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Surface")
            .field("vertices", &self.n_vertices())
            .field("faces", &self.n_faces())
            .field("embedded", &self.has_embedding())
            .finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wavg_embed::NoProgress;

    /// An embedding given to a surface moves into the projector (same allocation, no
    /// second copy); the whole [`Embedding`] is assembled only when asked for, with the
    /// same numbers.
    #[test]
    fn an_embedding_is_kept_once_until_asked_for() {
        let mesh = ValidMesh::new(wavg_mesh::procedural::torus(32, 12, 1.0, 0.35)).unwrap();
        let opts = PrecomputeOptions {
            landmarks: 40,
            ..Default::default()
        };
        let (e, _) = crate::precompute(&mesh, &opts, &NoProgress).unwrap();
        let given = e.clone();
        let at = given.coords.as_ptr() as usize;
        let s = Surface::from_valid_with_embedding(mesh, given).unwrap();
        assert_eq!(
            s.embedded_coords().as_ptr() as usize,
            at,
            "moved, not copied"
        );
        assert!(s.has_embedding());
        let summary = s.embedding_summary().unwrap();
        assert_eq!(
            (summary.landmarks, summary.dim, summary.stress),
            (e.landmarks.len(), e.dim, e.stress)
        );
        assert_eq!(
            summary.geodesic_rel_err_p90.to_bits(),
            e.geodesic_rel_err_p90.to_bits()
        );
        assert!(s.inner.whole.get().is_none(), "nothing copied yet");
        assert!(s.inner.embedding.as_ref().unwrap().coords.is_empty());
        assert_eq!(s.landmarks(), e.landmarks.as_slice());
        assert_eq!(s.embedding(), Some(&e));
        assert!(s.inner.whole.get().is_some());
        assert!(std::ptr::eq(s.embedding().unwrap(), s.embedding().unwrap()));
        let plain = Surface::from_valid(s.mesh().clone()).unwrap();
        assert!(!plain.has_embedding() && plain.embedding().is_none());
        assert!(plain.embedding_summary().is_none());
    }

    /// The coordinates' allocation is reused when they move into the projector.
    #[test]
    fn coordinates_move_without_a_copy() {
        let coords = vec![[1.0; 8]; 1000];
        let at = coords.as_ptr() as usize;
        let v = to_vec8(coords);
        assert_eq!(v.as_ptr() as usize, at);
        assert_eq!(v[999], Vec8::from([1.0; 8]));
    }
}
