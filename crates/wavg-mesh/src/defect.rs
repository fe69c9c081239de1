//! Typed validation defects and the report that groups them.
//!
//! "Defect" names what is wrong with a mesh; "problem" is kept for the paper's forward and
//! inverse problems. Field names and JSON keys (`problems`, `problem_summary`,
//! `remaining_problems`) keep their old spelling: they are a stable interface.

use std::fmt;

use crate::mesh::{FaceId, VertexId};

/// One thing wrong with a mesh, naming the offending index.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Defect {
    /// The mesh has no vertices or no faces.
    #[error("the mesh is empty ({vertices} vertices, {faces} faces)")]
    Empty {
        /// Vertex count.
        vertices: usize,
        /// Face count.
        faces: usize,
    },
    /// A face refers to a vertex that does not exist.
    #[error("face {face} refers to vertex {index}, but there are only {vertex_count} vertices")]
    IndexOutOfRange {
        /// The face.
        face: FaceId,
        /// The bad index.
        index: u32,
        /// Number of vertices in the mesh.
        vertex_count: usize,
    },
    /// A coordinate is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate")]
    NonFiniteCoordinate {
        /// The vertex.
        vertex: VertexId,
    },
    /// A face uses the same vertex twice.
    #[error("face {face} uses a vertex twice")]
    RepeatedIndex {
        /// The face.
        face: FaceId,
    },
    /// A face has (numerically) zero area relative to its size.
    #[error("face {face} has zero area (degenerate or needle)")]
    ZeroAreaFace {
        /// The face.
        face: FaceId,
    },
    /// Two faces use the same three vertices.
    #[error("face {face} duplicates face {first}")]
    DuplicateFace {
        /// The later face.
        face: FaceId,
        /// The earlier face with the same vertices.
        first: FaceId,
    },
    /// An edge with more than two incident faces.
    #[error("edge ({a}, {b}) has {faces} incident faces")]
    NonManifoldEdge {
        /// Smaller vertex of the edge.
        a: VertexId,
        /// Larger vertex of the edge.
        b: VertexId,
        /// Number of incident faces (> 2).
        faces: usize,
    },
    /// A vertex whose incident faces form more than one edge-connected fan.
    #[error("vertex {vertex} is pinched: its faces form {fans} separate fans")]
    NonManifoldVertex {
        /// The vertex.
        vertex: VertexId,
        /// Number of fans (> 1).
        fans: usize,
    },
    /// Two faces sharing an edge traverse it in the same direction.
    #[error("faces {face_a} and {face_b} have inconsistent orientation across edge ({a}, {b})")]
    InconsistentOrientation {
        /// First face.
        face_a: FaceId,
        /// Second face.
        face_b: FaceId,
        /// Smaller vertex of the shared edge.
        a: VertexId,
        /// Larger vertex of the shared edge.
        b: VertexId,
    },
    /// A vertex used by no face.
    #[error("vertex {vertex} is used by no face")]
    UnreferencedVertex {
        /// The vertex.
        vertex: VertexId,
    },
    /// Texture coordinates that do not match the faces.
    #[error("texture coordinates of face {face} are invalid: {reason}")]
    InvalidTexCoords {
        /// The face.
        face: FaceId,
        /// What is wrong.
        reason: String,
    },
}

/// The kinds of [`Defect`], for grouping and counting. With the `serde` feature a kind
/// serialises to its stable snake_case name (`non_manifold_edge`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize),
    serde(rename_all = "snake_case")
)]
pub enum DefectKind {
    /// [`Defect::Empty`]
    Empty,
    /// [`Defect::IndexOutOfRange`]
    IndexOutOfRange,
    /// [`Defect::NonFiniteCoordinate`]
    NonFiniteCoordinate,
    /// [`Defect::RepeatedIndex`]
    RepeatedIndex,
    /// [`Defect::ZeroAreaFace`]
    ZeroAreaFace,
    /// [`Defect::DuplicateFace`]
    DuplicateFace,
    /// [`Defect::NonManifoldEdge`]
    NonManifoldEdge,
    /// [`Defect::NonManifoldVertex`]
    NonManifoldVertex,
    /// [`Defect::InconsistentOrientation`]
    InconsistentOrientation,
    /// [`Defect::UnreferencedVertex`]
    UnreferencedVertex,
    /// [`Defect::InvalidTexCoords`]
    InvalidTexCoords,
}

impl DefectKind {
    /// Short human-readable name, e.g. "non-manifold edges".
    pub fn describe(self) -> &'static str {
        match self {
            Self::Empty => "empty mesh",
            Self::IndexOutOfRange => "face indices out of range",
            Self::NonFiniteCoordinate => "vertices with NaN/inf coordinates",
            Self::RepeatedIndex => "faces with a repeated vertex",
            Self::ZeroAreaFace => "zero-area faces",
            Self::DuplicateFace => "duplicate faces",
            Self::NonManifoldEdge => "non-manifold edges",
            Self::NonManifoldVertex => "non-manifold (pinched) vertices",
            Self::InconsistentOrientation => "edges with inconsistent orientation",
            Self::UnreferencedVertex => "unreferenced vertices",
            Self::InvalidTexCoords => "faces with invalid texture coordinates",
        }
    }

    /// The repair in [`crate::repair`] that fixes this kind, if any.
    pub fn remedy(self) -> Option<&'static str> {
        match self {
            // repair::drop_degenerate_faces also drops faces with out-of-range indices or
            // non-finite corners (the vertices left unused go with the unreferenced ones).
            Self::RepeatedIndex
            | Self::ZeroAreaFace
            | Self::IndexOutOfRange
            | Self::NonFiniteCoordinate => Some("drop degenerate faces"),
            Self::DuplicateFace => Some("drop duplicate faces"),
            Self::UnreferencedVertex => Some("drop unreferenced vertices"),
            Self::NonManifoldEdge | Self::NonManifoldVertex => {
                Some("split non-manifold vertices and edges")
            }
            // A non-orientable surface (a Moebius strip) has no consistent orientation.
            Self::InconsistentOrientation => Some("orient faces (orientable surfaces only)"),
            _ => None,
        }
    }
}

impl Defect {
    /// The kind of this defect.
    pub fn kind(&self) -> DefectKind {
        match self {
            Self::Empty { .. } => DefectKind::Empty,
            Self::IndexOutOfRange { .. } => DefectKind::IndexOutOfRange,
            Self::NonFiniteCoordinate { .. } => DefectKind::NonFiniteCoordinate,
            Self::RepeatedIndex { .. } => DefectKind::RepeatedIndex,
            Self::ZeroAreaFace { .. } => DefectKind::ZeroAreaFace,
            Self::DuplicateFace { .. } => DefectKind::DuplicateFace,
            Self::NonManifoldEdge { .. } => DefectKind::NonManifoldEdge,
            Self::NonManifoldVertex { .. } => DefectKind::NonManifoldVertex,
            Self::InconsistentOrientation { .. } => DefectKind::InconsistentOrientation,
            Self::UnreferencedVertex { .. } => DefectKind::UnreferencedVertex,
            Self::InvalidTexCoords { .. } => DefectKind::InvalidTexCoords,
        }
    }
}

/// All defects found in a mesh. Empty means the mesh is a valid oriented manifold.
///
/// ```
/// use wavg_mesh::{analyze, procedural};
/// let report = analyze(&procedural::icosphere(1)).report;
/// assert!(report.is_valid());
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ValidationReport {
    /// Every defect, grouped by kind in [`DefectKind`] order, ascending index within a kind
    /// (the field keeps its name, a stable interface).
    pub problems: Vec<Defect>,
}

/// Count and first examples of one kind of defect.
#[derive(Clone, Debug, PartialEq)]
pub struct DefectSummary {
    /// The kind.
    pub kind: DefectKind,
    /// How many defects of this kind.
    pub count: usize,
    /// The first few (at most 5).
    pub examples: Vec<Defect>,
}

impl ValidationReport {
    /// True when no defect was found.
    pub fn is_valid(&self) -> bool {
        self.problems.is_empty()
    }

    /// Number of defects of one kind.
    pub fn count(&self, kind: DefectKind) -> usize {
        self.problems.iter().filter(|p| p.kind() == kind).count()
    }

    /// Defects grouped by kind, with counts and the first five examples.
    pub fn summary(&self) -> Vec<DefectSummary> {
        let mut out: Vec<DefectSummary> = Vec::new();
        for p in &self.problems {
            match out.iter_mut().find(|s| s.kind == p.kind()) {
                Some(s) => {
                    s.count += 1;
                    if s.examples.len() < 5 {
                        s.examples.push(p.clone());
                    }
                }
                None => out.push(DefectSummary {
                    kind: p.kind(),
                    count: 1,
                    examples: vec![p.clone()],
                }),
            }
        }
        out.sort_by_key(|s| s.kind);
        out
    }

    /// One line per kind: `"3 non-manifold edges, e.g. edge (1, 2) has 3 incident faces; ..."`.
    pub fn lines(&self) -> Vec<String> {
        self.summary()
            .iter()
            .map(|s| {
                let ex: Vec<String> = s.examples.iter().map(|e| e.to_string()).collect();
                format!("{} {}: {}", s.count, s.kind.describe(), ex.join("; "))
            })
            .collect()
    }
}

impl fmt::Display for ValidationReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_valid() {
            return write!(f, "valid");
        }
        write!(f, "invalid mesh: {}", self.lines().join(" | "))
    }
}
