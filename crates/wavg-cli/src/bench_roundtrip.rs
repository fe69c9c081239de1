//! `wavg bench roundtrip`: the paper's Table 1 protocol ([`wavg_bench::round_trip`]).
//!
//! K anchors by farthest-point sampling (edge-graph distance, seeded) and the solver are set
//! up here; the library samples N surface points uniform by area (seed + 1), times the
//! inverse and forward batches on T threads and compares. This file prints its report as a
//! table or, with `--json`, serialises it with the mesh argument added.

use std::path::PathBuf;
use std::time::Instant;

use serde::Serialize;
use wavg::sampling::{FpsMetric, farthest_point_vertices};
use wavg::{Anchor, SearchMode, Solver};
use wavg_bench::{RoundTripOptions, RoundTripReport, load_average};

use crate::CliError;
use crate::common::load_valid;
use crate::error::Context;
use crate::textio;

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

Without --embedding or --precompute the 3-D positions are the embedding. The protocol is
the function wavg_bench::round_trip of the workspace's wavg-bench crate, outside the
library (its RoundTripReport serialises to these keys, less mesh).")]
pub struct Args {
    #[command(flatten)]
    pub mesh: crate::mesh_arg::MeshArg,
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
    #[arg(long, default_value_t = 100_000, value_parser = crate::common::parse_queries)]
    pub queries: usize,
    /// Worker threads T (default: all cores; the limit: docs/limits.md).
    #[arg(long, value_parser = crate::common::parse_threads)]
    pub threads: Option<usize>,
    /// Seed of the anchors and the query points.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Timed runs of each batch; the best is reported.
    #[arg(long, default_value_t = 3, value_parser = crate::common::parse_repeat)]
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

/// The JSON report: the protocol's report and the mesh argument.
#[derive(Serialize)]
struct JsonReport<'a> {
    #[serde(flatten)]
    report: &'a RoundTripReport,
    mesh: &'a str,
}

/// The process CPU-time clock of the report's CPU figures.
fn process_cpu_seconds() -> Option<f64> {
    crate::common::cpu_seconds(false)
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
    let anchors = farthest_point_vertices(&mesh, args.anchors, args.seed, FpsMetric::EdgeGraph)?;
    let solver = Solver::new(proj, anchors.into_iter().map(Anchor::Vertex))?;
    let opts = RoundTripOptions {
        queries: args.queries,
        seed: args.seed.wrapping_add(1),
        repeat: args.repeat,
        search: match args.search {
            Search::Fast => SearchMode::Fast,
            Search::Certified => SearchMode::Certified,
            Search::Exact => SearchMode::Exact,
        },
        verified: args.verified,
        cpu_clock: Some(process_cpu_seconds),
    };
    let report = textio::with_threads(Some(threads), || wavg_bench::round_trip(&solver, &opts))??;
    crate::anchors::warn_if_low(
        report.roundtrip_ok_fraction,
        "round trips that lead back to their point",
        report.anchors,
        &args.mesh,
    );
    if args.json {
        let json = JsonReport {
            report: &report,
            mesh: &args.mesh,
        };
        let s = serde_json::to_string(&json).map_err(CliError::failure)?;
        println!("{s}");
        return Ok(());
    }
    let source = match (&args.embedding, args.precompute) {
        (Some(p), _) => p.display().to_string(),
        (None, true) => "computed (--precompute)".into(),
        (None, false) => "3-D positions".into(),
    };
    // CPU per query is NaN where the platform has no process CPU clock.
    let cpu = |c: Option<f64>| c.unwrap_or(f64::NAN);
    println!(
        "mesh                      {} ({} vertices, {} faces)",
        args.mesh, report.vertices, report.faces
    );
    println!("embedding                 {source} ({t_emb:.2} s)");
    println!("projector                 {t_proj:.2} s");
    println!(
        "anchors / queries         {} / {} ({} threads, best of {})",
        report.anchors, report.queries, report.threads, report.repeat
    );
    println!(
        "inverse_us                {:.3}  (CPU per query {:.3})",
        report.inverse_us,
        cpu(report.inverse_cpu_us)
    );
    println!(
        "forward_us                {:.3}  (CPU per query {:.3})",
        report.forward_us,
        cpu(report.forward_cpu_us)
    );
    println!(
        "forward_warm_us           {:.3}  (CPU per query {:.3})",
        report.forward_warm_us,
        cpu(report.forward_warm_cpu_us)
    );
    println!("load average              {}", load_average());
    println!(
        "roundtrip_ok_fraction     {:.5}  (warm: {:.5})",
        report.roundtrip_ok_fraction, report.roundtrip_warm_ok_fraction
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
        report.forward_local, report.forward_fallback, report.forward_failed, report.inverse_failed
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

/// `--precompute`: the embedding pipeline with default parameters.
fn precompute_embedding(
    mesh: &std::sync::Arc<wavg::ValidMesh>,
) -> Result<std::sync::Arc<wavg::EmbeddedMesh>, CliError> {
    let opts = wavg::PrecomputeOptions::default();
    let (emb, _) = wavg::embed::precompute(mesh, &opts, &wavg::NoProgress).context("precompute")?;
    let coords = emb.coords.iter().map(|c| wavg::Vec8::from(*c)).collect();
    wavg::EmbeddedMesh::new(mesh.clone(), coords)
        .map(std::sync::Arc::new)
        .context("precompute")
}
