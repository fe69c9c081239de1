//! The raw triangle mesh as parsed or generated, before validation.

use nalgebra::{Vector2, Vector3};

/// Vertex index type used throughout wavg (meshes up to 4 billion vertices).
pub type VertexId = u32;
/// Face (triangle) index type.
pub type FaceId = u32;
/// Sentinel meaning "no face / no vertex" (for example: no neighbour across a boundary edge).
pub const NONE: u32 = u32::MAX;

/// Texture coordinates indexed per face corner, as OBJ stores them.
///
/// Positions are never split at UV seams (geodesics and Laplacians need the welded
/// surface), so a vertex may carry several UVs: `faces[f][c]` indexes `coords` for
/// corner `c` of triangle `f`.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct TexCoords {
    /// The distinct (u, v) values.
    pub coords: Vec<Vector2<f64>>,
    /// Per triangle, the index into `coords` of each corner; same length as the triangles.
    pub faces: Vec<[u32; 3]>,
}

/// A triangle mesh: positions, triangles and optional per-corner texture coordinates.
///
/// `TriMesh` is what parsers and generators produce; it may be broken in any way a file
/// can be. Later stages only accept a [`crate::ValidMesh`], obtained by validation.
///
/// ```
/// use wavg_mesh::TriMesh;
/// use nalgebra::Vector3;
/// let m = TriMesh::new(
///     vec![Vector3::new(0.0, 0.0, 0.0), Vector3::new(1.0, 0.0, 0.0), Vector3::new(0.0, 1.0, 0.0)],
///     vec![[0, 1, 2]],
/// );
/// assert_eq!((m.n_vertices(), m.n_faces()), (3, 1));
/// ```
#[derive(Clone, Debug, PartialEq, Default)]
pub struct TriMesh {
    /// Vertex positions.
    pub positions: Vec<Vector3<f64>>,
    /// Triangles as counter-clockwise vertex index triples (outward normal by the right-hand rule).
    pub triangles: Vec<[VertexId; 3]>,
    /// Optional per-corner texture coordinates.
    pub uv: Option<TexCoords>,
}

impl TriMesh {
    /// A mesh without texture coordinates.
    pub fn new(positions: Vec<Vector3<f64>>, triangles: Vec<[VertexId; 3]>) -> Self {
        Self {
            positions,
            triangles,
            uv: None,
        }
    }

    /// Number of vertices (including unreferenced ones).
    pub fn n_vertices(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles.
    pub fn n_faces(&self) -> usize {
        self.triangles.len()
    }

    /// The three corner positions of triangle `f`. Panics if `f` or its indices are out of range.
    #[inline]
    pub fn corners(&self, f: usize) -> [Vector3<f64>; 3] {
        let t = self.triangles[f];
        [
            self.positions[t[0] as usize],
            self.positions[t[1] as usize],
            self.positions[t[2] as usize],
        ]
    }

    /// Axis-aligned bounding box `(min, max)` of the finite positions; `None` if there are none.
    pub fn bounding_box(&self) -> Option<(Vector3<f64>, Vector3<f64>)> {
        let mut it = self
            .positions
            .iter()
            .filter(|p| p.iter().all(|c| c.is_finite()));
        let first = *it.next()?;
        Some(it.fold((first, first), |(lo, hi), p| (lo.inf(p), hi.sup(p))))
    }

    /// Length of the bounding-box diagonal (0 for an empty mesh): the scale used by
    /// scale-relative tolerances.
    pub fn bounding_box_diagonal(&self) -> f64 {
        self.bounding_box().map_or(0.0, |(lo, hi)| (hi - lo).norm())
    }

    /// Returns the mesh with every position mapped by `f` (for scaling, translating, noise).
    pub fn map_positions(mut self, f: impl Fn(Vector3<f64>) -> Vector3<f64>) -> Self {
        for p in &mut self.positions {
            *p = f(*p);
        }
        self
    }
}
