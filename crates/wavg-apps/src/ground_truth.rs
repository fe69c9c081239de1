//! A correspondence between two meshes that share connectivity (poses of one mesh)
//! measured against the ground truth: vertex `i` of the source should land on vertex `i`
//! of the target.

use wavg_mesh::ValidMesh;

use crate::correspond::{Correspondence, Validity};
use crate::error::AppError;

/// Count, mean, 95th percentile and maximum of a list of errors (all 0 when it is empty);
/// with the `serde` feature, keyed by the field names.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ErrorStats {
    /// Number of errors.
    pub count: usize,
    /// Their mean.
    pub mean: f64,
    /// The error at rank `floor(0.95 count)` in increasing order (the last one when that
    /// is past the end).
    pub p95: f64,
    /// The largest.
    pub max: f64,
}

impl ErrorStats {
    /// The statistics of `errors` (NaNs sort last).
    pub fn of(mut errors: Vec<f64>) -> Self {
        errors.sort_by(f64::total_cmp);
        let n = errors.len();
        if n == 0 {
            return Self::default();
        }
        Self {
            count: n,
            mean: errors.iter().sum::<f64>() / n as f64,
            p95: errors[((n as f64 * 0.95) as usize).min(n - 1)],
            max: errors[n - 1],
        }
    }
}

/// An image farther than this from the truth, in bounding-box diagonals of the target,
/// is wrong (for [`GroundTruthErrors::accepted_wrong`] and
/// [`GroundTruthErrors::rejected_correct`]).
pub const WRONG_ERROR: f64 = 0.02;

/// Errors of a map's images against the ground truth, in bounding-box diagonals of the
/// target, and how well the validity test separates right images from wrong ones; with
/// the `serde` feature, keyed by the field names.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct GroundTruthErrors {
    /// Over the valid vertices.
    pub valid: ErrorStats,
    /// Over every vertex with an image, valid or not.
    pub answered: ErrorStats,
    /// Vertices with an image within [`WRONG_ERROR`] of the truth that the test rejected.
    pub rejected_correct: usize,
    /// Valid vertices whose image is farther than [`WRONG_ERROR`] from the truth.
    pub accepted_wrong: usize,
}

impl Correspondence {
    /// How far each image lands from the vertex of the same index on `target`, when
    /// `source` and `target` share connectivity (else [`AppError::Input`]).
    ///
    /// ```
    /// use wavg_apps::ErrorStats;
    /// let s = ErrorStats::of(vec![0.3, 0.1, 0.2]);
    /// assert_eq!((s.count, s.max, s.p95), (3, 0.3, 0.3));
    /// assert!((s.mean - 0.2).abs() < 1e-15);
    /// ```
    pub fn ground_truth_errors(
        &self,
        source: &ValidMesh,
        target: &ValidMesh,
    ) -> Result<GroundTruthErrors, AppError> {
        if source.n_vertices() != target.n_vertices()
            || source.triangles != target.triangles
            || self.mapped.len() != target.n_vertices()
        {
            return Err(AppError::Input(
                "the source and target do not share connectivity".into(),
            ));
        }
        let diag = target.bounding_box_diagonal();
        let (mut valid, mut answered) = (Vec::new(), Vec::new());
        let (mut rejected_correct, mut accepted_wrong) = (0, 0);
        for (v, (m, ok)) in self.mapped.iter().zip(&self.validity).enumerate() {
            if let Ok(img) = &m.target {
                let e = (img.position - target.positions[v]).norm() / diag;
                answered.push(e);
                // NaN errors count as wrong.
                let right = e <= WRONG_ERROR;
                if *ok == Validity::Valid {
                    valid.push(e);
                    accepted_wrong += usize::from(!right);
                } else {
                    rejected_correct += usize::from(right);
                }
            }
        }
        Ok(GroundTruthErrors {
            valid: ErrorStats::of(valid),
            answered: ErrorStats::of(answered),
            rejected_correct,
            accepted_wrong,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_of_errors() {
        assert_eq!(ErrorStats::of(Vec::new()), ErrorStats::default());
        let s = ErrorStats::of((1..=100).rev().map(f64::from).collect());
        assert_eq!((s.count, s.p95, s.max), (100, 96.0, 100.0));
        assert!((s.mean - 50.5).abs() < 1e-12);
        let one = ErrorStats::of(vec![2.0]);
        assert_eq!((one.count, one.mean, one.p95, one.max), (1, 2.0, 2.0, 2.0));
    }
}
