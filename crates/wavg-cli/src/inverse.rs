//! `wavg inverse`: anchors + surface points -> weights.

use std::io::Write;
use std::path::PathBuf;

use crate::CliError;
use crate::textio::{self, write_numbers};

const LONG_ABOUT: &str = "\
Inverse problem: for each surface point, weights (one per anchor, summing to 1) whose
weighted average is that point: the minimum-norm weights of the paper (Section 3.4) that
make the point the Phong projection of the anchors' average, with far anchors and anchors
off the tangent plane penalised (D_ii = |v_T|^2 + gamma |v_O|^2, gamma = 10 by default).
At an anchor the weight is one-hot; weights are continuous across edges.

Output: one line per point with the weights in anchor order, or 'none REASON' when no
weights exist (the anchors do not surround the point in its tangent plane, e.g. fewer than
three anchors or all on a line). Malformed points (bad line, face or vertex out of range,
bad barycentrics) are input errors: exit status 2 naming the line, and nothing is written.

--verified checks every answer with the forward problem (the paper's search, no initial
guess): where the paper's weights do not lead back to the point (within 1e-3 mean edge
lengths; it happens on thin parts covered by few anchors), the smallest offset penalty
lambda in 10, 100, 1000, 10000 whose weights do is used instead (the objective gains
lambda d_ref |ybar - yhat|^2, d_ref the fourth smallest D_ii). The output format is
unchanged; a summary on standard error counts the penalised points and lists the points
(counted from 1) that no weights reach (those get the paper's weights). About 3-5x slower.";

/// Arguments.
#[derive(clap::Args)]
#[command(after_long_help = format!("{LONG_ABOUT}\n\n{}", textio::FORMAT_HELP))]
pub struct Args {
    #[command(flatten)]
    pub problem: textio::ProblemArgs,
    /// Points file ('v VERTEX' or 'f FACE B0 B1 B2' per line).
    #[arg(long)]
    pub points: PathBuf,
    /// How much more distance off the tangent plane counts than distance along it.
    #[arg(long, default_value_t = wavg_solve::DEFAULT_GAMMA)]
    pub gamma: f64,
    /// Check each answer by the forward problem; penalise the average's offset where the
    /// paper's weights do not lead back.
    #[arg(long)]
    pub verified: bool,
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), CliError> {
    let specs = textio::read_points(&args.points)?;
    let mut solver = textio::load_solver(
        &args.problem.mesh,
        args.problem.embedding.as_deref(),
        &args.problem.anchors,
    )?;
    solver
        .set_gamma(args.gamma)
        .map_err(|e| CliError::input(format!("--gamma: {e}")))?;
    let points = textio::resolve_points(solver.mesh(), &specs, &args.points)?;
    if args.verified {
        return run_verified(&args, &solver, &points);
    }
    let batch = textio::with_threads(args.problem.threads, || solver.inverse_batch(&points))?;
    textio::write_atomic(&args.problem.output, |w: &mut dyn Write| {
        for r in batch.iter() {
            match r {
                Ok(ws) => write_numbers(w, ws.iter().copied())?,
                Err(e) => write!(w, "none {}", crate::common::one_line(e))?,
            }
            writeln!(w)?;
        }
        Ok(())
    })
}

/// `--verified`: the same output, from [`wavg_solve::Solver::inverse_verified`].
fn run_verified(
    args: &Args,
    solver: &wavg_solve::Solver,
    points: &[wavg_mesh::SurfacePoint],
) -> Result<(), CliError> {
    use wavg_solve::DEFAULT_TOLERANCE;
    use wavg_solve::RoundTrip;
    let batch = textio::with_threads(args.problem.threads, || {
        solver.inverse_verified_batch(points, DEFAULT_TOLERANCE)
    })?;
    textio::write_atomic(&args.problem.output, |w: &mut dyn Write| {
        for r in &batch {
            match r {
                Ok(v) => write_numbers(w, v.weights.iter().copied())?,
                Err(e) => write!(w, "none {}", crate::common::one_line(e))?,
            }
            writeln!(w)?;
        }
        Ok(())
    })?;
    let penalised = batch
        .iter()
        .filter(|r| matches!(r, Ok(v) if matches!(v.round_trip, RoundTrip::Penalized(_))))
        .count();
    let missed: Vec<String> = batch
        .iter()
        .enumerate()
        .filter(|(_, r)| matches!(r, Ok(v) if v.round_trip == RoundTrip::NotReached))
        .map(|(i, _)| (i + 1).to_string())
        .collect();
    eprintln!(
        "verified: {} points, {penalised} with penalised weights, {} not reached{}",
        batch.len(),
        missed.len(),
        if missed.is_empty() {
            String::new()
        } else {
            let shown = missed
                .iter()
                .take(20)
                .cloned()
                .collect::<Vec<_>>()
                .join(", ");
            let more = if missed.len() > 20 { ", ..." } else { "" };
            format!(" (points {shown}{more}, counted from 1)")
        }
    );
    Ok(())
}
