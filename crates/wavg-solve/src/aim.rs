//! Where a warm start along a curve heads: the extrapolation of the two previous answers,
//! while the answers follow it.

use wavg_mesh::SurfacePoint;
use wavg_project::Vec8;

use crate::solver::Solver;

/// The aim of the next forward problem in a sequence of nearby ones (see
/// [`Solver::forward_aimed`]): `2 p1 - p0` from the two previous answers `p0`, `p1` (in
/// R^8), used only while the answers follow it: the last guess missed its answer by less
/// than half the step `|p1 - p0|` it extrapolated. Along a curve the miss is of second
/// order in the step; for unrelated queries (points in spatial order, say) it is not, and
/// each walk heads for its average as without an aim.
///
/// ```
/// use std::sync::Arc;
/// use wavg_mesh::{ValidMesh, procedural};
/// use wavg_solve::{Anchor, CurveAim, EmbeddedMesh, ForwardOptions, Projector, Solver};
/// let mesh = Arc::new(ValidMesh::new(procedural::icosphere(3)).unwrap());
/// let proj = Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh))).unwrap());
/// let solver = Solver::new(proj, [0u32, 100, 200].map(Anchor::Vertex)).unwrap();
/// let (mut aim, mut opts) = (CurveAim::default(), ForwardOptions::default());
/// for k in 0..20 {
///     let t = k as f64 / 20.0;
///     let w = [1.0 - t, t * 0.5, t * 0.5];
///     let r = solver.forward_aimed(&w, &opts, aim.aim().as_ref()).unwrap();
///     aim.record(&solver, &r.point);
///     opts = opts.warm(r.point);
/// }
/// assert!(aim.aim().is_some(), "the answers follow a straight blend");
/// ```
#[derive(Clone, Copy, Debug, Default)]
pub struct CurveAim {
    last: [Option<Vec8>; 2],
    aiming: bool,
}

impl CurveAim {
    /// The aim for the next query: the extrapolation, when it has been predicting well.
    pub fn aim(&self) -> Option<Vec8> {
        self.guess().filter(|_| self.aiming)
    }

    /// Records the next answer, `point`.
    pub fn record(&mut self, solver: &Solver, point: &SurfacePoint) {
        let p = solver.projector().embedded().point(point);
        let step = self.last[0].zip(self.last[1]).map(|(a, b)| (b - a).norm());
        self.aiming = self
            .guess()
            .zip(step)
            .is_some_and(|(g, step)| (g - p).norm() < 0.5 * step);
        self.last = [self.last[1], Some(p)];
    }

    fn guess(&self) -> Option<Vec8> {
        match self.last {
            [Some(a), Some(b)] => Some(b * 2.0 - a),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;
    use wavg_mesh::{ValidMesh, procedural};
    use wavg_project::{EmbeddedMesh, Projector};

    use crate::Anchor;

    /// Points at even steps along a line are followed (the guess is the next point); a
    /// jump away ends the aiming until the answers follow the guesses again.
    #[test]
    fn aims_while_the_answers_follow_the_extrapolation() {
        let mesh = Arc::new(ValidMesh::new(procedural::grid(20, 20, 1.0, 1.0)).unwrap());
        let emb = Arc::new(EmbeddedMesh::from_positions(mesh.clone()));
        let s = Solver::new(
            Arc::new(Projector::new(emb.clone()).unwrap()),
            [Anchor::Vertex(0)],
        )
        .unwrap();
        let x = emb.coords();
        let at = |u: f64, v: f64| {
            let mut q = Vec8::zeros();
            (q[0], q[1]) = (u, v);
            (0..mesh.n_faces() as u32)
                .find_map(|f| {
                    let t = mesh.triangles[f as usize].map(|i| x[i as usize]);
                    let b = wavg_project::closest_point_barycentric(&q, &t[0], &t[1], &t[2]);
                    let p = t[0] * b[0] + t[1] * b[1] + t[2] * b[2];
                    ((p - q).norm() < 1e-12).then_some(SurfacePoint::new(f, b))
                })
                .unwrap()
        };
        let mut aim = CurveAim::default();
        assert_eq!(aim.aim(), None);
        for k in 0..4 {
            aim.record(&s, &at(0.2 + 0.05 * k as f64, 0.3));
        }
        let next = emb.point(&at(0.4, 0.3));
        assert!((aim.aim().unwrap() - next).norm() < 1e-9);
        aim.record(&s, &at(0.9, 0.9));
        assert_eq!(aim.aim(), None);
        aim.record(&s, &at(0.8, 0.8));
        assert_eq!(aim.aim(), None, "a jump back is not following");
        aim.record(&s, &at(0.7, 0.7));
        assert!(aim.aim().is_some());
    }
}
