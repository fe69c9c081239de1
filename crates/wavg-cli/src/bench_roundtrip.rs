//! `wavg bench roundtrip`: the paper's Table 1 protocol.
//!
//! K anchors by farthest-point sampling (edge-graph distance, seeded); N surface points
//! uniform by area (seeded); for each, weights by the inverse problem, then the forward
//! problem with those weights and no initial guess. Times are wall time of the whole
//! batch on T threads divided by N (amortised over the threads, as in the paper), best of
//! `--repeat` runs. `forward_warm_us` runs the same forward problems visited in spatial
//! (Morton) order, each warm-started from the previous answer.

use std::path::PathBuf;
use std::time::Instant;

use serde::Serialize;
use wavg_mesh::geometry::mean_edge_length;
use wavg_solve::sampling::{
    FpsMetric, farthest_point_vertices, spatial_order, uniform_surface_points,
};
use wavg_solve::{
    Anchor, ForwardOptions, ForwardResult, ProjectionPath, SearchMode, SolveError, Solver,
};

use crate::CliError;
use crate::common::{load_valid, one_line};
use crate::textio;

/// A forward result within this many mean edge lengths of the original point counts as a
/// successful round trip.
const OK_TOLERANCE: f64 = 1e-3;
/// A query "has negative weights" when some weight is below this.
const NEGATIVE: f64 = -0.1;
/// Queries per warm-started chain (fixed, so results do not depend on the thread count).
const WARM_CHUNK: usize = 1024;

/// Arguments.
#[derive(clap::Args)]
#[command(after_long_help = "\
The paper's Table 1 protocol: K anchors by farthest-point sampling (shortest paths along
edges, seeded), N random surface points (uniform by area, seeded); for each point weights
by the inverse problem, then the forward problem with those weights and no initial guess.

Reports inverse_us and forward_us (wall time of each batch on T threads divided by N, best
of --repeat runs), forward_warm_us (the same forward problems in spatial order, each
warm-started from the previous answer), roundtrip_ok_fraction (forward result within 1e-3
mean edge lengths of the original point; a failed inverse or forward counts as not ok),
roundtrip_err_p50 / roundtrip_err_p99 (that distance in mean edge lengths; null in JSON
when infinite, i.e. more failures than the percentile), negative_weight_fraction (queries
with some weight below -0.1), and mesh, vertices, faces, anchors, queries, threads.

With --verified it also runs the verified inverse (Solver::inverse_verified: the paper's
weights where the forward problem returns them to the point, else the smallest offset
penalty of the ladder 10, 100, 1000, 10000 that does) and adds verified_inverse_us (best of
--repeat runs, buffers reused, including its forward checks), verified_roundtrip_ok_fraction and
verified_negative_weight_fraction (the same protocol on those weights),
verified_penalized_fraction and verified_not_reached_fraction.

Without --embedding or --precompute the 3-D positions are the embedding.")]
pub struct Args {
    /// Mesh file (.obj/.off/.ply, optionally .gz) or builtin:NAME.
    #[arg(long)]
    pub mesh: String,
    /// Embedding (.wavg from `wavg precompute`).
    #[arg(long, conflicts_with = "precompute")]
    pub embedding: Option<PathBuf>,
    /// Compute the embedding first (default parameters) instead of loading one.
    #[arg(long)]
    pub precompute: bool,
    /// Number of anchors K.
    #[arg(long)]
    pub anchors: usize,
    /// Number of random query points N.
    #[arg(long, default_value_t = 100_000)]
    pub queries: usize,
    /// Worker threads T (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Seed of the anchors and the query points.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Timed runs of each batch; the best is reported.
    #[arg(long, default_value_t = 3)]
    pub repeat: usize,
    /// Forward search: the paper's local search (fast), the projector's certified closest
    /// projection, or the exhaustive search.
    #[arg(long, value_enum, default_value_t = Search::Fast)]
    pub search: Search,
    /// Also run the verified inverse (round trip checked, offset penalty where needed).
    #[arg(long)]
    pub verified: bool,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// `--search` values.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Search {
    /// Walk + breadth-first triangle search (paper), certified fallback.
    Fast,
    /// Closest valid projection, certified against the bounding volume hierarchy.
    Certified,
    /// Exhaustive search.
    Exact,
}

/// The JSON report (keys as documented).
#[derive(Serialize)]
struct Report {
    inverse_us: f64,
    forward_us: f64,
    forward_warm_us: f64,
    roundtrip_ok_fraction: f64,
    roundtrip_err_p50: f64,
    roundtrip_err_p99: f64,
    negative_weight_fraction: f64,
    mesh: String,
    vertices: usize,
    faces: usize,
    anchors: usize,
    queries: usize,
    threads: usize,
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    verified: Option<VerifiedReport>,
}

/// The `--verified` keys.
#[derive(Serialize)]
struct VerifiedReport {
    verified_inverse_us: f64,
    verified_roundtrip_ok_fraction: f64,
    verified_negative_weight_fraction: f64,
    verified_penalized_fraction: f64,
    verified_not_reached_fraction: f64,
}

/// Best wall time of `repeat` runs of `f`, and the last result.
fn best_of<T>(repeat: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut best = f64::INFINITY;
    let mut out = None;
    for _ in 0..repeat.max(1) {
        let t = Instant::now();
        let r = f();
        best = best.min(t.elapsed().as_secs_f64());
        out = Some(r);
    }
    (best, out.expect("at least one run"))
}

/// The 1-minute load average (Linux), to judge how busy the machine was.
fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().map(str::to_string))
        .unwrap_or_else(|| "unknown".into())
}

/// Runs `f` and returns its result with the CPU seconds it used (NaN when unknown).
fn with_cpu<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let c0 = crate::common::cpu_seconds(false);
    let r = f();
    let dt = match (c0, crate::common::cpu_seconds(false)) {
        (Some(a), Some(b)) => b - a,
        _ => f64::NAN,
    };
    (r, dt)
}

/// Value at quantile `q` of sorted `xs` (nearest rank).
fn quantile(xs: &[f64], q: f64) -> f64 {
    if xs.is_empty() {
        return f64::NAN;
    }
    let i = ((q * xs.len() as f64).ceil() as usize).clamp(1, xs.len()) - 1;
    xs[i]
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), CliError> {
    if args.queries == 0 {
        return Err(CliError::input("--queries must be at least 1"));
    }
    if args.anchors < 3 {
        return Err(CliError::input("--anchors must be at least 3"));
    }
    let threads = args.threads.unwrap_or_else(rayon::current_num_threads);
    let mesh = load_valid(&args.mesh)?;
    let t0 = Instant::now();
    let emb = if args.precompute {
        precompute_embedding(&mesh)?
    } else {
        textio::load_embedded(mesh.clone(), args.embedding.as_deref())?
    };
    let t_emb = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let proj = textio::build_projector(emb)?;
    let t_proj = t0.elapsed().as_secs_f64();
    let anchors = farthest_point_vertices(&mesh, args.anchors, args.seed, FpsMetric::EdgeGraph)
        .map_err(|e| CliError::input(one_line(&e)))?;
    let solver = Solver::new(proj, anchors.into_iter().map(Anchor::Vertex))
        .map_err(|e| CliError::failure(one_line(&e)))?;
    let points = uniform_surface_points(&mesh, args.queries, args.seed.wrapping_add(1))
        .map_err(|e| CliError::input(one_line(&e)))?;
    let n = points.len();

    // The result buffers are reused across the repeats, as an application would.
    let mut weights = wavg_solve::BatchWeights::default();
    let (t_inv, cpu_inv) = with_cpu(|| {
        textio::with_threads(Some(threads), || {
            best_of(args.repeat, || {
                solver.inverse_batch_into(&points, &mut weights)
            })
            .0
        })
    });
    let t_inv = t_inv?;
    let k = solver.n_anchors();
    // Failed inverses get a placeholder that fails validation, so forward reports it.
    let rows: Vec<&[f64]> = weights.iter().map(|r| r.unwrap_or(&[])).collect();
    let opts = ForwardOptions {
        mode: match args.search {
            Search::Fast => SearchMode::Fast,
            Search::Certified => SearchMode::Certified,
            Search::Exact => SearchMode::Exact,
        },
        ..Default::default()
    };
    let (r, cpu_fwd) = with_cpu(|| {
        textio::with_threads(Some(threads), || {
            best_of(args.repeat, || solver.forward_batch(&rows, &opts))
        })
    });
    let (t_fwd, fwd) = r?;
    let order = spatial_order(&points.iter().map(|p| p.position(&mesh)).collect::<Vec<_>>());
    let ordered: Vec<&[f64]> = order.iter().map(|&i| rows[i]).collect();
    let (r, cpu_warm) = with_cpu(|| {
        textio::with_threads(Some(threads), || {
            best_of(args.repeat, || {
                solver.forward_batch_warm(&ordered, &opts, WARM_CHUNK)
            })
        })
    });
    let (t_warm, warm) = r?;
    // CPU microseconds per query (mean over the repeats, summed over threads).
    let cpu_us = |c: f64| c / (n * args.repeat.max(1)) as f64 * 1e6;

    let mel = mean_edge_length(&mesh);
    let err = |p: &wavg_mesh::SurfacePoint, r: &Result<ForwardResult, SolveError>| match r {
        Ok(r) => (r.position - p.position(&mesh)).norm() / mel,
        Err(_) => f64::INFINITY,
    };
    let mut errs: Vec<f64> = points.iter().zip(&fwd).map(|(p, r)| err(p, r)).collect();
    let warm_ok = order
        .iter()
        .zip(&warm)
        .filter(|(i, r)| err(&points[**i], r) < OK_TOLERANCE)
        .count();
    errs.sort_by(f64::total_cmp);
    let ok = errs.iter().filter(|&&e| e < OK_TOLERANCE).count();
    let negative = weights
        .iter()
        .filter(|r| r.is_ok_and(|w| w.iter().any(|&x| x < NEGATIVE)))
        .count();
    let inverse_failed = weights.iter().filter(|r| r.is_err()).count();
    let path_count = |p: ProjectionPath| {
        fwd.iter()
            .filter(|r| r.as_ref().is_ok_and(|r| r.path == p))
            .count()
    };
    let verified = if args.verified {
        Some(run_verified(
            &solver,
            &points,
            threads,
            args.repeat,
            &opts,
            mel,
        )?)
    } else {
        None
    };
    let report = Report {
        inverse_us: t_inv / n as f64 * 1e6,
        forward_us: t_fwd / n as f64 * 1e6,
        forward_warm_us: t_warm / n as f64 * 1e6,
        roundtrip_ok_fraction: ok as f64 / n as f64,
        roundtrip_err_p50: quantile(&errs, 0.5),
        roundtrip_err_p99: quantile(&errs, 0.99),
        negative_weight_fraction: negative as f64 / n as f64,
        mesh: args.mesh.clone(),
        vertices: mesh.n_vertices(),
        faces: mesh.n_faces(),
        anchors: k,
        queries: n,
        threads,
        verified,
    };
    if args.json {
        let s = serde_json::to_string(&report).map_err(CliError::failure)?;
        println!("{s}");
        return Ok(());
    }
    let source = match (&args.embedding, args.precompute) {
        (Some(p), _) => p.display().to_string(),
        (None, true) => "computed (--precompute)".into(),
        (None, false) => "3-D positions".into(),
    };
    println!(
        "mesh                      {} ({} vertices, {} faces)",
        report.mesh, report.vertices, report.faces
    );
    println!("embedding                 {source} ({t_emb:.2} s)");
    println!("projector                 {t_proj:.2} s");
    println!(
        "anchors / queries         {} / {} ({} threads, best of {})",
        k,
        n,
        threads,
        args.repeat.max(1)
    );
    println!(
        "inverse_us                {:.3}  (CPU per query {:.3})",
        report.inverse_us,
        cpu_us(cpu_inv)
    );
    println!(
        "forward_us                {:.3}  (CPU per query {:.3})",
        report.forward_us,
        cpu_us(cpu_fwd)
    );
    println!(
        "forward_warm_us           {:.3}  (CPU per query {:.3})",
        report.forward_warm_us,
        cpu_us(cpu_warm)
    );
    println!("load average              {}", load_average());
    println!(
        "roundtrip_ok_fraction     {:.5}  (warm: {:.5})",
        report.roundtrip_ok_fraction,
        warm_ok as f64 / n as f64
    );
    println!(
        "roundtrip_err_p50 / p99   {:.3e} / {:.3e} mean edge lengths",
        report.roundtrip_err_p50, report.roundtrip_err_p99
    );
    println!(
        "negative_weight_fraction  {:.5}",
        report.negative_weight_fraction
    );
    println!(
        "forward paths             local {}  fallback {}  failed {}  (inverse failed {})",
        path_count(ProjectionPath::Local),
        path_count(ProjectionPath::Fallback),
        fwd.iter().filter(|r| r.is_err()).count(),
        inverse_failed
    );
    if let Some(v) = &report.verified {
        println!(
            "verified_inverse_us       {:.3}  (forward checks included)",
            v.verified_inverse_us
        );
        println!(
            "verified round trip       ok {:.5}  negative weights {:.5}  penalized {:.5}  not reached {:.5}",
            v.verified_roundtrip_ok_fraction,
            v.verified_negative_weight_fraction,
            v.verified_penalized_fraction,
            v.verified_not_reached_fraction
        );
    }
    Ok(())
}

/// `--verified`: the checked inverse, then the same forward protocol on its weights.
fn run_verified(
    solver: &Solver,
    points: &[wavg_mesh::SurfacePoint],
    threads: usize,
    repeat: usize,
    opts: &ForwardOptions,
    mel: f64,
) -> Result<VerifiedReport, CliError> {
    use wavg_solve::RoundTrip;
    let n = points.len() as f64;
    // Buffers reused across the repeats, as for inverse_us.
    let mut weights = wavg_solve::BatchWeights::default();
    let mut trips = Vec::new();
    let t = textio::with_threads(Some(threads), || {
        best_of(repeat, || {
            solver.inverse_verified_batch_into(points, OK_TOLERANCE, &mut weights, &mut trips)
        })
        .0
    })?;
    let rows: Vec<&[f64]> = weights.iter().map(|r| r.unwrap_or(&[])).collect();
    let fwd = textio::with_threads(Some(threads), || solver.forward_batch(&rows, opts))?;
    let mesh = solver.mesh();
    let ok = points
        .iter()
        .zip(&fwd)
        .filter(|(p, r)| {
            r.as_ref()
                .is_ok_and(|r| (r.position - p.position(mesh)).norm() / mel < OK_TOLERANCE)
        })
        .count();
    let count = |f: &dyn Fn(&[f64], RoundTrip) -> bool| {
        rows.iter()
            .zip(&trips)
            .filter(|(w, t)| t.as_ref().is_ok_and(|t| f(w, *t)))
            .count() as f64
            / n
    };
    Ok(VerifiedReport {
        verified_inverse_us: t / n * 1e6,
        verified_roundtrip_ok_fraction: ok as f64 / n,
        verified_negative_weight_fraction: count(&|w, _| w.iter().any(|&x| x < NEGATIVE)),
        verified_penalized_fraction: count(&|_, t| matches!(t, RoundTrip::Penalized(_))),
        verified_not_reached_fraction: count(&|_, t| t == RoundTrip::NotReached),
    })
}

/// `--precompute`: the embedding pipeline with default parameters.
fn precompute_embedding(
    mesh: &std::sync::Arc<wavg_mesh::ValidMesh>,
) -> Result<std::sync::Arc<wavg_solve::EmbeddedMesh>, CliError> {
    let opts = wavg_embed::PrecomputeOptions::default();
    let (emb, _) = wavg_embed::precompute(mesh, &opts, &wavg_embed::NoProgress)
        .map_err(|e| CliError::failure(format!("precompute: {}", one_line(&e))))?;
    let coords = emb
        .coords
        .iter()
        .map(|c| wavg_solve::Vec8::from(*c))
        .collect();
    wavg_solve::EmbeddedMesh::new(mesh.clone(), coords)
        .map(std::sync::Arc::new)
        .map_err(|e| CliError::failure(format!("precompute: {}", one_line(&e))))
}
