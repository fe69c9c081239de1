//! Anchor sets: the points being averaged, with their embedded coordinates precomputed.
//! Adding, moving and removing an anchor costs O(1), O(1) and O(number of anchors), so
//! anchors can be edited interactively.

use std::sync::Arc;

use wavg_mesh::{SurfacePoint, VertexId};

use crate::error::SolveError;
use crate::kernel::AnchorCoords;
use crate::points::{Anchor, nearest_corner, resolve_anchor};
use crate::{EmbeddedMesh, Vec8};

/// An ordered set of anchors on one embedded mesh. Weights refer to anchors by position
/// in this order.
///
/// ```
/// use std::sync::Arc;
/// use wavg_mesh::{SurfacePoint, ValidMesh, procedural};
/// use wavg_solve::{Anchor, AnchorSet, EmbeddedMesh};
/// let mesh = Arc::new(ValidMesh::new(procedural::icosphere(2)).unwrap());
/// let emb = Arc::new(EmbeddedMesh::from_positions(mesh));
/// let mut a = AnchorSet::new(emb);
/// a.push(Anchor::Vertex(0)).unwrap();
/// a.push(Anchor::Point(SurfacePoint::new(5, [0.2, 0.3, 0.5]))).unwrap();
/// a.set(0, Anchor::Vertex(7)).unwrap();
/// assert_eq!(a.remove(1).unwrap(), Anchor::Point(SurfacePoint::new(5, [0.2, 0.3, 0.5])));
/// assert_eq!(a.len(), 1);
/// assert!(a.push(Anchor::Vertex(100_000)).is_err());
/// ```
#[derive(Clone)]
pub struct AnchorSet {
    emb: Arc<EmbeddedMesh>,
    anchors: Vec<Anchor>,
    points: Vec<SurfacePoint>,
    starts: Vec<VertexId>,
    coords: AnchorCoords,
}

impl AnchorSet {
    /// An empty set on `emb`.
    pub fn new(emb: Arc<EmbeddedMesh>) -> Self {
        Self {
            emb,
            anchors: Vec::new(),
            points: Vec::new(),
            starts: Vec::new(),
            coords: AnchorCoords::new(),
        }
    }

    /// A set holding `anchors` in order (the first invalid one is an error).
    pub fn with_anchors(
        emb: Arc<EmbeddedMesh>,
        anchors: impl IntoIterator<Item = Anchor>,
    ) -> Result<Self, SolveError> {
        let mut s = Self::new(emb);
        for a in anchors {
            s.push(a)?;
        }
        Ok(s)
    }

    /// The embedded mesh the anchors live on.
    pub fn embedded(&self) -> &Arc<EmbeddedMesh> {
        &self.emb
    }

    /// Number of anchors.
    pub fn len(&self) -> usize {
        self.anchors.len()
    }

    /// Whether the set is empty.
    pub fn is_empty(&self) -> bool {
        self.anchors.is_empty()
    }

    /// The anchors as given (after validation).
    pub fn anchors(&self) -> &[Anchor] {
        &self.anchors
    }

    fn check_index(&self, i: usize) -> Result<(), SolveError> {
        if i < self.len() {
            Ok(())
        } else {
            Err(SolveError::AnchorOutOfRange {
                index: i,
                count: self.len(),
            })
        }
    }

    /// Validates `a` and computes what is cached about it.
    fn prepare(&self, a: &Anchor) -> Result<(Anchor, SurfacePoint, VertexId, Vec8), SolveError> {
        let mesh = self.emb.mesh();
        let p = resolve_anchor(mesh, a)?;
        let (a, start, y) = match *a {
            Anchor::Vertex(v) => (*a, v, self.emb.coords()[v as usize]),
            Anchor::Point(_) => (
                Anchor::Point(p),
                nearest_corner(mesh, &p),
                self.emb.point(&p),
            ),
        };
        Ok((a, p, start, y))
    }

    /// Appends an anchor; returns its index.
    pub fn push(&mut self, a: Anchor) -> Result<usize, SolveError> {
        let (a, p, s, y) = self.prepare(&a)?;
        self.anchors.push(a);
        self.points.push(p);
        self.starts.push(s);
        self.coords.push(&y);
        Ok(self.len() - 1)
    }

    /// Moves anchor `i` to `a`.
    pub fn set(&mut self, i: usize, a: Anchor) -> Result<(), SolveError> {
        self.check_index(i)?;
        let (a, p, s, y) = self.prepare(&a)?;
        self.anchors[i] = a;
        self.points[i] = p;
        self.starts[i] = s;
        self.coords.set(i, &y);
        Ok(())
    }

    /// Removes anchor `i` (later anchors shift down by one) and returns it.
    pub fn remove(&mut self, i: usize) -> Result<Anchor, SolveError> {
        self.check_index(i)?;
        self.points.remove(i);
        self.starts.remove(i);
        self.coords.remove(i);
        Ok(self.anchors.remove(i))
    }

    /// Anchor `i` as a surface point.
    pub fn point(&self, i: usize) -> Result<SurfacePoint, SolveError> {
        self.check_index(i)?;
        Ok(self.points[i])
    }

    /// Anchor `i`'s embedded coordinates `y_i`.
    pub fn embedded_point(&self, i: usize) -> Result<Vec8, SolveError> {
        self.check_index(i)?;
        Ok(self.coords.get(i))
    }

    /// The vertex a forward search starts from when anchor `i` has the highest weight.
    pub fn start_vertex(&self, i: usize) -> Result<VertexId, SolveError> {
        self.check_index(i)?;
        Ok(self.starts[i])
    }

    pub(crate) fn starts(&self) -> &[VertexId] {
        &self.starts
    }

    /// The embedded coordinates, structure of arrays.
    pub fn coords(&self) -> &AnchorCoords {
        &self.coords
    }
}

impl std::fmt::Debug for AnchorSet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AnchorSet")
            .field("anchors", &self.anchors)
            .finish_non_exhaustive()
    }
}
