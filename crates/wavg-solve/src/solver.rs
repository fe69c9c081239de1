//! The forward problem (weights -> surface point) and the inverse problem (surface point
//! -> weights) for one anchor set, single and batched.

use std::sync::Arc;

use nalgebra::Vector3;
use rayon::prelude::*;
use wavg_mesh::{SurfacePoint, VertexId};
use wavg_project::{ProjectError, Projection, ProjectionPath};

use crate::anchors::AnchorSet;
use crate::error::SolveError;
use crate::kernel::{DEFAULT_GAMMA, InverseScratch, inverse_weights};
use crate::points::{check_point, nearest_corner};
use crate::search::LocalSearch;
use crate::weights::{Normalization, validate_weights};
use crate::{Mat2x8, Projector, Vec8};

/// Faces [`Solver::forward_embedded`] walks through from its start face (following
/// Newton's exits) before the full local search.
pub(crate) const FACE_WALK: usize = 4;

/// How the forward problem searches for the projection.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SearchMode {
    /// The paper's method (the local search): greedy walk from a start vertex, then a
    /// breadth-first search over triangles; the first triangle holding a valid projection
    /// wins. When none is found within `LOCAL_BUDGET` (96) triangles, the same
    /// search runs once more from the vertex nearest to the average; if that fails too, the
    /// projector's certified search is used (reported as [`ProjectionPath::Fallback`]).
    #[default]
    Fast,
    /// The projector's fast path certified against its bounding volume hierarchy: always
    /// the closest valid projection (slower when the average lies far off the surface).
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
    /// the highest-weight anchor.
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
    /// Nowhere: the exact mode searches every triangle.
    Exhaustive,
}

/// A validated forward query: the weighted average and where its search starts.
#[derive(Clone, Copy, Debug)]
struct Prepared {
    ybar: Vec8,
    start: Start,
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
    local: Arc<LocalSearch>,
    anchors: AnchorSet,
    gamma: f64,
    /// Mean 3-D edge length of the mesh (the unit of round-trip tolerances).
    mean_edge: f64,
}

impl Solver {
    /// A solver with the given anchors (validated) and `gamma` = [`DEFAULT_GAMMA`].
    pub fn new(
        projector: Arc<Projector>,
        anchors: impl IntoIterator<Item = crate::points::Anchor>,
    ) -> Result<Self, SolveError> {
        let set = AnchorSet::with_anchors(projector.embedded().clone(), anchors)?;
        Ok(Self {
            local: Arc::new(LocalSearch::new(projector.clone())),
            mean_edge: wavg_mesh::geometry::mean_edge_length(projector.embedded().mesh()),
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
            local: Arc::new(LocalSearch::new(projector.clone())),
            mean_edge: wavg_mesh::geometry::mean_edge_length(projector.embedded().mesh()),
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
        self.mean_edge
    }

    /// The projector.
    pub fn projector(&self) -> &Arc<Projector> {
        &self.projector
    }

    /// The local search used by [`SearchMode::Fast`] (for tests and experiments;
    /// **unstable**, like the crate's `internal` module).
    #[doc(hidden)]
    pub fn local_search(&self) -> &LocalSearch {
        &self.local
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
        let prepared = self.prepare(weights, opts)?;
        self.forward_prepared(&prepared, opts)
    }

    /// Forward problem for an average the caller formed: projects `ybar` (a point of R^8,
    /// typically `sum w_i y_i` over embedded surface points that change from query to query,
    /// such as the 2-4 corners of a remeshing stencil, where rebuilding an anchor set per
    /// query would cost more than the query) onto the surface. The search starts at the
    /// nearest corner of `opts.warm_start` when given, else of `near` (a point expected
    /// close to the answer, e.g. the highest-weight input point). With a warm start in
    /// [`SearchMode::Fast`], its face is tried first, then up to four faces that
    /// Newton's method exits into (a previous answer's face usually holds the new one when
    /// the inputs moved a little), before that search. The solver's own anchors
    /// are not used. A non-finite `ybar` is [`SolveError::InvalidParameter`].
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
        let start = match opts.mode {
            SearchMode::Exact => Start::Exhaustive,
            _ => {
                let p = check_point(self.mesh(), &opts.warm_start.unwrap_or(*near))?;
                let start = Start::Warm(nearest_corner(self.mesh(), &p));
                if opts.mode == SearchMode::Fast && opts.warm_start.is_some() {
                    let mut f = p.face;
                    for _ in 0..FACE_WALK {
                        match self.projector.project_onto_face_or_exit(ybar, f) {
                            Ok((xi, distance)) => {
                                let point = SurfacePoint::new(f, xi);
                                return Ok(ForwardResult {
                                    point,
                                    position: point.position(self.mesh()),
                                    distance,
                                    path: ProjectionPath::Local,
                                    start,
                                });
                            }
                            Err(g) if g != wavg_mesh::NONE => f = g,
                            Err(_) => break,
                        }
                    }
                }
                start
            }
        };
        self.forward_prepared(&Prepared { ybar: *ybar, start }, opts)
    }

    /// The part of the forward problem that reads the weights: validation, the average and
    /// the start vertex. Split off so a batch can read every weight row once, in input
    /// order, and then search in the order of the averages' positions.
    fn prepare(&self, weights: &[f64], opts: &ForwardOptions) -> Result<Prepared, SolveError> {
        let ybar = self.average(weights, opts.normalization)?;
        let start = match (opts.mode, opts.warm_start) {
            (SearchMode::Exact, _) => Start::Exhaustive,
            (_, Some(p)) => {
                Start::Warm(nearest_corner(self.mesh(), &check_point(self.mesh(), &p)?))
            }
            (_, None) => {
                // Highest weight; ties to the lowest index.
                let mut anchor = 0;
                for (i, &w) in weights.iter().enumerate() {
                    if w > weights[anchor] {
                        anchor = i;
                    }
                }
                Start::HighestWeight {
                    anchor,
                    vertex: self.anchors.starts()[anchor],
                }
            }
        };
        Ok(Prepared { ybar, start })
    }

    /// The search part of [`Solver::forward`], from a prepared average and start.
    fn forward_prepared(
        &self,
        prepared: &Prepared,
        opts: &ForwardOptions,
    ) -> Result<ForwardResult, SolveError> {
        let Prepared { ybar, start } = *prepared;
        let mesh = self.mesh();
        let proj = match start {
            Start::Exhaustive => self.projector.project_exhaustive(&ybar),
            Start::Warm(v) | Start::HighestWeight { vertex: v, .. } => {
                let found = match opts.mode {
                    // The paper's search; when the walk ends in a local minimum with no
                    // projection nearby, once more from the nearest vertex (much cheaper than
                    // the certified global search, and usually its answer).
                    SearchMode::Fast => self
                        .local
                        .search(&ybar, v)
                        .or_else(|| {
                            let u = self.local.nearest_vertex(&ybar);
                            self.local.search_at(&ybar, u)
                        })
                        .map(|h| Projection {
                            point: h.point,
                            distance: h.distance,
                            path: ProjectionPath::Local,
                        }),
                    _ => None,
                };
                match found {
                    Some(p) => Ok(p),
                    None => self.projector.project(&ybar, v).map(|mut p| {
                        if opts.mode == SearchMode::Fast {
                            p.path = ProjectionPath::Fallback;
                        }
                        p
                    }),
                }
            }
        };
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

    /// Forward problem for many weight vectors in parallel; result `i` belongs to
    /// `weights[i]`. Every query is independent, so the results do not depend on the
    /// number of threads. The weight rows are read once, in input order, into their averages;
    /// the searches then run in the Morton order of the averages (nearby queries together,
    /// so they share cached mesh data). Each still starts from its own highest-weight anchor (or warm start), so
    /// the results equal [`Solver::forward`]'s.
    pub fn forward_batch<W: AsRef<[f64]> + Sync>(
        &self,
        weights: &[W],
        opts: &ForwardOptions,
    ) -> Vec<Result<ForwardResult, SolveError>> {
        // The weight rows are read once, in input order (streaming), into averages and
        // start vertices; a failed validation is the query's answer.
        let mut prepared = Vec::with_capacity(weights.len());
        weights
            .par_iter()
            .with_min_len(256)
            .map(|w| self.prepare(w.as_ref(), opts))
            .collect_into_vec(&mut prepared);
        let keys: Vec<(u64, u32)> = prepared
            .par_iter()
            .with_min_len(1024)
            .enumerate()
            .map(|(i, p)| {
                let key = match p {
                    Ok(p) => u64::from(wavg_project::internal::locality_key(
                        &self.projector,
                        &p.ybar,
                    )),
                    Err(_) => u64::MAX,
                };
                (key, i as u32)
            })
            .collect();
        let order = sorted_order(keys);
        // In this order the prepared queries are read at random: each query first waits
        // for its record, so the record two queries ahead is requested early.
        const AHEAD: usize = 2;
        let mut done = Vec::with_capacity(order.len());
        order
            .par_iter()
            .enumerate()
            .with_min_len(64)
            .map(|(k, &i)| {
                if let Some(&j) = order.get(k + AHEAD) {
                    wavg_project::internal::prefetch(&prepared[j as usize]);
                }
                match &prepared[i as usize] {
                    Ok(p) => self.forward_prepared(p, opts),
                    Err(e) => Err(e.clone()),
                }
            })
            .collect_into_vec(&mut done);
        unpermute(&order, &done)
    }

    /// Forward problem for a sequence of nearby queries (e.g. samples along a curve):
    /// each query warm-starts from the previous answer. For parallelism the sequence is cut
    /// into chunks of `chunk` queries (independent of the thread count, so the results are
    /// too); the first query of each chunk starts cold (or from `opts.warm_start`).
    pub fn forward_batch_warm<W: AsRef<[f64]> + Sync>(
        &self,
        weights: &[W],
        opts: &ForwardOptions,
        chunk: usize,
    ) -> Vec<Result<ForwardResult, SolveError>> {
        weights
            .par_chunks(chunk.max(1))
            .flat_map_iter(|c| {
                let mut o = *opts;
                c.iter()
                    .map(move |w| {
                        let r = self.forward(w.as_ref(), &o);
                        if let Ok(r) = &r {
                            o.warm_start = Some(r.point);
                        }
                        r
                    })
                    .collect::<Vec<_>>()
            })
            .collect()
    }

    /// Inverse problem for many points in parallel (see [`BatchWeights`]); each point is
    /// independent, so the results equal [`Solver::inverse`]'s for any thread count.
    pub fn inverse_batch(&self, points: &[SurfacePoint]) -> BatchWeights {
        let mut out = BatchWeights::default();
        self.inverse_batch_into(points, &mut out);
        out
    }

    /// [`Solver::inverse_batch`] into an existing result, reusing its memory (repeated
    /// batches then neither allocate nor page-fault).
    pub fn inverse_batch_into(&self, points: &[SurfacePoint], out: &mut BatchWeights) {
        let n = self.n_anchors();
        out.n = n;
        out.data.resize(points.len() * n.max(1), 0.0);
        out.status.clear();
        // Random points read random face records and then their corners' records: request
        // both a few points ahead (software pipelining), so the waits overlap.
        const CHUNK: usize = 64;
        let proj = &self.projector;
        let status = out
            .data
            .par_chunks_mut(n.max(1) * CHUNK)
            .zip(points.par_chunks(CHUNK))
            .flat_map_iter(|(rows, pts)| {
                let mut scratch = InverseScratch::default();
                let mut buf = Vec::with_capacity(n);
                let ahead = |k: usize| pts.get(k).map(|p| p.face);
                for f in (0..4).filter_map(ahead) {
                    wavg_project::internal::prefetch_point_data(proj, f, false);
                }
                let mut status = Vec::with_capacity(pts.len());
                for (k, (row, p)) in rows.chunks_mut(n.max(1)).zip(pts).enumerate() {
                    if let Some(f) = ahead(k + 4) {
                        wavg_project::internal::prefetch_point_data(proj, f, false);
                    }
                    if let Some(f) = ahead(k + 2) {
                        wavg_project::internal::prefetch_point_data(proj, f, true);
                    }
                    let r = self.inverse_into(p, &mut scratch, &mut buf);
                    if r.is_ok() {
                        row.copy_from_slice(&buf);
                    }
                    status.push(r);
                }
                status
            });
        // In order (`par_extend` keeps the order of an ordered iterator).
        out.status.par_extend(status);
    }
}

/// Indices sorted by key (ties by index, so the order is deterministic).
fn sorted_order(mut keys: Vec<(u64, u32)>) -> Vec<u32> {
    keys.par_sort_unstable();
    keys.into_iter().map(|(_, i)| i).collect()
}

/// Results computed in `order` (`done[k]` belongs to input `order[k]`), back in input
/// order: one parallel gather into place, no intermediate lists (which cost about 10% of
/// a small mesh's forward batch in reallocations and page faults).
fn unpermute<T: Clone + Send + Sync>(order: &[u32], done: &[T]) -> Vec<T> {
    let mut pos = vec![0u32; order.len()];
    for (k, &i) in order.iter().enumerate() {
        pos[i as usize] = k as u32;
    }
    pos.par_iter().map(|&k| done[k as usize].clone()).collect()
}

/// Weights of a batch of inverse problems: one row of `n_anchors` weights per point.
#[derive(Clone, Debug, Default)]
pub struct BatchWeights {
    n: usize,
    data: Vec<f64>,
    status: Vec<Result<(), SolveError>>,
}

impl BatchWeights {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.status.len()
    }

    /// Whether the batch is empty.
    pub fn is_empty(&self) -> bool {
        self.status.is_empty()
    }

    /// Weights of point `i`, or why there are none.
    pub fn get(&self, i: usize) -> Result<&[f64], &SolveError> {
        match &self.status[i] {
            Ok(()) => Ok(&self.data[i * self.n..(i + 1) * self.n]),
            Err(e) => Err(e),
        }
    }

    /// All rows in order.
    pub fn iter(&self) -> impl Iterator<Item = Result<&[f64], &SolveError>> {
        (0..self.len()).map(|i| self.get(i))
    }

    /// Replaces row `i` with `w` (the anchor count long) or marks it failed.
    pub(crate) fn set(&mut self, i: usize, w: Result<&[f64], SolveError>) {
        match w {
            Ok(w) => {
                self.data[i * self.n..(i + 1) * self.n].copy_from_slice(w);
                self.status[i] = Ok(());
            }
            Err(e) => self.status[i] = Err(e),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn batch_ordering_helpers() {
        assert_eq!(
            sorted_order(vec![(3, 0), (1, 1), (3, 2), (0, 3)]),
            vec![3, 1, 0, 2]
        );
        assert_eq!(unpermute(&[2, 0, 1], &['c', 'a', 'b']), vec!['a', 'b', 'c']);
    }
}
