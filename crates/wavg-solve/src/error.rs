//! The crate's error type: every malformed input and every "no answer" is a variant.

/// Everything the solvers can refuse or fail to do.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolveError {
    /// A weight vector's length differs from the number of anchors.
    #[error("expected {expected} weights (one per anchor), got {got}")]
    WeightCount {
        /// Number of anchors.
        expected: usize,
        /// Number of weights given.
        got: usize,
    },
    /// A weight is NaN or infinite. The message counts weights from 1 (the first is
    /// weight 1), as every message that names a position in a list does, in every door.
    #[error("weight {} is not finite ({value})", index + 1)]
    NonFiniteWeight {
        /// Index of the weight (0-based).
        index: usize,
        /// Its value.
        value: f64,
    },
    /// The weights do not sum to 1 (and normalisation was not requested).
    #[error(
        "weights sum to {}, not 1 (tolerance {tolerance:e}; normalisation not requested)",
        short(*.sum)
    )]
    WeightSum {
        /// The sum.
        sum: f64,
        /// The accepted deviation from 1.
        tolerance: f64,
    },
    /// Normalisation was requested but the weights sum to (almost) zero for their size
    /// (at most 1e-12 of the sum of their magnitudes), or overflow.
    #[error("{}", zero_sum(*.sum))]
    ZeroWeightSum {
        /// The sum.
        sum: f64,
    },
    /// The anchor set is empty.
    #[error("the anchor set is empty")]
    NoAnchors,
    /// An anchor index does not exist.
    #[error("anchor {index} does not exist ({count} anchors)")]
    AnchorOutOfRange {
        /// The index.
        index: usize,
        /// Number of anchors.
        count: usize,
    },
    /// A vertex index is out of range.
    #[error("vertex {vertex} is out of range (mesh has {count} vertices)")]
    VertexOutOfRange {
        /// The vertex.
        vertex: u64,
        /// Number of vertices.
        count: usize,
    },
    /// A face index is out of range.
    #[error("face {face} is out of range (mesh has {count} faces)")]
    FaceOutOfRange {
        /// The face.
        face: u64,
        /// Number of faces.
        count: usize,
    },
    /// Barycentric coordinates that are not finite, clearly negative, or do not sum to 1.
    #[error("bad barycentric coordinates {bary:?} on face {face}: {reason}")]
    BadBarycentrics {
        /// The face.
        face: u32,
        /// The coordinates.
        bary: [f64; 3],
        /// What is wrong.
        reason: &'static str,
    },
    /// No point of the surface is a weighted average for these weights: the averaged point
    /// has no valid Phong projection onto any triangle.
    #[error(
        "no weighted average exists for these weights (no Phong projection of the averaged point)"
    )]
    NoWeightedAverage,
    /// The inverse problem's constraints cannot be met: the anchors do not surround the
    /// point in its tangent plane (for example fewer than three anchors, or all on a line).
    #[error("no weights reproduce this point: the anchors' constraint matrix is singular")]
    DegenerateAnchors,
    /// A parameter is out of its valid range.
    #[error("invalid parameter: {0}")]
    InvalidParameter(String),
    /// The tangent plane at a point is degenerate (its rows do not span a plane).
    #[error("degenerate tangent plane at the point")]
    DegenerateTangentPlane,
    /// An error from the projection layer other than "no projection".
    #[error("projection failed: {0}")]
    Project(#[from] wavg_project::ProjectError),
}

impl SolveError {
    /// True when the question was well-formed but has no answer (no weighted average, no
    /// weights for the point), as opposed to malformed input.
    pub fn is_no_solution(&self) -> bool {
        matches!(
            self,
            SolveError::NoWeightedAverage
                | SolveError::DegenerateAnchors
                | SolveError::DegenerateTangentPlane
                | SolveError::Project(wavg_project::ProjectError::NoProjection)
        )
    }
}

/// `x` for a message: plain decimals between 1e-4 and 1e6, else scientific notation (a sum
/// of 1e-320 would otherwise print 320 digits).
/// The message of [`SolveError::ZeroWeightSum`].
fn zero_sum(sum: f64) -> String {
    if sum.is_finite() {
        format!(
            "weights sum to {}, (almost) zero for their size (at most 1e-12 of the sum of \
             their magnitudes): cannot normalise",
            short(sum)
        )
    } else {
        format!("the weights' sum overflows ({sum}): cannot normalise")
    }
}

fn short(x: f64) -> String {
    if x == 0.0 || (1e-4..1e6).contains(&x.abs()) || !x.is_finite() {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}
