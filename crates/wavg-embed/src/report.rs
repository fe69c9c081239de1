//! What a precomputation measured: its time per stage and the embedding's errors.

/// Wall-clock seconds per stage.
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct StageSeconds {
    /// Landmark selection.
    pub decimate: f64,
    /// Fast-marching setup and landmark-to-landmark distances.
    pub geodesics: f64,
    /// Classical MDS and SMACOF.
    pub mds: f64,
    /// Least-squares mesh.
    pub lsmesh: f64,
    /// Quality check (0 if skipped).
    pub quality: f64,
}

/// What [`precompute`](crate::precompute) measured. With the `serde` feature it serialises to the keys of
/// `wavg precompute --json` (a NaN error, when not measured, becomes `null` in JSON).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Report {
    /// Total wall-clock seconds.
    pub seconds: f64,
    /// Per stage. Some stages overlap (the decimation with the quality check's fast
    /// marching, the geodesics with the least-squares factorisation), so these can add up
    /// to more than `seconds`.
    pub stages: StageSeconds,
    /// Landmarks used.
    pub landmarks: usize,
    /// Vertices of the mesh the landmark geodesics ran on (the input's own count when no
    /// intermediate mesh was used).
    pub geodesic_mesh_vertices: usize,
    /// Embedding dimension.
    pub dim: usize,
    /// Final MDS stress (RMS relative landmark distance error).
    pub stress: f64,
    /// Stress of the classical-MDS start.
    pub initial_stress: f64,
    /// SMACOF iterations.
    pub mds_iterations: usize,
    /// Whether SMACOF met its tolerance.
    pub mds_converged: bool,
    /// Median relative error of embedding vs geodesic distance (NaN if not measured).
    pub geodesic_rel_err_p50: f64,
    /// 90th percentile of the same.
    pub geodesic_rel_err_p90: f64,
    /// Pairs in the quality check.
    pub quality_pairs: usize,
    /// Mesh vertices.
    pub vertices: usize,
    /// Mesh faces.
    pub faces: usize,
}
