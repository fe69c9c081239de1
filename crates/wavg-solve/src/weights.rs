//! Validation of forward-problem weights: right length, finite, summing to one.

use crate::error::SolveError;

/// Accepted deviation of a weight vector's sum from 1.
pub const WEIGHT_SUM_TOLERANCE: f64 = 1e-6;

/// What to do with weights that do not sum to 1.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Normalization {
    /// Reject them with [`SolveError::WeightSum`] (the default: a wrong sum is usually a bug).
    #[default]
    Reject,
    /// Divide by their sum (explicit opt-in; a sum near zero is still an error).
    Normalize,
}

/// Checks `weights` for `n_anchors` anchors and returns the factor to multiply them by
/// (1 unless normalising): length, finiteness, and a sum of 1 within
/// [`WEIGHT_SUM_TOLERANCE`].
///
/// ```
/// use wavg_solve::{Normalization, validate_weights};
/// assert_eq!(validate_weights(&[0.25, 0.75], 2, Normalization::Reject).unwrap(), 1.0);
/// assert!(validate_weights(&[1.0, 1.0], 2, Normalization::Reject).is_err());
/// assert_eq!(validate_weights(&[1.0, 1.0], 2, Normalization::Normalize).unwrap(), 0.5);
/// ```
pub fn validate_weights(
    weights: &[f64],
    n_anchors: usize,
    norm: Normalization,
) -> Result<f64, SolveError> {
    if n_anchors == 0 {
        return Err(SolveError::NoAnchors);
    }
    if weights.len() != n_anchors {
        return Err(SolveError::WeightCount {
            expected: n_anchors,
            got: weights.len(),
        });
    }
    // One pass with four partial sums (the weights are usually a fresh cache miss and
    // a single running sum is a chain of dependent additions); a NaN or infinite weight
    // makes the sum non-finite, and only then are the weights searched for the culprit.
    let mut acc = [0.0f64; 4];
    let mut quads = weights.chunks_exact(4);
    for q in &mut quads {
        for k in 0..4 {
            acc[k] += q[k];
        }
    }
    for (k, &w) in quads.remainder().iter().enumerate() {
        acc[k] += w;
    }
    let sum = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    if !sum.is_finite()
        && let Some((index, &value)) = weights.iter().enumerate().find(|(_, w)| !w.is_finite())
    {
        return Err(SolveError::NonFiniteWeight { index, value });
    }
    match norm {
        Normalization::Reject => {
            // Written so that an overflowing (NaN or infinite) sum is rejected too.
            let deviation = (sum - 1.0).abs();
            if deviation.is_nan() || deviation > WEIGHT_SUM_TOLERANCE {
                Err(SolveError::WeightSum {
                    sum,
                    tolerance: WEIGHT_SUM_TOLERANCE,
                })
            } else {
                Ok(1.0)
            }
        }
        Normalization::Normalize => {
            // A sum this small relative to the weights' size means cancellation: the
            // normalised weights would be meaningless.
            let scale: f64 = weights.iter().map(|w| w.abs()).sum();
            let inv = 1.0 / sum;
            if !sum.is_finite() || sum.abs() <= 1e-12 * scale || !inv.is_finite() {
                Err(SolveError::ZeroWeightSum { sum })
            } else {
                Ok(inv)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_each_malformed_vector() {
        use Normalization::*;
        assert_eq!(
            validate_weights(&[1.0], 2, Reject),
            Err(SolveError::WeightCount {
                expected: 2,
                got: 1
            })
        );
        assert!(matches!(
            validate_weights(&[f64::NAN, 1.0], 2, Reject),
            Err(SolveError::NonFiniteWeight { index: 0, .. })
        ));
        assert!(matches!(
            validate_weights(&[0.5, f64::INFINITY], 2, Normalize),
            Err(SolveError::NonFiniteWeight { index: 1, .. })
        ));
        // Messages count from 1, as the text formats do: index 1 is the second weight.
        let e = validate_weights(&[0.5, f64::INFINITY], 2, Normalize).unwrap_err();
        assert_eq!(e.to_string(), "weight 2 is not finite (inf)");
        assert!(matches!(
            validate_weights(&[0.5, 0.5 + 2e-6], 2, Reject),
            Err(SolveError::WeightSum { .. })
        ));
        assert_eq!(validate_weights(&[0.5, 0.5 + 5e-7], 2, Reject), Ok(1.0));
        assert!(matches!(
            validate_weights(&[1.0, -1.0], 2, Normalize),
            Err(SolveError::ZeroWeightSum { .. })
        ));
        // A sum lost to cancellation and an overflowing one say so.
        let e = validate_weights(&[1e200, -1e200, 1.0], 3, Normalize).unwrap_err();
        assert!(e.to_string().contains("zero for their size"), "{e}");
        let e = validate_weights(&[1e308, 1e308, -1e308], 3, Normalize).unwrap_err();
        assert!(e.to_string().contains("overflows"), "{e}");
        assert_eq!(validate_weights(&[], 0, Reject), Err(SolveError::NoAnchors));
        assert_eq!(validate_weights(&[2.0, 2.0], 2, Normalize), Ok(0.25));
        assert_eq!(validate_weights(&[-1.0, 2.0], 2, Reject), Ok(1.0));
    }
}
