//! `wavg bench spline`: time per sample of a curve on the surface, best of repeated runs,
//! with the samples checked against the closest valid projection of each sample's average
//! (the protocol is [`wavg_bench::spline_bench`]'s; this prints its report).

use serde::Serialize;
use wavg::apps::SplineKind;
use wavg_bench::{SplineBenchOptions, SplineBenchReport, load_average, spline_bench};

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
    pub surface: crate::embedding_arg::SurfaceArgs,
    /// Control points, one per line (`v VERTEX` or `f FACE B0 B1 B2`).
    #[arg(long)]
    pub control: std::path::PathBuf,
    /// B-spline degree.
    #[arg(long, default_value_t = wavg::apps::DEFAULT_SPLINE_DEGREE)]
    pub degree: usize,
    /// A closed (periodic) B-spline.
    #[arg(long)]
    pub closed: bool,
    /// Samples along the curve.
    #[arg(long, default_value_t = wavg::apps::DEFAULT_SPLINE_SAMPLES, value_parser = crate::common::parse_samples)]
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

/// The `--json` object: the protocol's report between the mesh argument and the load
/// average.
#[derive(Serialize)]
struct JsonReport<'a> {
    mesh: &'a str,
    #[serde(flatten)]
    report: &'a SplineBenchReport,
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
    let solver = args.surface.solver(&args.control)?;
    let threads = args.threads.unwrap_or_else(rayon::current_num_threads);
    let opts = SplineBenchOptions {
        kind,
        samples: args.samples,
        repeat: args.repeat,
        chunk: wavg::apps::SPLINE_CHUNK,
        cpu_clock: Some(|| crate::common::cpu_seconds(false)),
    };
    let report = textio::with_threads(Some(threads), || spline_bench(&solver, &opts))?
        .context(args.control.display())?;
    let json = JsonReport {
        mesh: &args.surface.mesh,
        report: &report,
        load: load_average(),
    };
    if args.json {
        let s = serde_json::to_string(&json).map_err(CliError::failure)?;
        println!("{s}");
    } else {
        println!(
            "{}: {} of {} samples, {:.3} us per sample (median {:.3}, CPU {:.3}) on {} threads; \
             {:.5} agree with the closest projections (worst {:.3e} mean edges); load {}",
            json.mesh,
            report.ok_samples,
            report.samples,
            report.us_per_sample,
            report.us_per_sample_median,
            report.cpu_us_per_sample.unwrap_or(f64::NAN),
            report.threads,
            report.agree_fraction,
            report.max_disagreement,
            json.load
        );
    }
    Ok(())
}
