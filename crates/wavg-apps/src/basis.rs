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

impl SplineKind {
    /// The curve the front ends' options name: a Bézier curve when `bezier` is set (then
    /// `degree` and `closed` are ignored), else a B-spline of `degree`, periodic when
    /// `closed`.
    ///
    /// ```
    /// use wavg_apps::SplineKind;
    /// assert_eq!(SplineKind::from_options(3, true, true), SplineKind::Bezier);
    /// assert_eq!(
    ///     SplineKind::from_options(2, true, false),
    ///     SplineKind::BSpline { degree: 2, closed: true }
    /// );
    /// ```
    pub fn from_options(degree: usize, closed: bool, bezier: bool) -> Self {
        if bezier {
            Self::Bezier
        } else {
            Self::BSpline { degree, closed }
        }
    }
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
    let flat = spline_weights_flat(kind, n_controls, samples)?;
    Ok(flat.chunks_exact(n_controls).map(<[f64]>::to_vec).collect())
}

/// [`spline_weights`] as one row-major buffer of `samples * n_controls` weights (row `s`
/// at `s * n_controls ..`): one allocation for the whole curve.
///
/// ```
/// use wavg_apps::{SplineKind, spline_weights, spline_weights_flat};
/// let kind = SplineKind::Bezier;
/// let flat = spline_weights_flat(kind, 4, 9).unwrap();
/// let rows = spline_weights(kind, 4, 9).unwrap();
/// assert!(flat.chunks_exact(4).eq(rows.iter().map(|r| r.as_slice())));
/// ```
pub fn spline_weights_flat(
    kind: SplineKind,
    n_controls: usize,
    samples: usize,
) -> Result<Vec<f64>, SolveError> {
    let bad = |m: String| Err(SolveError::InvalidParameter(m));
    if samples == 0 {
        return bad("a curve needs at least one sample".into());
    }
    let mut out = vec![0.0; samples * n_controls];
    match kind {
        SplineKind::BSpline { degree: 0, .. } => {
            return bad("the spline degree must be at least 1".into());
        }
        SplineKind::BSpline { degree, .. } if n_controls < degree + 1 => {
            return bad(format!(
                "a degree-{degree} B-spline needs at least {} control points, got {n_controls}",
                degree + 1
            ));
        }
        SplineKind::Bezier if n_controls < 2 => {
            return bad(format!(
                "a Bézier curve needs at least 2 control points, got {n_controls}"
            ));
        }
        SplineKind::BSpline {
            degree,
            closed: true,
        } => closed_bspline(degree, n_controls, &mut out),
        SplineKind::BSpline {
            degree,
            closed: false,
        } => open_bspline(degree, n_controls, &mut out),
        SplineKind::Bezier => bezier(n_controls, &mut out),
    }
    Ok(out)
}

/// Parameter of sample `s` of `samples` in [0, 1], ends included.
fn unit_parameter(s: usize, samples: usize) -> f64 {
    if samples == 1 {
        0.0
    } else {
        s as f64 / (samples - 1) as f64
    }
}

/// Cox-de Boor evaluation with its scratch rows kept between samples.
struct Basis {
    n: Vec<f64>,
    left: Vec<f64>,
    right: Vec<f64>,
}

impl Basis {
    fn new(p: usize) -> Self {
        Basis {
            n: vec![0.0; p + 1],
            left: vec![0.0; p + 1],
            right: vec![0.0; p + 1],
        }
    }

    /// The `p + 1` non-zero basis functions of degree `p` at `t` in knot span `span`
    /// (`knots[span] <= t < knots[span + 1]`), for controls `span - p ..= span`.
    fn eval(&mut self, knots: &[f64], span: usize, t: f64) -> &[f64] {
        let p = self.n.len() - 1;
        let (n, left, right) = (&mut self.n, &mut self.left, &mut self.right);
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
}

fn open_bspline(p: usize, n: usize, out: &mut [f64]) {
    // Clamped uniform knots: p + 1 zeros, interior steps of 1 / (n - p), p + 1 ones.
    let segments = n - p;
    let mut knots = vec![0.0; p + 1];
    knots.extend((1..segments).map(|i| i as f64 / segments as f64));
    knots.extend(std::iter::repeat_n(1.0, p + 1));
    let samples = out.len() / n;
    let mut basis = Basis::new(p);
    for (s, w) in out.chunks_exact_mut(n).enumerate() {
        let t = unit_parameter(s, samples);
        // The span holding t; t = 1 belongs to the last non-empty span.
        let span = ((t * segments as f64).floor() as usize).min(segments - 1) + p;
        w[span - p..=span].copy_from_slice(basis.eval(&knots, span, t));
    }
}

fn closed_bspline(p: usize, n: usize, out: &mut [f64]) {
    // Integer knots; on [p, p + 1) the basis functions 0..=p are the uniform blend.
    let knots: Vec<f64> = (0..=2 * p + 1).map(|k| k as f64).collect();
    // Centre the blend so that parameter j lies near control j.
    let shift = (p - 1) / 2;
    let samples = out.len() / n;
    let mut basis = Basis::new(p);
    for (s, w) in out.chunks_exact_mut(n).enumerate() {
        let t = s as f64 * n as f64 / samples as f64;
        let i = (t.floor() as usize).min(n - 1);
        let b = basis.eval(&knots, p, p as f64 + (t - i as f64));
        // Controls (i - shift + k) mod n: one division per sample, then a wrap.
        let mut c = (i + n * p - shift) % n;
        for bk in b {
            w[c] += bk;
            c = if c + 1 == n { 0 } else { c + 1 };
        }
    }
}

fn bezier(n: usize, out: &mut [f64]) {
    let deg = n - 1;
    let samples = out.len() / n;
    for (s, w) in out.chunks_exact_mut(n).enumerate() {
        let t = unit_parameter(s, samples);
        // Bernstein polynomials by de Casteljau's triangle on the unit vectors.
        w[0] = 1.0;
        for j in 1..=deg {
            for k in (0..=j).rev() {
                let prev = if k > 0 { w[k - 1] } else { 0.0 };
                w[k] = w[k] * (1.0 - t) + prev * t;
            }
        }
    }
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
    fn clamped_spline_without_interior_knots_is_the_bezier_curve() {
        // With degree + 1 controls the clamped knot vector has no interior knots, and
        // the B-spline basis is the Bernstein basis: every degree, same weights.
        for degree in 1..8 {
            let n = degree + 1;
            let b = spline_weights_flat(SplineKind::Bezier, n, 33).unwrap();
            let kind = SplineKind::BSpline {
                degree,
                closed: false,
            };
            let s = spline_weights_flat(kind, n, 33).unwrap();
            assert_eq!(b.len(), s.len());
            for (x, y) in b.iter().zip(&s) {
                assert!((x - y).abs() < 1e-13, "degree {degree}: {x} vs {y}");
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
