//! `wavg inverse`: anchors + surface points -> weights.

use std::path::PathBuf;

use wavg::text::{self, PointSpec};
use wavg::{BatchWeights, DEFAULT_TOLERANCE, RoundTrip, Verified};

use crate::CliError;
use crate::stream::{Format, NpyRow, Sink, stream_queries};
use crate::textio;

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
lambda d_ref |ybar - yhat|^2, d_ref the fourth smallest D_ii). A point that no weights
reach is written as 'none not-reached' (a NaN row in .npy), as the C call
wavg_inverse_verified returns NO_SOLUTION for it: add anchors near it (wavg anchors
--count). A summary on standard error counts the penalised and the unreached points and
lists the latter (counted from 1). About 3-5x slower.

Why points fail to round-trip: the paper's weights make the point a stationary projection
of the anchors' average; on thin parts covered by few anchors (a pig's ears with 27
anchors) the average can land nearer another part of the surface, and the forward problem
then returns that part (about 5% of random points on pig.off with 27 anchors). This is a
property of the weights, not of the search: `wavg bench roundtrip --search certified`,
which always returns the closest valid projection, round-trips hardly more points (0.9512
of them on armadillo with 93 anchors, against 0.9509 with the paper's local search). In
Rust: Solver::inverse_verified, and for many points Solver::inverse_verified_batch_into.";

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
    #[arg(long, default_value_t = wavg::DEFAULT_GAMMA, allow_negative_numbers = true)]
    pub gamma: f64,
    /// Check each answer by the forward problem; penalise the average's offset where the
    /// paper's weights do not lead back.
    #[arg(long)]
    pub verified: bool,
}

/// Runs the command: the points stream through in chunks (parsed, resolved, solved and
/// written in parallel), so files of any length use bounded memory.
pub fn run(args: Args) -> Result<(), CliError> {
    args.problem.check_output(&args.points)?;
    let mut solver = textio::load_solver(&args.problem)?;
    solver
        .set_gamma(args.gamma)
        .map_err(|e| CliError::input(format!("--gamma: {e}")))?;
    let solver = solver;
    let resolve =
        |rows: &[(usize, PointSpec)]| textio::resolve_points(solver.mesh(), rows, &args.points);
    let mut summary = VerifiedSummary::default();
    let mut weights = BatchWeights::default();
    let solve = |rows: Vec<(usize, PointSpec)>, sink: &mut Sink| -> Result<(), CliError> {
        let points = resolve(&rows)?;
        let written = if args.verified {
            let batch = solver.inverse_verified_batch(&points, DEFAULT_TOLERANCE);
            summary.add(&batch);
            sink.write(
                &batch,
                |r, out| match r {
                    Ok(v) if v.round_trip == RoundTrip::NotReached => {
                        out.extend_from_slice(NOT_REACHED.as_bytes())
                    }
                    Ok(v) => text::push_numbers(out, v.weights.iter().copied()),
                    Err(e) => none(out, e),
                },
                |r, row| {
                    if let Ok(v) = r
                        && v.round_trip != RoundTrip::NotReached
                    {
                        row.copy_from_slice(&v.weights);
                    }
                },
            )
        } else {
            // `Par::Rayon` always starts.
            let _ = solver.inverse_batch_into(&points, &mut weights, wavg::Par::Rayon);
            let rows: Vec<usize> = (0..weights.len()).collect();
            summary.points += rows.len();
            summary.none += rows.iter().filter(|&&i| weights.get(i).is_err()).count();
            sink.write(
                &rows,
                |&i, out| match weights.get(i) {
                    Ok(ws) => text::push_numbers(out, ws.iter().copied()),
                    Err(e) => none(out, e),
                },
                |&i, row| {
                    if let Ok(ws) = weights.get(i) {
                        row.copy_from_slice(ws);
                    }
                },
            )
        };
        written.map_err(|e| CliError::failure(format!("{}: {e}", args.problem.output.display())))
    };
    let check = |rows: &[(usize, PointSpec)]| resolve(rows).map(|_| ());
    textio::with_threads(args.problem.threads, || {
        let format = Format {
            text: text::parse_points,
            npy: npy_point,
        };
        let k = solver.n_anchors();
        stream_queries(&args.points, &args.problem.output, format, k, check, solve)
    })??;
    if args.verified {
        summary.report();
    }
    if summary.points > 0 {
        let what = if args.verified {
            "points that weights lead back to"
        } else {
            "points with weights"
        };
        crate::anchors::warn_if_low(
            1.0 - (summary.missed.len() + summary.none) as f64 / summary.points as f64,
            what,
            solver.n_anchors(),
            &args.problem.mesh,
        );
    }
    Ok(())
}

/// A `.npy` point row: `FACE B0 B1 B2` (the face index as a float holding an integer).
fn npy_point(line: usize, row: NpyRow) -> Result<PointSpec, wavg::text::LineError> {
    let err = |message: String| wavg::text::LineError { line, message };
    let [face, b0, b1, b2] = &row[..] else {
        return Err(err(format!(
            "a point row has 4 values (FACE B0 B1 B2), got {}",
            row.len()
        )));
    };
    if !(*face >= 0.0 && face.fract() == 0.0 && *face < 4_294_967_296.0) {
        return Err(err(format!(
            "face index {face} is not a non-negative integer"
        )));
    }
    if let Some(b) = [b0, b1, b2].into_iter().find(|b| !b.is_finite()) {
        return Err(err(format!("barycentric coordinate {b} is not finite")));
    }
    Ok(PointSpec::Face {
        face: *face as u64,
        bary: [*b0, *b1, *b2],
    })
}

/// The line of a point that `--verified` finds no weights for (the C ABI's `NO_SOLUTION`).
const NOT_REACHED: &str = "none not-reached";

/// `none REASON` for a point without weights.
fn none(out: &mut Vec<u8>, e: &wavg::SolveError) {
    wavg::lines::push_answer(out, Err(&crate::common::reason(e)));
}

/// What `--verified` reports on standard error: penalised points and points no weights
/// reach (counted from 1 over the whole file); and, for the warning, points without weights.
#[derive(Default)]
struct VerifiedSummary {
    points: usize,
    penalised: usize,
    missed: Vec<usize>,
    /// Points without weights at all (`none REASON`).
    none: usize,
}

impl VerifiedSummary {
    fn add(&mut self, batch: &[Result<Verified, wavg::SolveError>]) {
        for (i, r) in batch.iter().enumerate() {
            match r {
                Err(_) => self.none += 1,
                Ok(v) if matches!(v.round_trip, RoundTrip::Penalized(_)) => self.penalised += 1,
                Ok(v) if v.round_trip == RoundTrip::NotReached => {
                    self.missed.push(self.points + i + 1);
                }
                _ => {}
            }
        }
        self.points += batch.len();
    }

    fn report(&self) {
        let shown: Vec<String> = self.missed.iter().take(20).map(|i| i.to_string()).collect();
        eprintln!(
            "verified: {} points, {} with penalised weights, {} not reached{}",
            self.points,
            self.penalised,
            self.missed.len(),
            if shown.is_empty() {
                String::new()
            } else {
                let more = if self.missed.len() > 20 { ", ..." } else { "" };
                format!(" (points {}{more}, counted from 1)", shown.join(", "))
            }
        );
    }
}
