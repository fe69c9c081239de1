//! Splines on surfaces: every sample is the weighted average of the control points with
//! the curve's blending weights, found by a forward problem warm-started from the
//! previous sample.

use wavg_solve::{ForwardOptions, ForwardResult, SolveError, Solver};

use crate::basis::{SplineKind, spline_weights_flat};

/// Default degree of a B-spline (cubic), in every front end.
pub const DEFAULT_SPLINE_DEGREE: usize = 3;

/// Default number of samples of a curve, in every front end.
pub const DEFAULT_SPLINE_SAMPLES: usize = 500;

/// Samples evaluated in sequence, warm-started, per parallel chunk of
/// [`evaluate_spline`] as the front ends call it: long enough that warm starts pay,
/// short enough to spread a few hundred samples over the cores.
pub const SPLINE_CHUNK: usize = 256;

/// A sampled curve on the surface.
#[derive(Clone, Debug)]
pub struct Curve {
    /// One answer per sample, in order (a sample without a weighted average is an error).
    pub samples: Vec<Result<ForwardResult, SolveError>>,
    /// Whether the curve is a loop (its length includes the last-to-first segment).
    pub closed: bool,
}

/// What a sampled curve came to; with the `serde` feature, the `wavg spline --json` keys.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct CurveReport {
    /// Samples asked for.
    pub samples: usize,
    /// Of these, the ones on the surface ([`Curve::ok_samples`]).
    pub ok_samples: usize,
    /// [`Curve::length`].
    pub length: f64,
}

impl Curve {
    /// The curve's [`CurveReport`].
    pub fn report(&self) -> CurveReport {
        CurveReport {
            samples: self.samples.len(),
            ok_samples: self.ok_samples(),
            length: self.length(),
        }
    }

    /// Samples that lie on the surface.
    pub fn ok_samples(&self) -> usize {
        self.samples.iter().filter(|r| r.is_ok()).count()
    }

    /// Length in 3-D of the polyline through consecutive samples on the surface (skipping
    /// failed samples).
    pub fn length(&self) -> f64 {
        let pts: Vec<_> = self
            .samples
            .iter()
            .filter_map(|r| r.as_ref().ok().map(|r| r.position))
            .collect();
        // A fold from +0 (an empty `sum` of floats is -0).
        let open = pts.windows(2).fold(0.0, |s, w| s + (w[1] - w[0]).norm());
        match (self.closed, pts.first(), pts.last()) {
            (true, Some(a), Some(b)) if pts.len() > 2 => open + (a - b).norm(),
            _ => open,
        }
    }
}

/// Samples of the curve whose control points are the solver's anchors, in anchor order.
/// Samples run in chunks of `chunk` in parallel, each chunk warm-started along the curve
/// (results do not depend on the thread count).
///
/// ```
/// use std::sync::Arc;
/// use wavg_mesh::{ValidMesh, procedural};
/// use wavg_project::{EmbeddedMesh, Projector};
/// use wavg_solve::{Anchor, Solver};
/// use wavg_apps::{SplineKind, evaluate_spline};
/// let mesh = Arc::new(ValidMesh::new(procedural::icosphere(3)).unwrap());
/// let proj = Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh))).unwrap());
/// let solver = Solver::new(proj, [0u32, 100, 200, 300, 400].map(Anchor::Vertex)).unwrap();
/// let kind = SplineKind::BSpline { degree: 3, closed: true };
/// let curve = evaluate_spline(&solver, kind, 100, 100).unwrap();
/// assert_eq!(curve.ok_samples(), 100);
/// assert!(curve.length() > 0.0);
/// ```
pub fn evaluate_spline(
    solver: &Solver,
    kind: SplineKind,
    samples: usize,
    chunk: usize,
) -> Result<Curve, SolveError> {
    let flat = spline_weights_flat(kind, solver.n_anchors(), samples)?;
    let weights: Vec<&[f64]> = flat.chunks_exact(solver.n_anchors()).collect();
    let samples = solver.forward_batch_warm(&weights, &ForwardOptions::default(), chunk.max(1));
    Ok(Curve {
        samples,
        closed: matches!(kind, SplineKind::BSpline { closed: true, .. }),
    })
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use wavg_mesh::{ValidMesh, procedural};
    use wavg_project::{EmbeddedMesh, Projector};
    use wavg_solve::{Anchor, Solver};

    use super::*;

    fn sphere_solver(anchors: &[u32]) -> Solver {
        let mesh = Arc::new(ValidMesh::new(procedural::icosphere(4)).unwrap());
        let proj = Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh))).unwrap();
        Solver::new(Arc::new(proj), anchors.iter().map(|&v| Anchor::Vertex(v))).unwrap()
    }

    #[test]
    fn clamped_curve_interpolates_its_end_controls_and_stays_on_the_sphere() {
        let solver = sphere_solver(&[0, 40, 300, 900, 1500, 2000]);
        let kind = SplineKind::BSpline {
            degree: 3,
            closed: false,
        };
        let curve = evaluate_spline(&solver, kind, 200, 50).unwrap();
        assert_eq!(curve.ok_samples(), 200);
        let mesh = solver.mesh();
        let first = curve.samples[0].as_ref().unwrap().position;
        let last = curve.samples[199].as_ref().unwrap().position;
        assert!((first - mesh.positions[0]).norm() < 1e-9);
        assert!((last - mesh.positions[2000]).norm() < 1e-9);
        for r in &curve.samples {
            // On the polyhedral icosphere: within the sphere, near radius 1.
            let r = r.as_ref().unwrap().position.norm();
            assert!(r <= 1.0 + 1e-12 && r > 0.99, "radius {r}");
        }
        // The polyline is at least as long as the chord between the ends.
        assert!(curve.length() >= (last - first).norm());
    }

    #[test]
    fn chunking_does_not_change_the_curve() {
        let solver = sphere_solver(&[5, 400, 800, 1200, 1600]);
        let kind = SplineKind::Bezier;
        let a = evaluate_spline(&solver, kind, 120, 1).unwrap();
        let b = evaluate_spline(&solver, kind, 120, 120).unwrap();
        for (x, y) in a.samples.iter().zip(&b.samples) {
            let (x, y) = (x.as_ref().unwrap(), y.as_ref().unwrap());
            assert!((x.position - y.position).norm() < 1e-9);
        }
    }

    #[test]
    fn too_few_controls_is_an_error() {
        let solver = sphere_solver(&[0, 40, 300]);
        let kind = SplineKind::BSpline {
            degree: 3,
            closed: true,
        };
        assert!(matches!(
            evaluate_spline(&solver, kind, 10, 10),
            Err(SolveError::InvalidParameter(_))
        ));
    }
}
