//! The projection benchmark protocol (`wavg bench project`): Phong projection speed and
//! accuracy on random surface points.
//!
//! Build the projector (`init_s`, `bytes_per_face`); (a) project N random on-surface
//! points (uniform by area, [`uniform_surface_points`]), each from a start vertex three
//! rings away ([`RingSearch`]), on one thread: mean time and the fraction that return to
//! themselves (same face within [`SAME_POINT`] in barycentrics, or the same position
//! within [`SAME_POINT`] mean edge lengths on a face sharing a vertex). Times are the
//! calling thread's CPU time per query (wall time without a clock), best of [`REPEATS`]
//! passes, as the machine may be shared; the queries go through
//! [`Projector::project_batch_into`] on one thread, which interleaves the walks of 16
//! queries, and once more through one [`Projector::project`] call at a time, whose
//! answers must be the same. (b) The same with the points offset from the surface by 0.1
//! mean edge length along the 3-D face normal (or a seeded random direction of R^8
//! orthogonal to the embedded face), timed, and on the first [`BRUTE_FORCE_CHECKS`]
//! compared with the brute-force search. (c) The fraction of each kind of query that
//! needed the global search (path [`ProjectionPath::Fallback`]), and the mean wall time of
//! one global search ([`Projector::project_exhaustive`] alone) on those queries.
//!
//! ```
//! use std::sync::Arc;
//! use wavg::{EmbeddedMesh, ValidMesh, mesh::procedural};
//! use wavg_bench::{ProjectionBenchOptions, projection_bench};
//!
//! let mesh = Arc::new(ValidMesh::new(procedural::icosphere(2)).unwrap());
//! let emb = Arc::new(EmbeddedMesh::from_positions(mesh));
//! let opts = ProjectionBenchOptions { queries: 200, offset_along_normal: true, ..Default::default() };
//! let report = projection_bench(emb, &opts).unwrap();
//! assert!(report.batch_agrees);
//! assert!(report.onsurface_self_fraction > 0.99);
//! ```

use std::sync::Arc;
use std::time::Instant;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use wavg::mesh::RingSearch;
use wavg::mesh::geometry::face_normal;
use wavg::project::{ProjectError, ProjectScratch, Projection};
use wavg::sampling::uniform_surface_points;
use wavg::{
    EmbeddedMesh, Par, ProjectionPath, Projector, SolveError, SurfacePoint, Vec8, VertexId,
};

use crate::timing::CpuClock;

/// Timed passes over the queries (the fastest is reported).
pub const REPEATS: usize = 3;
/// Offset points checked against the brute-force search.
pub const BRUTE_FORCE_CHECKS: usize = 1000;
/// Ring distance of the start vertex from the query's face.
pub const HINT_RINGS: usize = 3;
/// Tolerance of "the same point" (barycentrics, or mean edge lengths for positions).
pub const SAME_POINT: f64 = 1e-5;

/// Options of [`projection_bench`].
#[derive(Clone, Copy, Debug)]
pub struct ProjectionBenchOptions {
    /// Number of random queries per test; at least 1.
    pub queries: usize,
    /// Seed of the points, their start vertices and the offset directions.
    pub seed: u64,
    /// Offset along the 3-D face normal (for an embedding that is the zero-padded
    /// positions) instead of a random direction orthogonal to the embedded face.
    pub offset_along_normal: bool,
    /// The calling thread's CPU-time clock in seconds (the standard library has none);
    /// without one the CPU figures are wall time.
    pub thread_cpu_clock: Option<CpuClock>,
    /// Threads of the brute-force comparison (the timed passes run on the calling thread).
    pub par: Par,
}

impl Default for ProjectionBenchOptions {
    fn default() -> Self {
        Self {
            queries: 100_000,
            seed: 1,
            offset_along_normal: false,
            thread_cpu_clock: None,
            par: Par::Rayon,
        }
    }
}

/// Speed and accuracy of [`Projector`] on random surface points, and of the global
/// search on the queries that needed it. Times are microseconds per query. It serialises
/// to the keys of `wavg bench project --json` (the field names); the fields marked "not serialised" are the extra figures of its text output.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ProjectionBenchReport {
    /// Vertices of the mesh.
    pub vertices: usize,
    /// Faces of the mesh.
    pub faces: usize,
    /// Random queries per test.
    pub queries: usize,
    /// Seconds to build the projector.
    pub init_s: f64,
    /// Memory of the projector per face, in bytes.
    pub bytes_per_face: f64,
    /// Projecting points on the surface: CPU microseconds per query.
    pub onsurface_us: f64,
    /// Projecting points on the surface: wall microseconds per query. Not serialised.
    #[serde(skip)]
    pub onsurface_wall_us: f64,
    /// The same points, one `project` call at a time: CPU microseconds per query. Not
    /// serialised.
    #[serde(skip)]
    pub single_us: f64,
    /// One `project` call at a time: wall microseconds per query. Not serialised.
    #[serde(skip)]
    pub single_wall_us: f64,
    /// Whether the batch and the one-at-a-time answers are the same (they must be). Not
    /// serialised.
    #[serde(skip)]
    pub batch_agrees: bool,
    /// Fraction of the points on the surface that project back to themselves.
    pub onsurface_self_fraction: f64,
    /// Answers to the points on the surface by path: local (certified or not), fallback,
    /// none. Not serialised.
    #[serde(skip)]
    pub onsurface_paths: [usize; 3],
    /// Projecting points offset from the surface: CPU microseconds per query.
    pub offset_us: f64,
    /// Projecting offset points: wall microseconds per query. Not serialised.
    #[serde(skip)]
    pub offset_wall_us: f64,
    /// Fraction of the offset points checked whose answer equals the brute-force search's.
    pub offset_bruteforce_agree_fraction: f64,
    /// Offset points compared with the brute-force search. Not serialised.
    #[serde(skip)]
    pub bruteforce_checked: usize,
    /// Answers to the offset points by path, as `onsurface_paths`. Not serialised.
    #[serde(skip)]
    pub offset_paths: [usize; 3],
    /// Fraction of the points on the surface that needed the global search.
    pub onsurface_fallback_fraction: f64,
    /// Fraction of the offset points that needed the global search.
    pub offset_fallback_fraction: f64,
    /// Wall microseconds of one global search on the queries that needed it (`None` when
    /// none did).
    pub fallback_us: Option<f64>,
    /// Queries that needed the global search (both kinds). Not serialised.
    #[serde(skip)]
    pub fallback_queries: usize,
}

/// One query's answer.
type Answer = Result<Projection, ProjectError>;

/// Runs the protocol on `emb`: builds its projector, then measures. Errors when
/// `opts.queries` is 0, the projector cannot be built ([`SolveError::Project`]) or the
/// mesh has no area to sample.
pub fn projection_bench(
    emb: Arc<EmbeddedMesh>,
    opts: &ProjectionBenchOptions,
) -> Result<ProjectionBenchReport, SolveError> {
    if opts.queries == 0 {
        return Err(SolveError::InvalidParameter(
            "the projection benchmark needs at least one query".into(),
        ));
    }
    let t0 = Instant::now();
    let projector = Projector::new(emb.clone())?;
    let init_s = t0.elapsed().as_secs_f64();
    let mesh = emb.mesh();
    let bytes_per_face = projector.bytes() as f64 / mesh.n_faces() as f64;

    let points = uniform_surface_points(mesh, opts.queries, opts.seed)?;
    let mut rng = ChaCha8Rng::seed_from_u64(opts.seed);
    let mut rings = RingSearch::new(mesh.n_vertices());
    let starts: Vec<VertexId> = points
        .iter()
        .map(|p| {
            let from = mesh.triangles[p.face as usize][0];
            let ring = rings.ring_or_farthest(mesh.topology(), from, HINT_RINGS);
            ring[rng.random_range(0..ring.len())]
        })
        .collect();
    let mean_edge = emb.mean_edge_length();
    let clock = opts.thread_cpu_clock;

    // (a) on-surface points.
    let ys: Vec<Vec8> = points.iter().map(|p| emb.point(p)).collect();
    let (on, on_time) = timed(&projector, &ys, &starts, true, clock);
    let (single, single_time) = timed(&projector, &ys, &starts, false, clock);
    let back = (points.iter().zip(&on).zip(&ys))
        .filter(|((p, r), y)| matches!(r, Ok(r) if returns_to(&emb, p, y, r, mean_edge)))
        .count();

    // (b) offset points.
    let offset: Vec<Vec8> = (points.iter().zip(&ys))
        .map(|(p, y)| {
            let dir = offset_direction(&emb, p.face, opts.offset_along_normal, &mut rng);
            y + dir * (0.1 * mean_edge)
        })
        .collect();
    let (off, off_time) = timed(&projector, &offset, &starts, true, clock);
    let n_check = BRUTE_FORCE_CHECKS.min(offset.len());
    let agree = brute_force_agreement(
        &projector,
        &offset[..n_check],
        &off[..n_check],
        mean_edge,
        opts.par,
    )?;

    // (c) the queries that needed the global search, and its cost alone on them.
    let needed: Vec<Vec8> = (ys.iter().zip(&on))
        .chain(offset.iter().zip(&off))
        .filter(|(_, r)| used_fallback(r))
        .map(|(y, _)| *y)
        .collect();
    let fraction =
        |v: &[Answer]| v.iter().filter(|r| used_fallback(r)).count() as f64 / v.len() as f64;

    Ok(ProjectionBenchReport {
        vertices: mesh.n_vertices(),
        faces: mesh.n_faces(),
        queries: opts.queries,
        init_s,
        bytes_per_face,
        onsurface_us: on_time.cpu_us,
        onsurface_wall_us: on_time.wall_us,
        single_us: single_time.cpu_us,
        single_wall_us: single_time.wall_us,
        batch_agrees: single == on,
        onsurface_self_fraction: back as f64 / points.len() as f64,
        onsurface_paths: path_counts(&on),
        offset_us: off_time.cpu_us,
        offset_wall_us: off_time.wall_us,
        offset_bruteforce_agree_fraction: agree as f64 / n_check as f64,
        bruteforce_checked: n_check,
        offset_paths: path_counts(&off),
        onsurface_fallback_fraction: fraction(&on),
        offset_fallback_fraction: fraction(&off),
        fallback_us: fallback_wall_us(&projector, &needed),
        fallback_queries: needed.len(),
    })
}

/// Per-query times of one pass, in microseconds.
#[derive(Clone, Copy)]
struct Timing {
    /// CPU time of the measuring thread (wall time without a clock).
    cpu_us: f64,
    /// Wall-clock time.
    wall_us: f64,
}

/// Projects every query on the calling thread, as one batch or one call at a time; mean
/// microseconds per query, the best of [`REPEATS`] passes.
fn timed(
    p: &Projector,
    ys: &[Vec8],
    starts: &[VertexId],
    batch: bool,
    clock: Option<CpuClock>,
) -> (Vec<Answer>, Timing) {
    let mut out = Vec::with_capacity(ys.len());
    let mut scratch = ProjectScratch::default();
    let mut best = Timing {
        cpu_us: f64::INFINITY,
        wall_us: f64::INFINITY,
    };
    let n = ys.len() as f64;
    let cpu_now = || clock.and_then(|c| c());
    for _ in 0..REPEATS {
        out.clear();
        let c0 = cpu_now();
        let t = Instant::now();
        if batch {
            // On this thread (`Par::Seq` never fails).
            let _ = p.project_batch_into(ys, starts, &mut scratch, &mut out, Par::Seq);
        } else {
            out.extend(ys.iter().zip(starts).map(|(y, &s)| p.project(y, s)));
        }
        let wall = t.elapsed().as_secs_f64();
        let cpu = match (c0, cpu_now()) {
            (Some(a), Some(b)) => b - a,
            _ => wall,
        };
        best.cpu_us = best.cpu_us.min(cpu * 1e6 / n);
        best.wall_us = best.wall_us.min(wall * 1e6 / n);
    }
    (out, best)
}

/// Whether the query needed the global search.
fn used_fallback(r: &Answer) -> bool {
    matches!(r, Ok(p) if p.path == ProjectionPath::Fallback)
}

/// Answers by path: local (certified or not), fallback, none.
fn path_counts(v: &[Answer]) -> [usize; 3] {
    let mut n = [0usize; 3];
    for r in v {
        n[match r {
            Ok(p) if matches!(p.path, ProjectionPath::Certified | ProjectionPath::Local) => 0,
            Ok(p) if p.path == ProjectionPath::Fallback => 1,
            _ => 2,
        }] += 1;
    }
    n
}

/// Mean wall microseconds of one global search (`project_exhaustive`) over `ys`, the best
/// of [`REPEATS`] passes; `None` for no queries.
fn fallback_wall_us(p: &Projector, ys: &[Vec8]) -> Option<f64> {
    if ys.is_empty() {
        return None;
    }
    let mut best = f64::INFINITY;
    for _ in 0..REPEATS {
        let t = Instant::now();
        for y in ys {
            // The answer itself was checked before; only the time matters here.
            let _ = std::hint::black_box(p.project_exhaustive(std::hint::black_box(y)));
        }
        best = best.min(t.elapsed().as_secs_f64() * 1e6 / ys.len() as f64);
    }
    Some(best)
}

/// Whether projection `r` of `y = e(p)` is `p` itself.
fn returns_to(
    emb: &EmbeddedMesh,
    p: &SurfacePoint,
    y: &Vec8,
    r: &Projection,
    mean_edge: f64,
) -> bool {
    if r.point.face == p.face {
        let d = (0..3)
            .map(|i| (r.point.bary[i] - p.bary[i]).abs())
            .fold(0.0, f64::max);
        return d <= SAME_POINT;
    }
    let mesh = emb.mesh();
    let (a, b) = (
        mesh.triangles[p.face as usize],
        mesh.triangles[r.point.face as usize],
    );
    a.iter().any(|v| b.contains(v)) && (emb.point(&r.point) - y).norm() <= SAME_POINT * mean_edge
}

/// Unit offset direction for face `f`: the 3-D normal, or a random direction orthogonal
/// to the embedded face.
fn offset_direction(emb: &EmbeddedMesh, f: u32, normal: bool, rng: &mut ChaCha8Rng) -> Vec8 {
    if normal {
        let n = face_normal(emb.mesh(), f as usize);
        let mut v = Vec8::zeros();
        v.fixed_rows_mut::<3>(0).copy_from(&n);
        return v;
    }
    let [a, b, c] = emb.corners(f as usize);
    let e1 = (b - a).normalize();
    let e2 = {
        let w = c - a;
        (w - e1 * e1.dot(&w)).normalize()
    };
    loop {
        let r = Vec8::from_fn(|_, _| rng.random_range(-1.0..1.0));
        let n = r - e1 * e1.dot(&r) - e2 * e2.dot(&r);
        let len = n.norm();
        if len > 1e-3 && len.is_finite() {
            return n / len;
        }
    }
}

/// How many of the fast answers equal the brute-force ones (same point, or a tie in
/// distance, or both "no projection"), the brute force running with `par`.
fn brute_force_agreement(
    p: &Projector,
    ys: &[Vec8],
    fast: &[Answer],
    mean_edge: f64,
    par: Par,
) -> Result<usize, SolveError> {
    let emb = p.embedded();
    let mut same = Vec::with_capacity(ys.len());
    par.map_range(ys.len(), 1, &mut same, |i| {
        match (&fast[i], &p.project_brute_force(&ys[i])) {
            (Err(_), Err(_)) => true,
            (Ok(f), Ok(b)) => {
                (emb.point(&f.point) - emb.point(&b.point)).norm() <= SAME_POINT * mean_edge
                    || (f.distance - b.distance).abs() <= 1e-9 * (b.distance + mean_edge)
            }
            _ => false,
        }
    })?;
    Ok(same.iter().filter(|&&s| s).count())
}
