//! The coarse base mesh of semiregular remeshing: polygons (triangles, quads and larger
//! polygons) over 3-D positions, its validation, and the typed errors of remeshing.

use std::collections::HashMap;

use nalgebra::Vector3;
use wavg_solve::SolveError;

/// Largest number of corners of a base polygon.
pub const MAX_POLYGON: usize = 64;

/// A coarse polygon mesh whose vertices lie on or near the surface: the input of
/// [`crate::Remesher`]. Faces list 0-based vertex indices, counter-clockwise.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BaseMesh {
    /// Vertex positions in 3-D (the surface's units).
    pub positions: Vec<Vector3<f64>>,
    /// Polygons with 3 to [`MAX_POLYGON`] corners.
    pub faces: Vec<Vec<u32>>,
}

/// Why a base mesh was refused or remeshing failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RemeshError {
    /// The base has no vertices or no faces.
    #[error("the base mesh is empty ({vertices} vertices, {faces} faces)")]
    EmptyBase {
        /// Number of vertices.
        vertices: usize,
        /// Number of faces.
        faces: usize,
    },
    /// A base vertex has a NaN or infinite coordinate.
    #[error("base vertex {vertex} has a non-finite coordinate")]
    NonFinite {
        /// The vertex.
        vertex: usize,
    },
    /// A face refers to a vertex that does not exist.
    #[error(
        "base face {face} refers to vertex {index} (0-based), but the base has {count} vertices"
    )]
    IndexOutOfRange {
        /// The face.
        face: usize,
        /// The index it holds.
        index: u64,
        /// Number of vertices.
        count: usize,
    },
    /// A face with too few or too many corners, or a repeated corner.
    #[error("base face {face} is unusable: {reason}")]
    BadFace {
        /// The face.
        face: usize,
        /// What is wrong.
        reason: String,
    },
    /// An edge shared by more than two faces, or by two faces of the same orientation.
    #[error(
        "the base mesh is not an oriented manifold: edge ({a}, {b}) {reason} (fix the \
         base's connectivity)"
    )]
    NonManifold {
        /// One end of the edge.
        a: u32,
        /// The other end.
        b: u32,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// A base vertex no face uses.
    #[error("base vertex {vertex} is not used by any face")]
    Unreferenced {
        /// The vertex.
        vertex: usize,
    },
    /// A base vertex too far from the surface to be put on it.
    #[error(
        "base vertex {vertex} is {distance:.4} bounding-box diagonals from the surface (at \
         most {limit} allowed): is the base mesh in the surface's coordinates?"
    )]
    FarFromSurface {
        /// The vertex.
        vertex: usize,
        /// Its distance to the surface over the surface's bounding-box diagonal.
        distance: f64,
        /// The accepted distance, in the same unit.
        limit: f64,
    },
    /// A base vertex index given to an edit does not exist.
    #[error("base vertex {vertex} does not exist ({count} base vertices)")]
    VertexOutOfRange {
        /// The index.
        vertex: usize,
        /// Number of base vertices.
        count: usize,
    },
    /// Malformed OBJ text of a base mesh.
    #[error("line {line}: {message}")]
    Parse {
        /// 1-based line.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A parameter out of its range.
    #[error("invalid parameter: {0}")]
    InvalidParameter(String),
    /// A point of the refined mesh has no weighted average (or a given point is invalid).
    #[error("remeshing failed at {stage}, vertex {vertex}: {source}")]
    Solve {
        /// Which step: `level L` or `smoothing step S`.
        stage: String,
        /// The output vertex.
        vertex: usize,
        /// The solver's answer.
        source: SolveError,
    },
}

impl RemeshError {
    /// True for a base mesh whose connectivity is not a manifold (the rest are bad
    /// values or parameters, or a failed solve).
    pub fn is_invalid_mesh(&self) -> bool {
        matches!(
            self,
            RemeshError::NonManifold { .. }
                | RemeshError::BadFace { .. }
                | RemeshError::Unreferenced { .. }
                | RemeshError::EmptyBase { .. }
        )
    }

    /// True when the input was fine but some weighted average does not exist.
    pub fn is_no_solution(&self) -> bool {
        matches!(self, RemeshError::Solve { source, .. } if source.is_no_solution())
    }
}

/// Whether each vertex lies on a boundary edge (an edge of exactly one face), for faces
/// already known to be manifold.
pub(crate) fn boundary_vertices(n_vertices: usize, faces: &[Vec<u32>]) -> Vec<bool> {
    let mut count: HashMap<(u32, u32), u8> = HashMap::new();
    for f in faces {
        for (a, b) in polygon_edges(f) {
            *count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let mut out = vec![false; n_vertices];
    for ((a, b), c) in count {
        if c == 1 {
            out[a as usize] = true;
            out[b as usize] = true;
        }
    }
    out
}

/// The directed edges of a polygon: `(f[i], f[i+1])`, closing the loop.
pub(crate) fn polygon_edges(f: &[u32]) -> impl Iterator<Item = (u32, u32)> + '_ {
    (0..f.len()).map(move |i| (f[i], f[(i + 1) % f.len()]))
}

impl BaseMesh {
    /// About how many faces `levels` levels of splitting make of this base, counted
    /// before any work: its corners times four per level after the first (the first
    /// level makes `n` quads of a polygon of `n` corners, each later one four faces of
    /// every face).
    pub fn estimated_faces(&self, levels: usize) -> usize {
        let corners: usize = self.faces.iter().map(Vec::len).sum();
        let per_corner = u32::try_from(levels.saturating_sub(1))
            .ok()
            .and_then(|e| 4usize.checked_pow(e))
            .unwrap_or(usize::MAX);
        corners.saturating_mul(per_corner)
    }

    /// Refuses `levels` levels of splitting when they would make more than `max_faces`
    /// faces ([`BaseMesh::estimated_faces`]), a bound on one answer's size; returns the
    /// estimate.
    pub fn check_size(&self, levels: usize, max_faces: usize) -> Result<usize, RemeshError> {
        let faces = self.estimated_faces(levels);
        if faces > max_faces {
            return Err(RemeshError::InvalidParameter(format!(
                "{levels} levels on this base make about {faces} faces, more than \
                 {max_faces}: use fewer levels or a smaller base"
            )));
        }
        Ok(faces)
    }

    /// Checks the base: at least one vertex and face, finite positions, every face with 3
    /// to [`MAX_POLYGON`] distinct in-range corners, every vertex used, and every edge in
    /// at most two faces that traverse it in opposite directions (an oriented manifold
    /// along edges; vertices where two fans touch are accepted).
    pub fn validate(&self) -> Result<(), RemeshError> {
        let n = self.positions.len();
        if n == 0 || self.faces.is_empty() {
            return Err(RemeshError::EmptyBase {
                vertices: n,
                faces: self.faces.len(),
            });
        }
        if let Some(v) = self
            .positions
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(RemeshError::NonFinite { vertex: v });
        }
        let mut used = vec![false; n];
        let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
        for (fi, f) in self.faces.iter().enumerate() {
            if f.len() < 3 || f.len() > MAX_POLYGON {
                return Err(RemeshError::BadFace {
                    face: fi,
                    reason: format!("{} corners (3 to {MAX_POLYGON} allowed)", f.len()),
                });
            }
            for &v in f {
                if v as usize >= n {
                    return Err(RemeshError::IndexOutOfRange {
                        face: fi,
                        index: v.into(),
                        count: n,
                    });
                }
                used[v as usize] = true;
            }
            for (i, &v) in f.iter().enumerate() {
                if f[..i].contains(&v) {
                    return Err(RemeshError::BadFace {
                        face: fi,
                        reason: format!("vertex {v} appears twice"),
                    });
                }
            }
            for (a, b) in polygon_edges(f) {
                if directed.insert((a, b), fi).is_some() {
                    return Err(RemeshError::NonManifold {
                        a,
                        b,
                        reason: "is traversed twice in the same direction (more than two \
                                 faces, or inconsistent orientation)",
                    });
                }
            }
        }
        if let Some(v) = used.iter().position(|u| !u) {
            return Err(RemeshError::Unreferenced { vertex: v });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> BaseMesh {
        BaseMesh {
            positions: vec![
                Vector3::new(0.0, 0.0, 0.0),
                Vector3::new(1.0, 0.0, 0.0),
                Vector3::new(1.0, 1.0, 0.0),
                Vector3::new(0.0, 1.0, 0.0),
                Vector3::new(2.0, 0.0, 0.0),
            ],
            faces: vec![vec![0, 1, 2, 3], vec![1, 4, 2]],
        }
    }

    #[test]
    fn face_estimates_count_corners_times_four_per_later_level_and_bound_answers() {
        let b = square();
        assert_eq!(b.estimated_faces(0), 7);
        assert_eq!(b.estimated_faces(1), 7);
        assert_eq!(b.estimated_faces(3), 7 * 16);
        assert_eq!(b.estimated_faces(usize::MAX), usize::MAX);
        assert_eq!(b.check_size(3, 112).unwrap(), 112);
        let e = b.check_size(3, 111).unwrap_err();
        assert!(matches!(e, RemeshError::InvalidParameter(_)), "{e}");
        assert!(e.to_string().contains("faces, more than 111"), "{e}");
        assert!(!e.is_invalid_mesh());
    }

    #[test]
    fn a_good_base_passes_and_every_defect_is_named() {
        let good = square();
        good.validate().unwrap();
        assert_eq!(
            boundary_vertices(5, &good.faces),
            vec![true, true, true, true, true]
        );
        let with = |f: &dyn Fn(&mut BaseMesh)| {
            let mut b = square();
            f(&mut b);
            b.validate().unwrap_err()
        };
        assert!(matches!(
            with(&|b| b.faces.clear()),
            RemeshError::EmptyBase { .. }
        ));
        assert!(matches!(
            with(&|b| b.positions[2].x = f64::NAN),
            RemeshError::NonFinite { vertex: 2 }
        ));
        assert!(matches!(
            with(&|b| b.faces[1][1] = 9),
            RemeshError::IndexOutOfRange { index: 9, .. }
        ));
        assert!(matches!(
            with(&|b| b.faces[1] = vec![1, 4]),
            RemeshError::BadFace { face: 1, .. }
        ));
        assert!(matches!(
            with(&|b| b.faces[1] = vec![1, 4, 1]),
            RemeshError::BadFace { face: 1, .. }
        ));
        // Same orientation across the shared edge (1, 2).
        assert!(matches!(
            with(&|b| b.faces[1] = vec![2, 4, 1]),
            RemeshError::NonManifold { .. }
        ));
        // A third face on edge (1, 2).
        let e = with(&|b| {
            b.positions.push(Vector3::new(1.0, 0.5, 1.0));
            b.faces.push(vec![1, 2, 5]);
        });
        assert!(matches!(e, RemeshError::NonManifold { .. }) && e.is_invalid_mesh());
        assert!(matches!(
            with(&|b| b.positions.push(Vector3::zeros())),
            RemeshError::Unreferenced { vertex: 5 }
        ));
    }
}
