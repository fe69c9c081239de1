//! The inverse problem's linear algebra against a straightforward dense reference.

use nalgebra::{DMatrix, DVector};
use proptest::prelude::*;
use wavg_solve::{AnchorCoords, InverseScratch, inverse_weights};
use wavg_solve::{Mat2x8, SolveError, Vec8};

/// The textbook formula `w = S C^T (C S C^T)^{-1} b` with `S = diag(1/d^2)`, uncentred,
/// projector computed with a dense pseudo-inverse.
fn reference(psi: &Mat2x8, yhat: &Vec8, ys: &[Vec8], gamma: f64) -> Vec<f64> {
    let n = ys.len();
    let psi_d = DMatrix::from_fn(2, 8, |i, j| psi[(i, j)]);
    let proj = psi_d.transpose() * (&psi_d * psi_d.transpose()).try_inverse().unwrap() * &psi_d;
    let mut c = DMatrix::zeros(3, n);
    let mut s = DVector::zeros(n);
    for (j, y) in ys.iter().enumerate() {
        let v = DVector::from_fn(8, |k, _| y[k] - yhat[k]);
        let vt = &proj * &v;
        let vo = &v - &vt;
        let d = vt.norm_squared() + gamma * vo.norm_squared();
        s[j] = 1.0 / (d * d);
        let py = psi * y;
        c[(0, j)] = py[0];
        c[(1, j)] = py[1];
        c[(2, j)] = 1.0;
    }
    let ph = psi * yhat;
    let b = DVector::from_vec(vec![ph[0], ph[1], 1.0]);
    let sct = DMatrix::from_diagonal(&s) * c.transpose();
    let m = &c * &sct;
    let z = m.lu().solve(&b).unwrap();
    (sct * z).iter().copied().collect()
}

fn solve(psi: &Mat2x8, yhat: &Vec8, ys: &[Vec8], gamma: f64) -> Result<Vec<f64>, SolveError> {
    let mut w = Vec::new();
    inverse_weights(
        psi,
        yhat,
        &AnchorCoords::from_points(ys),
        gamma,
        &mut InverseScratch::default(),
        &mut w,
    )?;
    Ok(w)
}

fn vec8() -> impl Strategy<Value = Vec8> {
    prop::array::uniform8(-1.0f64..1.0).prop_map(Vec8::from)
}

/// Near-orthonormal tangent plane: two random rows, slightly perturbed from orthonormal.
fn psi() -> impl Strategy<Value = Mat2x8> {
    (vec8(), vec8(), 0.0f64..0.1).prop_filter_map("degenerate", |(a, b, eps)| {
        let a = a.try_normalize(1e-3)?;
        let b = (b - a * a.dot(&b)).try_normalize(1e-3)?;
        let mut m = Mat2x8::zeros();
        m.set_row(0, &(a * (1.0 + eps)).transpose());
        m.set_row(1, &(b + a * eps).transpose());
        Some(m)
    })
}

/// Constraint residual |sum w_j Psi (y_j - yhat)| and |sum w - 1|.
fn residuals(psi: &Mat2x8, yhat: &Vec8, ys: &[Vec8], w: &[f64]) -> (f64, f64) {
    let mut r = nalgebra::Vector2::zeros();
    for (y, wj) in ys.iter().zip(w) {
        r += psi * (y - yhat) * *wj;
    }
    (r.norm(), (w.iter().sum::<f64>() - 1.0).abs())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn matches_reference_and_meets_constraints(
        psi in psi(),
        yhat in vec8(),
        ys in prop::collection::vec(vec8(), 3..40),
        gamma in 1.0f64..20.0,
    ) {
        let w = solve(&psi, &yhat, &ys, gamma).unwrap();
        let r = reference(&psi, &yhat, &ys, gamma);
        let (res, sum) = residuals(&psi, &yhat, &ys, &w);
        prop_assert!(res < 1e-9, "constraint residual {res}");
        // Exact up to rounding: a few ulps of the weights' magnitudes.
        let mag: f64 = w.iter().map(|x| x.abs()).sum::<f64>().max(1.0);
        prop_assert!(sum <= 4.0 * f64::EPSILON * w.len() as f64 * mag, "sum off by {sum}");
        for (a, b) in w.iter().zip(&r) {
            prop_assert!((a - b).abs() < 1e-7 * (1.0 + b.abs()), "{a} vs {b}");
        }
    }

    #[test]
    fn invariant_under_translation_and_scale(
        psi in psi(),
        yhat in vec8(),
        ys in prop::collection::vec(vec8(), 3..20),
        shift in vec8(),
        scale in 0.01f64..100.0,
    ) {
        let w = solve(&psi, &yhat, &ys, 10.0).unwrap();
        let moved: Vec<Vec8> = ys.iter().map(|y| (y + shift) * scale).collect();
        let w2 = solve(&psi, &((yhat + shift) * scale), &moved, 10.0).unwrap();
        for (a, b) in w.iter().zip(&w2) {
            prop_assert!((a - b).abs() < 1e-7 * (1.0 + a.abs()));
        }
    }

    /// Approaching anchor i the weights tend to the one-hot weight, smoothly and without
    /// NaN, and are exactly one-hot at the anchor.
    #[test]
    fn interpolates_anchors_smoothly(
        psi in psi(),
        dir in vec8(),
        ys in prop::collection::vec(vec8(), 3..20),
        i in 0usize..3,
    ) {
        let at = solve(&psi, &ys[i], &ys, 10.0).unwrap();
        for (j, w) in at.iter().enumerate() {
            prop_assert_eq!(*w, if j == i { 1.0 } else { 0.0 });
        }
        // Far from the anchor an ill-conditioned configuration (anchors nearly collinear
        // under Psi) can have large weights; from 1e-4 on the error is in its linear
        // regime: it shrinks with the distance, about tenfold per decade.
        const K0: i32 = 4;
        let mut prev = f64::INFINITY;
        let mut at_k0 = f64::INFINITY;
        for k in 1..16 {
            let t = 10f64.powi(-k);
            let w = solve(&psi, &(ys[i] + dir * t), &ys, 10.0).unwrap();
            let err: f64 = w.iter().enumerate().map(|(j, w)| (w - if j == i { 1.0 } else { 0.0 }).abs()).sum();
            prop_assert!(err.is_finite());
            if k == K0 {
                at_k0 = err;
            } else if k > K0 {
                // Allow rounding noise.
                prop_assert!(err <= prev * 0.5 + 1e-12, "k={k}: {err} after {prev}");
                let linear = at_k0 * 10f64.powi(K0 - k);
                prop_assert!(err <= 2.0 * linear + 1e-12, "k={k}: {err}, linear from 1e-4: {linear}");
            }
            prev = err;
        }
    }
}

#[test]
fn coincident_anchors_share_the_weight() {
    let mut psi = Mat2x8::zeros();
    psi[(0, 0)] = 1.0;
    psi[(1, 1)] = 1.0;
    let p = |x: f64, y: f64| Vec8::from_fn(|k, _| [x, y, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0][k]);
    let ys = [
        p(0.0, 0.0),
        p(1.0, 0.0),
        p(0.0, 0.0),
        p(0.0, 1.0),
        p(-1.0, -1.0),
    ];
    let w = solve(&psi, &p(0.0, 0.0), &ys, 10.0).unwrap();
    assert_eq!(w, vec![0.5, 0.0, 0.5, 0.0, 0.0]);
    let w = solve(&psi, &p(1e-9, 1e-9), &ys, 10.0).unwrap();
    assert!(
        (w[0] - 0.5).abs() < 1e-6 && (w[0] - w[2]).abs() < 1e-12,
        "{w:?}"
    );
}

#[test]
fn degenerate_inputs_are_typed_errors() {
    let mut psi = Mat2x8::zeros();
    psi[(0, 0)] = 1.0;
    psi[(1, 1)] = 1.0;
    let p = |x: f64, y: f64| Vec8::from_fn(|k, _| [x, y, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0][k]);
    // Two anchors: a point off their line cannot be reproduced.
    let ys = [p(0.0, 0.0), p(1.0, 0.0)];
    assert_eq!(
        solve(&psi, &p(0.5, 0.5), &ys, 10.0),
        Err(SolveError::DegenerateAnchors)
    );
    // ... one on the line can.
    let w = solve(
        &psi,
        &p(0.25, 0.0),
        &[p(0.0, 0.0), p(1.0, 0.0), p(0.0, 1.0)],
        10.0,
    )
    .unwrap();
    assert!(w[0] > w[1] && w[1] > 0.0);
    assert_eq!(
        solve(&psi, &p(0.0, 0.0), &[], 10.0),
        Err(SolveError::NoAnchors)
    );
    assert!(matches!(
        solve(&psi, &p(0.0, 0.0), &ys, f64::NAN),
        Err(SolveError::InvalidParameter(_))
    ));
    assert!(matches!(
        solve(&psi, &p(0.0, 0.0), &ys, 0.0),
        Err(SolveError::InvalidParameter(_))
    ));
    assert!(matches!(
        solve(&Mat2x8::zeros(), &p(0.0, 0.0), &ys, 10.0),
        Err(SolveError::DegenerateTangentPlane)
    ));
}

/// A `gamma` whose product with a squared distance overflows is named as the cause;
/// NaN coordinates are named as theirs.
#[test]
fn overflowing_distances_name_their_cause() {
    let mut psi = Mat2x8::zeros();
    psi[(0, 0)] = 1.0;
    psi[(1, 1)] = 1.0;
    let p = |x: f64, y: f64, z: f64| Vec8::from_fn(|k, _| [x, y, z, 0.0, 0.0, 0.0, 0.0, 0.0][k]);
    let ys = [p(0.0, 0.0, 10.0), p(1.0, 0.0, 10.0), p(0.0, 1.0, 10.0)];
    let at = p(0.2, 0.2, 0.0);
    let message = |r: Result<Vec<f64>, SolveError>| match r {
        Err(SolveError::InvalidParameter(m)) => m,
        other => panic!("expected an invalid parameter, got {other:?}"),
    };
    assert!(solve(&psi, &at, &ys, 1e300).is_ok());
    let m = message(solve(&psi, &at, &ys, 1e308));
    assert!(m.contains("gamma 1e308 is too large"), "{m}");
    let m = message(wavg_solve::internal::penalized_weights(
        &psi,
        &at,
        &AnchorCoords::from_points(&ys),
        1e308,
        10.0,
    ));
    assert!(m.contains("gamma 1e308 is too large"), "{m}");
    let m = message(solve(&psi, &p(f64::NAN, 0.0, 0.0), &ys, 10.0));
    assert!(m.contains("non-finite"), "{m}");
}

#[test]
fn locality_far_anchors_get_small_weights() {
    // Anchors on a line-free spread in the plane; the point sits next to anchor 0.
    let mut psi = Mat2x8::zeros();
    psi[(0, 0)] = 1.0;
    psi[(1, 1)] = 1.0;
    let p = |x: f64, y: f64| Vec8::from_fn(|k, _| [x, y, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0][k]);
    let mut ys = Vec::new();
    for i in 0..10 {
        for j in 0..10 {
            ys.push(p(i as f64 + 0.1 * ((i * j) % 3) as f64, j as f64));
        }
    }
    let w = solve(&psi, &p(0.4, 0.3), &ys, 10.0).unwrap();
    for (j, y) in ys.iter().enumerate() {
        let dist = (y - p(0.4, 0.3)).norm();
        if dist > 4.0 {
            assert!(w[j].abs() < 1e-3, "anchor {j} at {dist}: {}", w[j]);
        }
    }
    assert!(w[0] > 0.3);
}
