//! `wavg spline`: a B-spline or Bézier curve on the surface through control points given
//! in the anchors format; every sample is a forward problem warm-started from the last.

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use wavg::apps::{CurveReport, SPLINE_CHUNK, SplineKind, curve_scene, evaluate_spline};
use wavg::mesh::io::gltf::is_gltf_path;

use crate::CliError;
use crate::error::Context;
use crate::textio;

/// Arguments.
#[derive(clap::Args)]
#[command(after_long_help = "\
Samples a curve on the surface whose control points are the lines of --control (the
anchors format: `v VERTEX` or `f FACE B0 B1 B2`, one per line, in curve order). Default: a
clamped (open) cubic B-spline that starts at the first control point and ends at the last;
--closed makes it periodic (a loop), --bezier a Bézier curve of degree (controls - 1).
Each sample is the weighted average of the control points with the curve's blending
weights (forward problem), warm-started from the previous sample.

Output: one line per sample, `FACE B0 B1 B2 X Y Z`, or `none REASON` where the average has
no projection. --json prints one object: samples, ok_samples, seconds, us_per_sample,
length (3-D length of the polyline through the samples), plus mesh, controls, degree,
closed, bezier. With -o OUT.glb (or OUT.gltf, its buffer in OUT.bin) the samples on the
surface are written as one glTF polyline instead (LINE_STRIP, LINE_LOOP when --closed), to
view over the mesh.")]
pub struct Args {
    #[command(flatten)]
    pub surface: crate::embedding_arg::SurfaceArgs,
    /// Control points, one per line (`v VERTEX` or `f FACE B0 B1 B2`).
    #[arg(long)]
    pub control: PathBuf,
    /// B-spline degree.
    #[arg(long, default_value_t = wavg::apps::DEFAULT_SPLINE_DEGREE, conflicts_with = "bezier")]
    pub degree: usize,
    /// A closed (periodic) B-spline.
    #[arg(long, conflicts_with = "bezier")]
    pub closed: bool,
    /// A Bézier curve through all control points' Bernstein blend.
    #[arg(long)]
    pub bezier: bool,
    /// Samples along the curve.
    #[arg(long, default_value_t = wavg::apps::DEFAULT_SPLINE_SAMPLES, value_parser = crate::common::parse_samples)]
    pub samples: usize,
    /// Output file (`-` for standard output), or .glb/.gltf: the curve as a polyline.
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Print one JSON object on standard output.
    #[arg(long)]
    pub json: bool,
}

/// The `--json` object: the curve's [`CurveReport`] with the command's settings and
/// timings (printed through `serde_json::Value`, so keys come out sorted).
#[derive(serde::Serialize)]
struct JsonReport<'a> {
    mesh: &'a str,
    controls: usize,
    degree: usize,
    closed: bool,
    bezier: bool,
    #[serde(flatten)]
    curve: CurveReport,
    seconds: f64,
    us_per_sample: f64,
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), CliError> {
    crate::common::check_outputs(
        &crate::common::inputs(
            [std::path::Path::new(&*args.surface.mesh), &args.control],
            [&args.surface.embedding.file],
        ),
        &[("-o", &args.output)],
        args.json,
    )?;
    if args.samples == 0 {
        return Err(CliError::input("--samples must be at least 1"));
    }
    if !args.bezier && !(1..=64).contains(&args.degree) {
        return Err(CliError::input(format!(
            "--degree must be 1 to 64, got {}",
            args.degree
        )));
    }
    let kind = SplineKind::from_options(args.degree, args.closed, args.bezier);
    let solver = args.surface.solver(&args.control)?;
    let t = Instant::now();
    let curve = evaluate_spline(&solver, kind, args.samples, SPLINE_CHUNK)
        .context(args.control.display())?;
    let seconds = t.elapsed().as_secs_f64();
    let t = crate::common::step("spline", t);
    if is_gltf_path(&args.output) {
        curve_scene(&curve)
            .save(&args.output)
            .map_err(wavg::Error::from)?;
    } else {
        textio::write_atomic(&args.output, |w: &mut dyn Write| {
            w.write_all(&wavg::lines::points_text(&curve.samples))
        })?;
    }
    crate::common::step("write the curve", t);
    let ok = curve.ok_samples();
    crate::anchors::warn_if_low(
        ok as f64 / args.samples as f64,
        "samples of the curve on the surface",
        solver.n_anchors(),
        &args.surface.mesh,
    );
    let us = seconds / args.samples as f64 * 1e6;
    if args.json {
        let j = serde_json::to_value(JsonReport {
            mesh: &args.surface.mesh,
            controls: solver.n_anchors(),
            degree: if args.bezier {
                solver.n_anchors() - 1
            } else {
                args.degree
            },
            closed: args.closed,
            bezier: args.bezier,
            curve: curve.report(),
            seconds,
            us_per_sample: us,
        })
        .map_err(CliError::failure)?;
        println!("{j}");
    } else if args.output != std::path::Path::new("-") {
        println!(
            "{ok} of {} samples on the surface, length {:.6}, {us:.2} us per sample -> {}",
            args.samples,
            curve.length(),
            args.output.display()
        );
    }
    Ok(())
}
