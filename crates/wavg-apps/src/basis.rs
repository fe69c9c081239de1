//! Blending weights of spline curves: for each sample, one weight per control point,
//! non-negative and summing to 1 (so every sample is a weighted average of the controls).

use wavg_solve::SolveError;

/// Which curve the control points define.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplineKind {
    /// A uniform B-spline of `degree` (1 or more). Open: clamped (the curve starts at the
    /// first control point and ends at the last; needs `degree + 1` controls). Closed:
    /// periodic (needs `degree + 1` controls too); near parameter `j` it follows control
    /// point `j`.
    BSpline {
        /// Polynomial degree (3 = cubic).
        degree: usize,
        /// Periodic (a loop) rather than clamped.
        closed: bool,
    },
    /// A Bézier curve whose degree is the number of control points minus one.
    Bezier,
}

/// `samples` rows of `n_controls` weights along the curve: uniform in the parameter, the
/// first and last samples at the ends of an open curve, a closed curve's samples covering
/// the loop once (the last sample is not the first again).
///
/// ```
/// use wavg_apps::{SplineKind, spline_weights};
/// let w = spline_weights(SplineKind::BSpline { degree: 3, closed: false }, 6, 11).unwrap();
/// assert_eq!(w[0], [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]); // clamped: starts at control 0
/// assert!(w.iter().all(|r| (r.iter().sum::<f64>() - 1.0).abs() < 1e-12));
/// ```
pub fn spline_weights(
    kind: SplineKind,
    n_controls: usize,
    samples: usize,
) -> Result<Vec<Vec<f64>>, SolveError> {
    let bad = |m: String| Err(SolveError::InvalidParameter(m));
    if samples == 0 {
        return bad("a curve needs at least one sample".into());
    }
    match kind {
        SplineKind::BSpline { degree: 0, .. } => bad("the spline degree must be at least 1".into()),
        SplineKind::BSpline { degree, .. } if n_controls < degree + 1 => bad(format!(
            "a degree-{degree} B-spline needs at least {} control points, got {n_controls}",
            degree + 1
        )),
        SplineKind::Bezier if n_controls < 2 => bad(format!(
            "a Bézier curve needs at least 2 control points, got {n_controls}"
        )),
        SplineKind::BSpline {
            degree,
            closed: true,
        } => Ok(closed_bspline(degree, n_controls, samples)),
        SplineKind::BSpline {
            degree,
            closed: false,
        } => Ok(open_bspline(degree, n_controls, samples)),
        SplineKind::Bezier => Ok(bezier(n_controls, samples)),
    }
}

/// Parameter of sample `s` of `samples` in [0, 1], ends included.
fn unit_parameter(s: usize, samples: usize) -> f64 {
    if samples == 1 {
        0.0
    } else {
        s as f64 / (samples - 1) as f64
    }
}

/// Cox-de Boor: the `p + 1` non-zero basis functions of degree `p` at `t` in knot span
/// `span` (`knots[span] <= t < knots[span + 1]`), for controls `span - p ..= span`.
fn basis_functions(knots: &[f64], span: usize, t: f64, p: usize) -> Vec<f64> {
    let mut n = vec![0.0; p + 1];
    let mut left = vec![0.0; p + 1];
    let mut right = vec![0.0; p + 1];
    n[0] = 1.0;
    for j in 1..=p {
        left[j] = t - knots[span + 1 - j];
        right[j] = knots[span + j] - t;
        let mut saved = 0.0;
        for r in 0..j {
            let denom = right[r + 1] + left[j - r];
            let temp = if denom == 0.0 { 0.0 } else { n[r] / denom };
            n[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        n[j] = saved;
    }
    n
}

fn open_bspline(p: usize, n: usize, samples: usize) -> Vec<Vec<f64>> {
    // Clamped uniform knots: p + 1 zeros, interior steps of 1 / (n - p), p + 1 ones.
    let segments = n - p;
    let mut knots = vec![0.0; p + 1];
    knots.extend((1..segments).map(|i| i as f64 / segments as f64));
    knots.extend(std::iter::repeat_n(1.0, p + 1));
    (0..samples)
        .map(|s| {
            let t = unit_parameter(s, samples);
            // The span holding t; t = 1 belongs to the last non-empty span.
            let span = ((t * segments as f64).floor() as usize).min(segments - 1) + p;
            let b = basis_functions(&knots, span, t, p);
            let mut w = vec![0.0; n];
            for (k, bk) in b.iter().enumerate() {
                w[span - p + k] = *bk;
            }
            w
        })
        .collect()
}

fn closed_bspline(p: usize, n: usize, samples: usize) -> Vec<Vec<f64>> {
    // Integer knots; on [p, p + 1) the basis functions 0..=p are the uniform blend.
    let knots: Vec<f64> = (0..=2 * p + 1).map(|k| k as f64).collect();
    // Centre the blend so that parameter j lies near control j.
    let shift = (p - 1) / 2;
    (0..samples)
        .map(|s| {
            let t = s as f64 * n as f64 / samples as f64;
            let i = (t.floor() as usize).min(n - 1);
            let b = basis_functions(&knots, p, p as f64 + (t - i as f64), p);
            let mut w = vec![0.0; n];
            for (k, bk) in b.iter().enumerate() {
                w[(i + n * p + k - shift) % n] += bk;
            }
            w
        })
        .collect()
}

fn bezier(n: usize, samples: usize) -> Vec<Vec<f64>> {
    let deg = n - 1;
    (0..samples)
        .map(|s| {
            let t = unit_parameter(s, samples);
            // Bernstein polynomials by de Casteljau's triangle on the unit vectors.
            let mut w = vec![0.0; n];
            w[0] = 1.0;
            for j in 1..=deg {
                for k in (0..=j).rev() {
                    let prev = if k > 0 { w[k - 1] } else { 0.0 };
                    w[k] = w[k] * (1.0 - t) + prev * t;
                }
            }
            w
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn binomial(n: usize, k: usize) -> f64 {
        (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
    }

    #[test]
    fn closed_cubic_matches_the_closed_form() {
        // The uniform cubic blend: (1-u)^3/6, (3u^3 - 6u^2 + 4)/6, (-3u^3 + 3u^2 + 3u + 1)/6,
        // u^3/6, for controls i-1 .. i+2.
        let n = 7;
        let samples = 50;
        let w = spline_weights(
            SplineKind::BSpline {
                degree: 3,
                closed: true,
            },
            n,
            samples,
        )
        .unwrap();
        for (s, row) in w.iter().enumerate() {
            let t = s as f64 * n as f64 / samples as f64;
            let i = t.floor() as usize;
            let u = t - i as f64;
            let (u2, u3) = (u * u, u * u * u);
            let b = [
                (1.0 - u).powi(3) / 6.0,
                (3.0 * u3 - 6.0 * u2 + 4.0) / 6.0,
                (-3.0 * u3 + 3.0 * u2 + 3.0 * u + 1.0) / 6.0,
                u3 / 6.0,
            ];
            let mut want = vec![0.0; n];
            for (k, bk) in b.iter().enumerate() {
                want[(i + n + k - 1) % n] += bk;
            }
            for (a, b) in row.iter().zip(&want) {
                assert!((a - b).abs() < 1e-14, "sample {s}: {row:?} vs {want:?}");
            }
        }
    }

    #[test]
    fn bezier_is_bernstein() {
        let n = 6;
        let w = spline_weights(SplineKind::Bezier, n, 9).unwrap();
        for (s, row) in w.iter().enumerate() {
            let t = s as f64 / 8.0;
            for (k, wk) in row.iter().enumerate() {
                let b = binomial(n - 1, k) * t.powi(k as i32) * (1.0 - t).powi((n - 1 - k) as i32);
                assert!((wk - b).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn open_degree_one_is_the_polyline() {
        // Degree 1, clamped: linear interpolation between consecutive controls.
        let w = spline_weights(
            SplineKind::BSpline {
                degree: 1,
                closed: false,
            },
            3,
            5,
        )
        .unwrap();
        let want = [
            [1.0, 0.0, 0.0],
            [0.5, 0.5, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.5, 0.5],
            [0.0, 0.0, 1.0],
        ];
        for (row, want) in w.iter().zip(want) {
            for (a, b) in row.iter().zip(want) {
                assert!((a - b).abs() < 1e-14, "{row:?} vs {want:?}");
            }
        }
    }

    #[test]
    fn bad_parameters_are_errors() {
        let b = |degree, closed| SplineKind::BSpline { degree, closed };
        assert!(spline_weights(b(0, false), 5, 10).is_err());
        assert!(spline_weights(b(3, true), 3, 10).is_err());
        assert!(spline_weights(b(3, false), 4, 0).is_err());
        assert!(spline_weights(SplineKind::Bezier, 1, 10).is_err());
    }

    proptest! {
        /// Partition of unity, non-negativity, locality (at most degree + 1 non-zero
        /// weights), and clamped ends.
        #[test]
        fn bspline_weights_are_a_local_partition_of_unity(
            degree in 1usize..6, extra in 0usize..8, samples in 1usize..60, closed: bool,
        ) {
            let n = degree + 1 + extra;
            let w = spline_weights(SplineKind::BSpline { degree, closed }, n, samples).unwrap();
            prop_assert_eq!(w.len(), samples);
            for row in &w {
                prop_assert!((row.iter().sum::<f64>() - 1.0).abs() < 1e-12);
                prop_assert!(row.iter().all(|&x| x >= -1e-15));
                prop_assert!(row.iter().filter(|&&x| x > 1e-15).count() <= degree + 1);
            }
            if !closed && samples > 1 {
                prop_assert!((w[0][0] - 1.0).abs() < 1e-12);
                prop_assert!((w[samples - 1][n - 1] - 1.0).abs() < 1e-12);
            }
        }
    }
}
