//! The figures of the projection benchmark (`wavg bench project`, whose documentation
//! describes the protocol): with the `serde` feature, its `--json` keys.

/// Speed and accuracy of [`crate::Projector`] on random surface points, and of the global
/// search on the queries that needed it. Times are microseconds per query.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ProjectionBenchReport {
    /// Vertices of the mesh.
    pub vertices: usize,
    /// Faces of the mesh.
    pub faces: usize,
    /// Random queries per test.
    pub queries: usize,
    /// Seconds to build the projector.
    pub init_s: f64,
    /// Memory of the projector per face, in bytes.
    pub bytes_per_face: f64,
    /// Projecting points on the surface: CPU microseconds per query.
    pub onsurface_us: f64,
    /// Fraction of the points on the surface that project back to themselves.
    pub onsurface_self_fraction: f64,
    /// Projecting points offset from the surface: CPU microseconds per query.
    pub offset_us: f64,
    /// Fraction of the offset points checked whose answer equals the brute-force search's.
    pub offset_bruteforce_agree_fraction: f64,
    /// Fraction of the points on the surface that needed the global search.
    pub onsurface_fallback_fraction: f64,
    /// Fraction of the offset points that needed the global search.
    pub offset_fallback_fraction: f64,
    /// Wall microseconds of one global search on the queries that needed it (`None` when
    /// none did).
    pub fallback_us: Option<f64>,
}
