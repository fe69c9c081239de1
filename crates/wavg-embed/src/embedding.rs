//! An 8-D embedding of a mesh's vertices with its landmarks and provenance (what a `.wavg`
//! file stores; see [`crate::file`] for the format).

use crate::file::MAX_DIM;

/// The parameters an embedding was computed with (stored for provenance).
#[derive(Clone, Debug, PartialEq)]
pub struct EmbeddingParams {
    /// Number of landmarks requested (the decimation target).
    pub landmarks_requested: u64,
    /// Seed of the random choices (quality pairs, any randomised step).
    pub seed: u64,
    /// SMACOF iteration limit.
    pub mds_max_iterations: u64,
    /// SMACOF relative stress-change tolerance.
    pub mds_tolerance: f64,
    /// Vertex count of the mesh the geodesics were computed on; 0 means the mesh itself.
    pub geodesic_mesh_vertices: u64,
}

impl Default for EmbeddingParams {
    fn default() -> Self {
        Self {
            landmarks_requested: 1000,
            seed: 0,
            mds_max_iterations: 300,
            mds_tolerance: 1e-4,
            geodesic_mesh_vertices: 0,
        }
    }
}

/// An embedding of every mesh vertex into R^`dim` (`dim <= 8`), as stored in a `.wavg` file.
#[derive(Clone, Debug, PartialEq)]
pub struct Embedding {
    /// Dimension in use; entries `dim..8` of every coordinate are zero.
    pub dim: usize,
    /// One point per mesh vertex.
    pub coords: Vec<[f64; MAX_DIM]>,
    /// The landmark vertex ids (distinct), in the order MDS saw them.
    pub landmarks: Vec<u32>,
    /// How it was computed.
    pub params: EmbeddingParams,
    /// Final MDS stress of the landmark embedding.
    pub stress: f64,
    /// Median relative error of embedding vs geodesic distance (NaN if not measured).
    pub geodesic_rel_err_p50: f64,
    /// 90th percentile of the same (NaN if not measured).
    pub geodesic_rel_err_p90: f64,
}

impl Embedding {
    /// The first `dim` coordinates of vertex `v`.
    pub fn point(&self, v: usize) -> &[f64] {
        &self.coords[v][..self.dim]
    }

    /// Checks the invariants the file format requires, for a mesh with `n_vertices`.
    pub fn validate(&self, n_vertices: usize) -> Result<(), String> {
        if self.dim == 0 || self.dim > MAX_DIM {
            return Err(format!("dimension {} is not in 1..={MAX_DIM}", self.dim));
        }
        if self.coords.len() != n_vertices {
            return Err(format!(
                "{} coordinates for a mesh with {n_vertices} vertices",
                self.coords.len()
            ));
        }
        for (v, c) in self.coords.iter().enumerate() {
            if !c[..self.dim].iter().all(|x| x.is_finite()) {
                return Err(format!("vertex {v} has a non-finite coordinate"));
            }
            if c[self.dim..].iter().any(|&x| x != 0.0) {
                return Err(format!(
                    "vertex {v} has non-zero entries beyond dimension {}",
                    self.dim
                ));
            }
        }
        if self.landmarks.len() > n_vertices {
            return Err(format!(
                "{} landmarks for {n_vertices} vertices",
                self.landmarks.len()
            ));
        }
        let mut seen = vec![false; n_vertices];
        for &l in &self.landmarks {
            let slot = seen.get_mut(l as usize).ok_or_else(|| {
                format!("landmark id {l} out of range (mesh has {n_vertices} vertices)")
            })?;
            if std::mem::replace(slot, true) {
                return Err(format!("landmark id {l} appears twice"));
            }
        }
        if !(self.stress.is_finite() && self.stress >= 0.0) {
            return Err(format!(
                "stress {} is not a finite non-negative number",
                self.stress
            ));
        }
        for (name, e) in [
            ("p50", self.geodesic_rel_err_p50),
            ("p90", self.geodesic_rel_err_p90),
        ] {
            if !(e.is_nan() || (e.is_finite() && e >= 0.0)) {
                return Err(format!("geodesic relative error {name} = {e} is invalid"));
            }
        }
        let t = self.params.mds_tolerance;
        if !(t.is_finite() && t >= 0.0) {
            return Err(format!(
                "MDS tolerance {t} is not a finite non-negative number"
            ));
        }
        Ok(())
    }
}
