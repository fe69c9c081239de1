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
bad barycentrics) are input errors: exit status 2 naming the line, and nothing is written.";

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
    #[arg(long, default_value_t = wavg_solve::kernel::DEFAULT_GAMMA)]
    pub gamma: f64,
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
