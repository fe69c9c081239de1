//! `wavg bench spline`: time per sample of a curve on the surface ([`evaluate_spline`],
//! the same call as `wavg spline`), best of repeated runs, with the samples checked
//! against the closest valid projection of each sample's average.

use std::time::Instant;

use serde::Serialize;
use wavg::apps::{SplineKind, evaluate_spline, spline_weights_flat};
use wavg::{ForwardOptions, SearchMode};

use crate::CliError;
use crate::error::Context;
use crate::textio;

/// Arguments.
#[derive(clap::Args)]
#[command(after_long_help = "\
Evaluates the curve of `wavg spline` (same control points, kind and chunking) --repeat
times on T threads and reports us_per_sample (best wall time / samples), us_per_sample_median
and cpu_us_per_sample (process CPU time of all runs / all samples). Every sample is also
solved on its own by the certified search (the closest valid projection of its average,
no warm start): agree_fraction is the fraction of samples whose curve point lies within
1e-6 mean edge lengths of that answer (or that both fail),
max_disagreement the largest distance in mean edge lengths (0 when all agree). Also
samples, ok_samples, controls, threads, repeat, load (1-minute load average) and mesh.
builtin:genus2 (51k vertices, genus 2) is the mesh of the spline figures in BENCHMARKS.md.")]
pub struct Args {
    #[command(flatten)]
    pub mesh: crate::mesh_arg::MeshArg,
    /// A .wavg embedding of the mesh (default: the embedding cache's).
    #[arg(long)]
    pub embedding: Option<std::path::PathBuf>,
    #[command(flatten)]
    pub cache: crate::cache::CacheArg,
    /// Control points, one per line (`v VERTEX` or `f FACE B0 B1 B2`).
    #[arg(long)]
    pub control: std::path::PathBuf,
    /// B-spline degree.
    #[arg(long, default_value_t = 3)]
    pub degree: usize,
    /// A closed (periodic) B-spline.
    #[arg(long)]
    pub closed: bool,
    /// Samples along the curve.
    #[arg(long, default_value_t = 500, value_parser = crate::common::parse_samples)]
    pub samples: usize,
    /// Timed runs.
    #[arg(long, default_value_t = 50, value_parser = crate::common::parse_repeat)]
    pub repeat: usize,
    /// Worker threads T (default: all cores; the limit: docs/limits.md).
    #[arg(long, value_parser = crate::common::parse_threads)]
    pub threads: Option<usize>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// The report (`--json` keys).
#[derive(Serialize)]
struct Report<'a> {
    mesh: &'a str,
    controls: usize,
    samples: usize,
    ok_samples: usize,
    threads: usize,
    repeat: usize,
    us_per_sample: f64,
    us_per_sample_median: f64,
    cpu_us_per_sample: Option<f64>,
    agree_fraction: f64,
    max_disagreement: f64,
    load: String,
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), CliError> {
    if args.samples == 0 || args.repeat == 0 {
        return Err(CliError::input("--samples and --repeat must be at least 1"));
    }
    let kind = SplineKind::BSpline {
        degree: args.degree,
        closed: args.closed,
    };
    let solver = crate::apps_common::solver_for(
        &args.mesh,
        args.embedding.as_deref(),
        &args.control,
        args.cache,
    )?;
    let threads = args.threads.unwrap_or_else(rayon::current_num_threads);
    let (times, curve, cpu) = textio::with_threads(Some(threads), || {
        let cpu0 = crate::common::cpu_seconds(false);
        let mut times = Vec::with_capacity(args.repeat);
        let mut curve = None;
        for _ in 0..args.repeat {
            let t = Instant::now();
            let c = evaluate_spline(&solver, kind, args.samples, crate::spline::CHUNK);
            times.push(t.elapsed().as_secs_f64());
            curve = Some(c);
        }
        let cpu = crate::common::cpu_seconds(false)
            .zip(cpu0)
            .map(|(b, a)| b - a);
        (times, curve, cpu)
    })?;
    let curve = curve
        .expect("repeat >= 1")
        .context(args.control.display())?;
    // The reference: every sample on its own, the closest valid projection.
    let flat = spline_weights_flat(kind, solver.n_anchors(), args.samples)
        .context(args.control.display())?;
    let mel = solver.mean_edge_length();
    let closest = ForwardOptions {
        mode: SearchMode::Certified,
        ..ForwardOptions::default()
    };
    let mut agree = 0usize;
    let mut worst = 0.0f64;
    for (w, got) in flat.chunks_exact(solver.n_anchors()).zip(&curve.samples) {
        let want = solver.forward(w, &closest);
        match (got, want) {
            (Ok(a), Ok(b)) => {
                let d = (a.position - b.position).norm() / mel;
                worst = worst.max(d);
                agree += usize::from(d <= 1e-6);
            }
            (Err(_), Err(_)) => agree += 1,
            _ => worst = f64::INFINITY,
        }
    }
    let mut sorted = times.clone();
    sorted.sort_by(f64::total_cmp);
    let n = args.samples as f64;
    let report = Report {
        mesh: &args.mesh,
        controls: solver.n_anchors(),
        samples: args.samples,
        ok_samples: curve.ok_samples(),
        threads,
        repeat: args.repeat,
        us_per_sample: sorted[0] / n * 1e6,
        us_per_sample_median: sorted[sorted.len() / 2] / n * 1e6,
        cpu_us_per_sample: cpu.map(|c| c / (n * args.repeat as f64) * 1e6),
        agree_fraction: agree as f64 / n,
        max_disagreement: worst,
        load: crate::bench_roundtrip::load_average(),
    };
    if args.json {
        let s = serde_json::to_string(&report).map_err(CliError::failure)?;
        println!("{s}");
    } else {
        println!(
            "{}: {} of {} samples, {:.3} us per sample (median {:.3}, CPU {:.3}) on {} threads; \
             {:.5} agree with the closest projections (worst {:.3e} mean edges); load {}",
            report.mesh,
            report.ok_samples,
            report.samples,
            report.us_per_sample,
            report.us_per_sample_median,
            report.cpu_us_per_sample.unwrap_or(f64::NAN),
            report.threads,
            report.agree_fraction,
            report.max_disagreement,
            report.load
        );
    }
    Ok(())
}
