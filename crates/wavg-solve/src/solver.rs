//! The forward problem (weights -> surface point) and the inverse problem (surface point
//! -> weights) for one anchor set, single and batched.

use std::sync::Arc;

use nalgebra::Vector3;
use wavg_mesh::{FaceId, SurfacePoint, VertexId};
use wavg_project::{ProjectError, ProjectionPath, SearchGoal};

use crate::anchors::AnchorSet;
use crate::error::SolveError;
use crate::kernel::{DEFAULT_GAMMA, InverseScratch, inverse_weights};
use crate::points::{check_point, nearest_corner};
use crate::weights::{Normalization, validate_weights};
use crate::{Mat2x8, Projector, Vec8};

/// How the forward problem searches for the projection.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SearchMode {
    /// The paper's method: the projector's local search for the first valid projection
    /// ([`SearchGoal::FirstHit`]): greedy walk from a start vertex, then a breadth-first
    /// search over triangles; with a warm start, the previous answer's face and the faces
    /// Newton's method exits into are tried first. Answers are
    /// [`ProjectionPath::Local`], or [`ProjectionPath::Fallback`] when the global search
    /// had to answer.
    #[default]
    Fast,
    /// The projector's local search certified against its bounding volume hierarchy
    /// ([`SearchGoal::Closest`]): always the closest valid projection (slower when the
    /// average lies far off the surface).
    Certified,
    /// Exhaustive search over all triangles for the closest valid projection.
    Exact,
}

/// Options of the forward problem.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ForwardOptions {
    /// Fast (default) or exact search.
    pub mode: SearchMode,
    /// Reject (default) or normalise weights that do not sum to 1.
    pub normalization: Normalization,
    /// The previous answer, if any: the search starts from its nearest corner instead of
    /// the highest-weight anchor, and [`SearchMode::Fast`] tries its face first.
    pub warm_start: Option<SurfacePoint>,
}

impl ForwardOptions {
    /// These options with a warm start.
    pub fn warm(self, previous: SurfacePoint) -> Self {
        Self {
            warm_start: Some(previous),
            ..self
        }
    }
}

/// Where the forward search started.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Start {
    /// At the nearest corner of the warm start.
    Warm(VertexId),
    /// At the start vertex of the anchor with the highest weight.
    HighestWeight {
        /// The anchor.
        anchor: usize,
        /// Its start vertex.
        vertex: VertexId,
    },
    /// At a vertex near the average ([`Projector::start_near`]), closer to it than the
    /// start vertex of the anchor with the highest weight.
    Located {
        /// The anchor with the highest weight.
        anchor: usize,
        /// The vertex.
        vertex: VertexId,
    },
    /// Nowhere: the exact mode searches every triangle.
    Exhaustive,
}

/// A validated forward query: the weighted average and where its search starts.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Prepared {
    pub(crate) ybar: Vec8,
    start: Start,
    /// The warm start's face, tried first by the fast search.
    hint: Option<FaceId>,
    /// Where the walk over faces from `hint` heads (see [`Projector::project_aimed`]);
    /// `None`: the average itself.
    pub(crate) aim: Option<Vec8>,
}

/// The index of the highest of (finite, validated) `weights`, ties to the lowest index:
/// the maximum in four running lanes, then its first position.
fn highest(weights: &[f64]) -> usize {
    let mut lanes = [f64::NEG_INFINITY; 4];
    let chunks = weights.chunks_exact(4);
    for &w in chunks.remainder() {
        lanes[0] = if w > lanes[0] { w } else { lanes[0] };
    }
    for c in chunks {
        for (l, &w) in lanes.iter_mut().zip(c) {
            *l = if w > *l { w } else { *l };
        }
    }
    let max = lanes
        .into_iter()
        .fold(f64::NEG_INFINITY, |m, l| if l > m { l } else { m });
    weights.iter().position(|&w| w == max).unwrap_or(0)
}

/// Answer of the forward problem.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForwardResult {
    /// The weighted average on the surface.
    pub point: SurfacePoint,
    /// Its 3-D position.
    pub position: Vector3<f64>,
    /// Distance in R^8 between the averaged point and its projection.
    pub distance: f64,
    /// Which search of the projector found it.
    pub path: ProjectionPath,
    /// Where the search started.
    pub start: Start,
}

/// Forward and inverse problems for one anchor set on one projector.
///
/// ```
/// use std::sync::Arc;
/// use wavg_mesh::{SurfacePoint, ValidMesh, procedural};
/// use wavg_solve::{Anchor, EmbeddedMesh, ForwardOptions, Projector, Solver};
/// let mesh = Arc::new(ValidMesh::new(procedural::icosphere(3)).unwrap());
/// let proj = Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh))).unwrap());
/// let anchors = [0u32, 50, 100, 200, 300, 400, 500, 600].map(Anchor::Vertex);
/// let solver = Solver::new(proj, anchors).unwrap();
/// let x = SurfacePoint::new(10, [0.2, 0.3, 0.5]);
/// let w = solver.inverse(&x).unwrap();
/// assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
/// let back = solver.forward(&w, &ForwardOptions::default()).unwrap();
/// assert!((back.position - x.position(solver.mesh())).norm() < 1e-6);
/// ```
#[derive(Clone)]
pub struct Solver {
    projector: Arc<Projector>,
    anchors: AnchorSet,
    gamma: f64,
}

impl Solver {
    /// A solver with the given anchors (validated) and `gamma` = [`DEFAULT_GAMMA`].
    pub fn new(
        projector: Arc<Projector>,
        anchors: impl IntoIterator<Item = crate::points::Anchor>,
    ) -> Result<Self, SolveError> {
        let set = AnchorSet::with_anchors(projector.embedded().clone(), anchors)?;
        Ok(Self {
            projector,
            anchors: set,
            gamma: DEFAULT_GAMMA,
        })
    }

    /// A solver over an existing anchor set (which must live on the projector's mesh).
    pub fn with_anchor_set(
        projector: Arc<Projector>,
        anchors: AnchorSet,
    ) -> Result<Self, SolveError> {
        if !Arc::ptr_eq(anchors.embedded(), projector.embedded()) {
            return Err(SolveError::InvalidParameter(
                "the anchor set belongs to a different embedded mesh".into(),
            ));
        }
        Ok(Self {
            projector,
            anchors,
            gamma: DEFAULT_GAMMA,
        })
    }

    /// Sets the inverse problem's `gamma` (> 0; the paper uses 10).
    pub fn set_gamma(&mut self, gamma: f64) -> Result<(), SolveError> {
        if !(gamma.is_finite() && gamma > 0.0) {
            return Err(SolveError::InvalidParameter(format!(
                "gamma must be finite and positive, got {gamma}"
            )));
        }
        self.gamma = gamma;
        Ok(())
    }

    /// The inverse problem's `gamma`.
    pub fn gamma(&self) -> f64 {
        self.gamma
    }

    /// Mean 3-D edge length of the mesh (the unit of round-trip tolerances).
    ///
    /// ```
    /// use std::sync::Arc;
    /// use wavg_mesh::{ValidMesh, procedural};
    /// use wavg_solve::{Anchor, EmbeddedMesh, Projector, Solver};
    /// let m = Arc::new(ValidMesh::new(procedural::grid(4, 4, 1.0, 1.0)).unwrap());
    /// let p = Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(m))).unwrap());
    /// let s = Solver::new(p, (0..3).map(Anchor::Vertex)).unwrap();
    /// assert!(s.mean_edge_length() > 0.25 && s.mean_edge_length() < 0.36);
    /// ```
    pub fn mean_edge_length(&self) -> f64 {
        self.projector.mesh_mean_edge_length()
    }

    /// The projector.
    pub fn projector(&self) -> &Arc<Projector> {
        &self.projector
    }

    /// The mesh.
    pub fn mesh(&self) -> &wavg_mesh::ValidMesh {
        self.projector.embedded().mesh()
    }

    /// The anchors.
    pub fn anchors(&self) -> &AnchorSet {
        &self.anchors
    }

    /// The anchors, for editing (add, move, remove).
    pub fn anchors_mut(&mut self) -> &mut AnchorSet {
        &mut self.anchors
    }

    /// Number of anchors (the length every weight vector must have).
    pub fn n_anchors(&self) -> usize {
        self.anchors.len()
    }

    /// The weighted average `sum w_i y_i` in R^8 of validated weights.
    pub fn average(&self, weights: &[f64], norm: Normalization) -> Result<Vec8, SolveError> {
        let scale = validate_weights(weights, self.n_anchors(), norm)?;
        Ok(self.anchors.coords().weighted_sum(weights, scale))
    }

    /// Forward problem: the point of the surface that is the weighted average of the
    /// anchors. [`SolveError::NoWeightedAverage`] when the averaged point has no Phong
    /// projection.
    pub fn forward(
        &self,
        weights: &[f64],
        opts: &ForwardOptions,
    ) -> Result<ForwardResult, SolveError> {
        self.forward_aimed(weights, opts, None)
    }

    /// [`Solver::forward`] whose warm start heads for the face under `aim` (a point of
    /// R^8 near where the answer is expected) before Newton's method, instead of the face
    /// under the average: along a curve the answer trails the face under the average, and
    /// the extrapolation of the two previous answers usually lies over its face (see
    /// [`CurveAim`](crate::CurveAim), what [`Solver::forward_batch_warm`] passes). Only
    /// the route of the search
    /// changes, and only with `opts.warm_start` in [`SearchMode::Fast`]; a non-finite or
    /// missing `aim` heads for the average.
    pub fn forward_aimed(
        &self,
        weights: &[f64],
        opts: &ForwardOptions,
        aim: Option<&Vec8>,
    ) -> Result<ForwardResult, SolveError> {
        let mut prepared = self.prepare(weights, opts)?;
        prepared.aim = aim.copied();
        self.forward_prepared(&prepared, opts)
    }

    /// Forward problem for an average the caller formed: projects `ybar` (a point of R^8,
    /// typically `sum w_i y_i` over embedded surface points that change from query to query,
    /// such as the 2-4 corners of a remeshing stencil, where rebuilding an anchor set per
    /// query would cost more than the query) onto the surface. The search starts at the
    /// nearest corner of `opts.warm_start` when given, else of `near` (a point expected
    /// close to the answer, e.g. the highest-weight input point). With a warm start in
    /// [`SearchMode::Fast`], the face the average lies over is tried first (found within
    /// [`wavg_project::HINT_STEPS`] steps over faces from the warm start's face), then up
    /// to [`wavg_project::FACE_WALK`] faces in all that Newton's method exits into (a
    /// previous answer's face or a neighbour usually holds the new one when the inputs
    /// moved a little), before that search. The solver's own anchors are not used. A non-finite `ybar` is
    /// [`SolveError::InvalidParameter`].
    pub fn forward_embedded(
        &self,
        ybar: &Vec8,
        near: &SurfacePoint,
        opts: &ForwardOptions,
    ) -> Result<ForwardResult, SolveError> {
        if !ybar.iter().all(|v| v.is_finite()) {
            return Err(SolveError::InvalidParameter(
                "the averaged point is not finite".into(),
            ));
        }
        let (start, hint) = match opts.mode {
            SearchMode::Exact => (Start::Exhaustive, None),
            _ => {
                let p = check_point(self.mesh(), &opts.warm_start.unwrap_or(*near))?;
                let hint = opts.warm_start.map(|_| p.face);
                (Start::Warm(nearest_corner(self.mesh(), &p)), hint)
            }
        };
        let prepared = Prepared {
            ybar: *ybar,
            start,
            hint,
            aim: None,
        };
        self.forward_prepared(&prepared, opts)
    }

    /// The part of the forward problem that reads the weights: validation, the average and
    /// the start vertex. Split off so a batch can read every weight row once, in input
    /// order, and then search in the order of the averages' positions.
    pub(crate) fn prepare(
        &self,
        weights: &[f64],
        opts: &ForwardOptions,
    ) -> Result<Prepared, SolveError> {
        let ybar = self.average(weights, opts.normalization)?;
        let mut hint = None;
        let start = match (opts.mode, opts.warm_start) {
            (SearchMode::Exact, _) => Start::Exhaustive,
            (_, Some(p)) => {
                let p = check_point(self.mesh(), &p)?;
                hint = Some(p.face);
                Start::Warm(nearest_corner(self.mesh(), &p))
            }
            (_, None) => {
                let anchor = highest(weights);
                Start::HighestWeight {
                    anchor,
                    vertex: self.anchors.starts()[anchor],
                }
            }
        };
        Ok(Prepared {
            ybar,
            start,
            hint,
            aim: None,
        })
    }

    /// The search part of [`Solver::forward`], from a prepared average and start.
    pub(crate) fn forward_prepared(
        &self,
        prepared: &Prepared,
        opts: &ForwardOptions,
    ) -> Result<ForwardResult, SolveError> {
        let Prepared {
            ybar,
            mut start,
            hint,
            aim,
        } = *prepared;
        if let Start::HighestWeight { anchor, vertex } = start {
            // Here rather than in `prepare`: batches search in spatial order, so the
            // lookups of nearby queries share cached data.
            let v = self.projector.start_near(&ybar, vertex);
            if v != vertex {
                start = Start::Located { anchor, vertex: v };
            }
        }
        let proj = match start {
            Start::Exhaustive => self.projector.project_exhaustive(&ybar),
            Start::Warm(v)
            | Start::HighestWeight { vertex: v, .. }
            | Start::Located { vertex: v, .. } => match opts.mode {
                SearchMode::Fast => {
                    self.projector
                        .project_aimed(&ybar, v, hint, aim.as_ref(), SearchGoal::FirstHit)
                }
                _ => self.projector.project(&ybar, v),
            },
        };
        self.forward_result(proj, start)
    }

    /// The goal of a prepared query's search when it can run in a group of
    /// [`wavg_project::internal::project_group`] (a cold start and no hint: the start
    /// lookup, the walk and the local search from its anchor's vertex), else `None`.
    pub(crate) fn group_goal(prepared: &Prepared, opts: &ForwardOptions) -> Option<SearchGoal> {
        match (prepared.start, prepared.hint, opts.mode) {
            (Start::HighestWeight { .. }, None, SearchMode::Fast) => Some(SearchGoal::FirstHit),
            (Start::HighestWeight { .. }, None, SearchMode::Certified) => Some(SearchGoal::Closest),
            _ => None,
        }
    }

    /// [`Solver::forward_prepared`] for up to `WALK_GROUP` prepared queries that all have
    /// the [`Solver::group_goal`] `goal`, their memory waits overlapped (the same results);
    /// pushed to `out` in order.
    pub(crate) fn forward_group(
        &self,
        group: &[&Prepared],
        goal: SearchGoal,
        out: &mut Vec<Result<ForwardResult, SolveError>>,
    ) {
        use wavg_project::internal::{WALK_GROUP, project_group};
        let m = group.len().min(WALK_GROUP);
        let mut ys = [Vec8::zeros(); WALK_GROUP];
        let mut starts = [0 as VertexId; WALK_GROUP];
        let mut anchors = [(0usize, 0 as VertexId); WALK_GROUP];
        for (k, p) in group[..m].iter().enumerate() {
            ys[k] = p.ybar;
            if let Start::HighestWeight { anchor, vertex } = p.start {
                (starts[k], anchors[k]) = (vertex, (anchor, vertex));
            }
        }
        let mut found = Vec::with_capacity(m);
        project_group(
            &self.projector,
            &ys[..m],
            &mut starts[..m],
            true,
            goal,
            &mut found,
        );
        // The answers' corner positions, requested before any is read.
        for p in found.iter().flatten() {
            let c = self.projector.face_corners(p.point.face);
            for v in c {
                if let Some(x) = self.mesh().positions.get(v as usize) {
                    wavg_project::internal::prefetch(x);
                }
            }
        }
        for (k, proj) in found.into_iter().enumerate() {
            let (anchor, vertex) = anchors[k];
            let start = if starts[k] == vertex {
                Start::HighestWeight { anchor, vertex }
            } else {
                Start::Located {
                    anchor,
                    vertex: starts[k],
                }
            };
            out.push(self.forward_result(proj, start));
        }
    }

    /// A forward answer from the projection of the average, searched from `start`.
    fn forward_result(
        &self,
        proj: Result<wavg_project::Projection, ProjectError>,
        start: Start,
    ) -> Result<ForwardResult, SolveError> {
        let mesh = self.mesh();
        let p = proj.map_err(|e| match e {
            ProjectError::NoProjection => SolveError::NoWeightedAverage,
            e => SolveError::Project(e),
        })?;
        Ok(ForwardResult {
            point: p.point,
            // Corners from the projector's face record (in cache): one lookup fewer.
            position: {
                let c = self.projector.face_corners(p.point.face);
                let pos = &mesh.positions;
                pos[c[0] as usize] * p.point.bary[0]
                    + pos[c[1] as usize] * p.point.bary[1]
                    + pos[c[2] as usize] * p.point.bary[2]
            },
            distance: p.distance,
            path: p.path,
            start,
        })
    }

    /// Inverse problem: weights (one per anchor, summing to 1) whose weighted average is
    /// `point`: the paper's minimum-norm weights with `D_ii = |v_T|^2 + gamma |v_O|^2`.
    pub fn inverse(&self, point: &SurfacePoint) -> Result<Vec<f64>, SolveError> {
        let mut out = Vec::with_capacity(self.n_anchors());
        self.inverse_into(point, &mut InverseScratch::default(), &mut out)?;
        Ok(out)
    }

    /// [`Solver::inverse`] into caller-owned buffers (no allocation once they are sized).
    pub fn inverse_into(
        &self,
        point: &SurfacePoint,
        scratch: &mut InverseScratch,
        out: &mut Vec<f64>,
    ) -> Result<(), SolveError> {
        let p = check_point(self.mesh(), point)?;
        let (psi, yhat) = self.tangent_plane(&p);
        inverse_weights(&psi, &yhat, self.anchors.coords(), self.gamma, scratch, out)
    }

    /// The tangent plane the inverse problem uses at a checked point, and the embedded
    /// point: the interpolated `Psi`, except where it (nearly) loses rank, which happens
    /// where a triangle's corner frames disagree in orientation (the embedding folds, as
    /// on thin extremities): there `Psi` blends a rotation with a reflection. The frame of
    /// the nearest corner is used instead; at a vertex it spans the tangent plane exactly.
    pub(crate) fn tangent_plane(&self, p: &SurfacePoint) -> (Mat2x8, Vec8) {
        let (psi, y) = self.projector.psi_and_point(p);
        let g00 = psi.row(0).norm_squared();
        let g11 = psi.row(1).norm_squared();
        let g01 = psi.row(0).dot(&psi.row(1));
        // det(G) = s_min^2 s_max^2: the smaller singular value below 1% of the larger.
        if g00 * g11 - g01 * g01 > 1e-4 * g00.max(g11).powi(2) {
            return (psi, y);
        }
        let k = (0..3)
            .max_by(|&a, &b| p.bary[a].total_cmp(&p.bary[b]))
            .unwrap_or(0);
        let v = self.projector.face_corners(p.face)[k];
        (self.projector.frame(v), y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first index of the largest weight, as a scan with a strict comparison finds
    /// it, for lengths around the lane count, ties and signed zeros.
    #[test]
    fn highest_is_the_first_largest() {
        let scan = |w: &[f64]| {
            let mut a = 0;
            for (i, &x) in w.iter().enumerate() {
                if x > w[a] {
                    a = i;
                }
            }
            a
        };
        for n in 1..40usize {
            for pattern in 0..6u64 {
                let w: Vec<f64> = (0..n as u64)
                    .map(|i| match pattern {
                        0 => ((i * 7919 + 13) % 31) as f64 - 15.0,
                        1 => 1.0,
                        2 => {
                            if i % 3 == 0 {
                                -0.0
                            } else {
                                0.0
                            }
                        }
                        3 => -(i as f64),
                        4 => i as f64,
                        _ => ((i * 31) % 5) as f64,
                    })
                    .collect();
                assert_eq!(highest(&w), scan(&w), "n {n}, pattern {pattern}: {w:?}");
            }
        }
    }

    #[test]
    fn forward_embedded_equals_forward_with_the_same_average() {
        use crate::{Anchor, EmbeddedMesh};
        use wavg_mesh::{ValidMesh, procedural};
        let mesh = Arc::new(ValidMesh::new(procedural::torus(48, 16, 1.0, 0.35)).unwrap());
        let proj = Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh))).unwrap());
        let pts = [
            SurfacePoint::new(10, [0.2, 0.3, 0.5]),
            SurfacePoint::new(40, [0.6, 0.2, 0.2]),
            SurfacePoint::new(75, [0.1, 0.1, 0.8]),
        ];
        let solver = Solver::new(proj.clone(), pts.map(Anchor::Point)).unwrap();
        let plain = Solver::new(proj.clone(), std::iter::empty()).unwrap();
        let w = [0.5, 0.3, 0.2];
        let want = solver.forward(&w, &ForwardOptions::default()).unwrap();
        let y: Vec8 = pts
            .iter()
            .zip(w)
            .map(|(p, w)| proj.embedded().point(p) * w)
            .sum();
        let opts = ForwardOptions::default();
        let cold = plain.forward_embedded(&y, &pts[0], &opts).unwrap();
        let warm = plain
            .forward_embedded(&y, &pts[0], &opts.warm(want.point))
            .unwrap();
        for r in [cold, warm] {
            assert!((r.position - want.position).norm() < 1e-9);
        }
        assert_eq!(warm.point.face, want.point.face);
        let mut bad = y;
        bad[0] = f64::NAN;
        assert!(matches!(
            plain.forward_embedded(&bad, &pts[0], &opts),
            Err(SolveError::InvalidParameter(_))
        ));
    }
}
