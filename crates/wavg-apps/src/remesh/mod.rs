//! Semiregular remeshing with Laplacian smoothing on the surface (paper Section 4.1).
//!
//! A coarse base mesh (triangles, quads, larger polygons) is put on the surface (each base
//! vertex at its closest surface point in 3-D), then split `levels` times: every edge
//! gets the weighted average of its two ends (weights 1/2, 1/2), every polygon with `n >= 4`
//! corners a face point, the average of its corners (weights 1/n: 1/4 for a quad), and
//! the polygon becomes `n` quads; a triangle becomes four triangles from its edge points
//! alone. Then `smooth` Jacobi steps of uniform Laplacian smoothing move every interior
//! vertex to the average of its edge neighbours (all from the previous step's points);
//! vertices on the boundary of an open base stay where subdivision put them.
//!
//! Every average is a forward problem over its own 2 to `n` points, which change from
//! query to query: the embedded points `y(p)` of the surface points are averaged in R^8
//! and projected with [`Solver::forward_embedded`]. A first run starts each search at
//! the stencil's first point (smoothing: in the vertex's own face); later runs (after
//! [`Remesher::move_base_vertex`]) start every vertex of every stage from its own answer
//! (its face first) in the previous run, so dragging a base vertex recomputes
//! interactively.

mod base;
mod defaults;
mod obj;
mod plan;

use std::sync::Arc;

use nalgebra::Vector3;
use rayon::prelude::*;
use wavg_mesh::SurfacePoint;
use wavg_solve::{
    EmbeddedMesh, ForwardOptions, ProjectionPath, Projector, SolveError, Solver, Vec8,
};

pub use base::{BaseMesh, MAX_POLYGON, RemeshError};
pub use defaults::{
    DEFAULT_CAGE_VERTICES, DEFAULT_LEVELS, DEFAULT_SMOOTH_STEPS, MAX_CAGE_VERTICES,
    MIN_CAGE_VERTICES, default_cage_vertices, max_cage_vertices,
};
pub use obj::polygons_to_obj;
use plan::{Plan, Stencils};

/// Most levels of splitting accepted (each multiplies the face count by about four).
pub const MAX_LEVELS: usize = 8;

/// Most smoothing steps [`Remesher::remesh`] takes: each step's answers are kept as the
/// next run's warm starts, so memory grows with the steps (a few are typical; smoothing
/// has long converged after this many).
pub const MAX_SMOOTH_STEPS: usize = 1000;

/// Default largest distance of a base vertex from the surface, over the surface's
/// bounding-box diagonal: generous, since the control cage of a subdivision surface lies
/// several percent of the diagonal off the surface, yet a base in other coordinates (or
/// scaled) is refused.
pub const DEFAULT_MAX_BASE_DISTANCE: f64 = 0.15;

/// Checks a largest base-vertex distance from the surface (over the bounding-box
/// diagonal): finite and positive.
pub fn check_max_base_distance(max_distance: f64) -> Result<(), RemeshError> {
    if max_distance.is_finite() && max_distance > 0.0 {
        return Ok(());
    }
    Err(RemeshError::InvalidParameter(format!(
        "the largest base distance must be finite and positive (a fraction of the \
         bounding-box diagonal, {DEFAULT_MAX_BASE_DISTANCE} by default), got {max_distance}"
    )))
}

/// The refined mesh of one run.
#[derive(Clone, Debug)]
pub struct RemeshResult {
    /// Every output vertex on the surface (base vertices first, then each level's new
    /// vertices).
    pub points: Vec<SurfacePoint>,
    /// Their 3-D positions.
    pub positions: Vec<Vector3<f64>>,
    /// Output polygons (quads where the base had polygons of four or more corners,
    /// triangles where it had triangles), counter-clockwise like the base.
    pub faces: Arc<Vec<Vec<u32>>>,
    /// Levels of splitting.
    pub levels: usize,
    /// Smoothing steps.
    pub smooth_steps: usize,
    /// Forward problems solved.
    pub problems: usize,
    /// Of these, how many needed the projector's certified search after the local search
    /// failed.
    pub fallbacks: usize,
}

/// What one remeshing came to; with the `serde` feature, the `wavg remesh --json` keys.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RemeshReport {
    /// Base vertices.
    pub base_vertices: usize,
    /// Base polygons.
    pub base_faces: usize,
    /// Output vertices.
    pub vertices: usize,
    /// Output polygons.
    pub faces: usize,
    /// [`RemeshResult::levels`].
    pub levels: usize,
    /// [`RemeshResult::smooth_steps`].
    pub smooth_steps: usize,
    /// [`Remesher::max_offsurface`] of the output vertices.
    pub max_offsurface: f64,
    /// [`RemeshResult::roughness`].
    pub roughness: f64,
    /// [`RemeshResult::problems`].
    pub problems: usize,
    /// [`RemeshResult::fallbacks`].
    pub fallbacks: usize,
}

impl RemeshResult {
    /// Roughness of the mesh: the mean length of the umbrella vector (a vertex's offset
    /// from the 3-D centroid of its edge neighbours) over the vertices with neighbours,
    /// divided by the mean edge length; 0 for a perfectly evened-out mesh.
    pub fn roughness(&self) -> f64 {
        let s = plan::smoothing_stencils(self.positions.len(), &self.faces);
        let p = &self.positions;
        let (mut sum, mut n) = (0.0, 0usize);
        for v in 0..s.len() {
            let nb = s.get(v);
            if nb.is_empty() {
                continue;
            }
            let c = nb.iter().map(|&u| p[u as usize]).sum::<Vector3<f64>>() / nb.len() as f64;
            sum += (p[v] - c).norm();
            n += 1;
        }
        let (mut len, mut m) = (0.0, 0usize);
        for f in self.faces.iter() {
            for (a, b) in base::polygon_edges(f) {
                len += (p[a as usize] - p[b as usize]).norm();
                m += 1;
            }
        }
        if n == 0 || len == 0.0 {
            return 0.0;
        }
        (sum / n as f64) / (len / m as f64)
    }
}

/// Semiregular remeshing of one base mesh on one surface, with warm-started recomputation
/// after edits.
///
/// ```
/// use std::sync::Arc;
/// use wavg_mesh::{ValidMesh, procedural};
/// use wavg_solve::{EmbeddedMesh, Projector};
/// use wavg_apps::{BaseMesh, Remesher};
/// let mesh = Arc::new(ValidMesh::new(procedural::icosphere(4)).unwrap());
/// let proj = Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh))).unwrap());
/// // An octahedron's vertices, on the unit sphere.
/// let s = 1.0;
/// let positions = [[s, 0., 0.], [-s, 0., 0.], [0., s, 0.], [0., -s, 0.], [0., 0., s], [0., 0., -s]]
///     .map(nalgebra::Vector3::from).to_vec();
/// let faces = vec![vec![0, 2, 4], vec![2, 1, 4], vec![1, 3, 4], vec![3, 0, 4],
///                  vec![2, 0, 5], vec![1, 2, 5], vec![3, 1, 5], vec![0, 3, 5]];
/// let mut r = Remesher::new(proj, &BaseMesh { positions, faces }).unwrap();
/// let out = r.remesh(2, 3).unwrap();
/// assert_eq!(out.faces.len(), 8 * 16);
/// assert_eq!(out.positions.len(), 66);
/// ```
pub struct Remesher {
    solver: Solver,
    emb: Arc<EmbeddedMesh>,
    /// Closest points in 3-D (a projector over the 3-D positions).
    closest: Arc<Projector>,
    diag: f64,
    faces: Vec<Vec<u32>>,
    base_points: Vec<SurfacePoint>,
    plan: Option<CachedPlan>,
    /// The previous run's answers per stage (each level's new vertices, then every
    /// smoothing step's vertices), with its levels and smoothing steps.
    warm: Option<(usize, usize, Vec<Vec<SurfacePoint>>)>,
}

impl Remesher {
    /// Validates `base` and puts its vertices on the surface of `projector` (each at the
    /// closest point of the mesh in 3-D), refusing a vertex farther than
    /// [`DEFAULT_MAX_BASE_DISTANCE`] bounding-box diagonals.
    pub fn new(projector: Arc<Projector>, base: &BaseMesh) -> Result<Self, RemeshError> {
        Self::with_max_distance(projector, base, DEFAULT_MAX_BASE_DISTANCE)
    }

    /// [`Remesher::new`] with another largest base-vertex distance (over the bounding-box
    /// diagonal; positive).
    pub fn with_max_distance(
        projector: Arc<Projector>,
        base: &BaseMesh,
        max_distance: f64,
    ) -> Result<Self, RemeshError> {
        check_max_base_distance(max_distance)?;
        base.validate()?;
        let emb = projector.embedded().clone();
        let mesh = emb.mesh().clone();
        let closest = Arc::new(
            Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh.clone())))
                .map_err(|e| RemeshError::InvalidParameter(e.to_string()))?,
        );
        let diag = bbox_diagonal(&mesh.positions);
        let solver = Solver::new(projector, std::iter::empty())
            .map_err(|e| RemeshError::InvalidParameter(e.to_string()))?;
        let mut me = Self {
            solver,
            emb,
            closest,
            diag,
            faces: base.faces.clone(),
            base_points: Vec::with_capacity(base.positions.len()),
            plan: None,
            warm: None,
        };
        let limit = max_distance;
        for (v, p) in base.positions.iter().enumerate() {
            let (sp, d) = me.closest_point(p);
            let distance = d / me.diag;
            if distance.is_nan() || distance > limit {
                return Err(RemeshError::FarFromSurface {
                    vertex: v,
                    distance,
                    limit,
                });
            }
            me.base_points.push(sp);
        }
        Ok(me)
    }

    /// The closest point of the surface to `p` in 3-D and its distance.
    pub fn closest_point(&self, p: &Vector3<f64>) -> (SurfacePoint, f64) {
        let mut y = Vec8::zeros();
        y.fixed_rows_mut::<3>(0).copy_from(p);
        let hit = self.closest.project_euclidean(&y);
        (hit.point, hit.distance)
    }

    /// Largest 3-D distance of `positions` from the surface, over the surface's
    /// bounding-box diagonal.
    pub fn max_offsurface(&self, positions: &[Vector3<f64>]) -> f64 {
        positions
            .par_iter()
            .map(|p| self.closest_point(p).1)
            .reduce(|| 0.0, f64::max)
            / self.diag
    }

    /// Length of the surface's bounding-box diagonal.
    pub fn diagonal(&self) -> f64 {
        self.diag
    }

    /// The base vertices on the surface.
    pub fn base_points(&self) -> &[SurfacePoint] {
        &self.base_points
    }

    /// The base polygons.
    pub fn base_faces(&self) -> &[Vec<u32>] {
        &self.faces
    }

    /// The [`RemeshReport`] of `out`, a result of this remesher.
    pub fn report(&self, out: &RemeshResult) -> RemeshReport {
        RemeshReport {
            base_vertices: self.base_points.len(),
            base_faces: self.faces.len(),
            vertices: out.positions.len(),
            faces: out.faces.len(),
            levels: out.levels,
            smooth_steps: out.smooth_steps,
            max_offsurface: self.max_offsurface(&out.positions),
            roughness: out.roughness(),
            problems: out.problems,
            fallbacks: out.fallbacks,
        }
    }

    /// Moves base vertex `i` to `p` (validated); the next [`Remesher::remesh`] starts
    /// every search from the previous run's answers.
    pub fn move_base_vertex(&mut self, i: usize, p: SurfacePoint) -> Result<(), RemeshError> {
        let count = self.base_points.len();
        if i >= count {
            return Err(RemeshError::VertexOutOfRange { vertex: i, count });
        }
        let p =
            wavg_solve::check_point(self.emb.mesh(), &p).map_err(|source| RemeshError::Solve {
                stage: "the moved base vertex".into(),
                vertex: i,
                source,
            })?;
        self.base_points[i] = p;
        Ok(())
    }

    /// Forgets the previous run, so the next one starts cold (from the stencils).
    pub fn forget_warm_start(&mut self) {
        self.warm = None;
    }

    fn plan_for(&mut self, levels: usize) -> (Arc<Plan>, Arc<Vec<Vec<u32>>>) {
        match &self.plan {
            Some((l, p, f)) if *l == levels => (p.clone(), f.clone()),
            _ => {
                let p = Arc::new(plan::plan(self.base_points.len(), &self.faces, levels));
                let f = Arc::new(p.faces.clone());
                self.plan = Some((levels, p.clone(), f.clone()));
                (p, f)
            }
        }
    }

    /// Splits `levels` times (at most [`MAX_LEVELS`]) and smooths `smooth` steps (at most
    /// [`MAX_SMOOTH_STEPS`]). When the
    /// previous run had the same `levels` and `smooth`, every search starts from that
    /// run's answer for the same vertex and stage; otherwise from the stencil's first
    /// point. On error the previous run's answers are kept.
    pub fn remesh(&mut self, levels: usize, smooth: usize) -> Result<RemeshResult, RemeshError> {
        if levels > MAX_LEVELS {
            return Err(RemeshError::InvalidParameter(format!(
                "at most {MAX_LEVELS} levels, got {levels}"
            )));
        }
        if smooth > MAX_SMOOTH_STEPS {
            return Err(RemeshError::InvalidParameter(format!(
                "at most {MAX_SMOOTH_STEPS} smoothing steps, got {smooth}"
            )));
        }
        let (plan, faces) = self.plan_for(levels);
        let warm = match self.warm.take() {
            Some((l, s, w)) if l == levels && s == smooth => Some(w),
            _ => None,
        };
        let stage_warm = |k: usize| warm.as_ref().map(|w| w[k].as_slice());
        let n_final = plan.smooth.len();
        let mut pts = Vec::with_capacity(n_final);
        pts.extend_from_slice(&self.base_points);
        let mut ys: Vec<Vec8> = Vec::with_capacity(n_final);
        ys.extend(pts.iter().map(|p| self.emb.point(p)));
        let mut stages = Vec::with_capacity(levels + smooth);
        let (mut problems, mut fallbacks) = (0, 0);
        let run =
            |stencils: &Stencils,
             pts: &[SurfacePoint],
             ys: &[Vec8],
             warm: Option<&[SurfacePoint]>,
             smoothing: bool| { self.stage(stencils, pts, ys, warm, smoothing) };
        let mut result = Ok(());
        for (k, level) in plan.levels.iter().enumerate() {
            match run(&level.new, &pts, &ys, stage_warm(k), false) {
                Ok(out) => {
                    problems += out.problems;
                    fallbacks += out.fallbacks;
                    pts.extend_from_slice(&out.points);
                    ys.extend_from_slice(&out.ys);
                    stages.push(out.points);
                }
                Err((vertex, source)) => {
                    result = Err(RemeshError::Solve {
                        stage: format!("level {}", k + 1),
                        vertex: level.n_old + vertex,
                        source,
                    });
                    break;
                }
            }
        }
        if result.is_ok() {
            for s in 0..smooth {
                match run(&plan.smooth, &pts, &ys, stage_warm(levels + s), true) {
                    Ok(out) => {
                        problems += out.problems;
                        fallbacks += out.fallbacks;
                        pts.clone_from(&out.points);
                        ys = out.ys;
                        stages.push(out.points);
                    }
                    Err((vertex, source)) => {
                        result = Err(RemeshError::Solve {
                            stage: format!("smoothing step {}", s + 1),
                            vertex,
                            source,
                        });
                        break;
                    }
                }
            }
        }
        if let Err(e) = result {
            self.warm = warm.map(|w| (levels, smooth, w));
            return Err(e);
        }
        self.warm = Some((levels, smooth, stages));
        let mesh = self.emb.mesh();
        let positions = pts.par_iter().map(|p| p.position(mesh)).collect();
        Ok(RemeshResult {
            points: pts,
            positions,
            faces,
            levels,
            smooth_steps: smooth,
            problems,
            fallbacks,
        })
    }

    /// One stage: the average of every stencil on the surface, in parallel. With
    /// `smoothing`, stencil `i` belongs to vertex `i` (an empty one keeps the vertex);
    /// otherwise to the `i`-th new vertex. An error names the stencil.
    fn stage(
        &self,
        stencils: &Stencils,
        pts: &[SurfacePoint],
        ys: &[Vec8],
        warm: Option<&[SurfacePoint]>,
        smoothing: bool,
    ) -> Result<StageOut, (usize, SolveError)> {
        let opts = ForwardOptions::default();
        let out: Vec<Result<Answer, (usize, SolveError)>> = (0..stencils.len())
            .into_par_iter()
            .with_min_len(64)
            .map(|i| {
                let s = stencils.get(i);
                if s.is_empty() {
                    return Ok((pts[i], ys[i], 0));
                }
                let mut y = Vec8::zeros();
                for &c in s {
                    y += ys[c as usize];
                }
                y /= s.len() as f64;
                let near = pts[s[0] as usize];
                // A smoothed vertex moves little: its own point is a warm start.
                let o = match warm.and_then(|w| w.get(i)) {
                    Some(&w) => opts.warm(w),
                    None if smoothing => opts.warm(pts[i]),
                    None => opts,
                };
                let r = self
                    .solver
                    .forward_embedded(&y, &near, &o)
                    .map_err(|e| (i, e))?;
                let flag = 1 + u8::from(r.path == ProjectionPath::Fallback);
                Ok((r.point, self.emb.point(&r.point), flag))
            })
            .collect();
        let mut st = StageOut {
            points: Vec::with_capacity(out.len()),
            ys: Vec::with_capacity(out.len()),
            problems: 0,
            fallbacks: 0,
        };
        for r in out {
            let (p, y, flag) = r?;
            st.points.push(p);
            st.ys.push(y);
            st.problems += usize::from(flag > 0);
            st.fallbacks += usize::from(flag > 1);
        }
        Ok(st)
    }
}

/// The plan for a number of levels, with its faces shared with every result.
type CachedPlan = (usize, Arc<Plan>, Arc<Vec<Vec<u32>>>);

/// One stencil's answer: the point, its embedded point, and 0 (kept), 1 (solved) or 2
/// (solved by the fallback search).
type Answer = (SurfacePoint, Vec8, u8);

/// What one stage computed.
struct StageOut {
    points: Vec<SurfacePoint>,
    ys: Vec<Vec8>,
    problems: usize,
    fallbacks: usize,
}

/// Length of the diagonal of the points' bounding box (1 when it is zero).
fn bbox_diagonal(p: &[Vector3<f64>]) -> f64 {
    let lo = p
        .iter()
        .fold(Vector3::repeat(f64::INFINITY), |a, b| a.inf(b));
    let hi = p
        .iter()
        .fold(Vector3::repeat(f64::NEG_INFINITY), |a, b| a.sup(b));
    let d = (hi - lo).norm();
    if d > 0.0 && d.is_finite() { d } else { 1.0 }
}

impl std::fmt::Debug for Remesher {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Remesher")
            .field("base_vertices", &self.base_points.len())
            .field("base_faces", &self.faces.len())
            .finish_non_exhaustive()
    }
}
