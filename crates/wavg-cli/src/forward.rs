//! `wavg forward`: anchors + weights -> points on the surface.

use std::path::PathBuf;

use rayon::prelude::*;
use wavg::text;

use wavg::{ForwardOptions, ForwardScratch, Normalization, Par, SearchMode, SolveError};

use crate::CliError;
use crate::stream::{Format, NpyRow, Sink, stream_queries};
use crate::textio::{self, located};

const LONG_ABOUT: &str = "\
Forward problem: for each line of weights, the point of the surface that is the weighted
average of the anchors (average the anchors' embedded points in R^8, then Phong-project
the average onto the embedded mesh; paper Section 3.3).

Output: one line per weight line, 'FACE B0 B1 B2 X Y Z' (face, barycentric coordinates,
3-D position), or 'none REASON' when no weighted average exists for that line (the
averaged point has no Phong projection onto any triangle). Weight lines that are
malformed, have the wrong count, non-finite values, or do not sum to 1 (without
--normalize) are input errors: the command exits with status 2 naming the line, and writes
nothing.

Each search walks from a vertex near the average (the highest-weight anchor's, or a closer
one found on a grid) and returns the first valid projection it meets, as the paper does;
when none is met nearby, a search of the whole mesh answers. --exact searches all
triangles for the closest projection; --warm starts each line from the previous line's
answer (for sequences of nearby queries).";

/// Arguments.
#[derive(clap::Args)]
#[command(after_long_help = format!("{LONG_ABOUT}\n\n{}", textio::FORMAT_HELP))]
pub struct Args {
    #[command(flatten)]
    pub problem: textio::ProblemArgs,
    /// Weights file (one line of numbers per query, one number per anchor).
    #[arg(long)]
    pub weights: PathBuf,
    /// Divide each weight line by its sum instead of rejecting lines that do not sum to 1.
    #[arg(long)]
    pub normalize: bool,
    /// Exhaustive search over all triangles (slow; for checking).
    #[arg(long, conflicts_with = "warm")]
    pub exact: bool,
    /// Start each query from the previous line's answer.
    #[arg(long)]
    pub warm: bool,
}

/// Runs the command: the weights stream through in chunks (parsed, checked, solved and
/// written in parallel), so files of any length use bounded memory.
pub fn run(args: Args) -> Result<(), CliError> {
    args.problem.check_output(&args.weights)?;
    let solver = textio::load_solver(&args.problem)?;
    let normalization = if args.normalize {
        Normalization::Normalize
    } else {
        Normalization::Reject
    };
    let opts = ForwardOptions {
        mode: if args.exact {
            SearchMode::Exact
        } else {
            SearchMode::Fast
        },
        normalization,
        warm_start: None,
    };
    // A line's weights as the forward problem checks them, its error naming the line.
    let validate = |line: usize, w: &[f64]| {
        wavg::validate_weights(w, solver.n_anchors(), normalization)
            .map(|_| ())
            .map_err(|e| match e {
                SolveError::WeightSum { .. } => located(
                    &args.weights,
                    line,
                    &format!("{e}; pass --normalize to divide each line by its sum"),
                ),
                e => located(&args.weights, line, &e),
            })
    };
    // The first pass for outputs that cannot be written atomically (in parallel; the
    // error reported is the first bad line's).
    let check = |rows: &[(usize, WeightRow)]| {
        let bad = rows
            .par_iter()
            .position_first(|(line, w)| validate(*line, w.as_ref()).is_err());
        bad.map_or(Ok(()), |i| validate(rows[i].0, rows[i].1.as_ref()))
    };
    // The batch's buffers live across chunks (no fresh memory to fault in per chunk).
    let (mut scratch, mut results) = (ForwardScratch::default(), Vec::new());
    // Lines answered and lines without a weighted average, for the warning at the end.
    let (mut answered, mut missing) = (0usize, 0usize);
    let solve = |rows: Vec<(usize, WeightRow)>, sink: &mut Sink| -> Result<(), CliError> {
        let weights: Vec<&[f64]> = rows.iter().map(|(_, w)| w.as_ref()).collect();
        // `Par::Rayon` always starts.
        let _ = if args.warm {
            solver.forward_batch_warm_into(&weights, &opts, 256, &mut results, Par::Rayon)
        } else {
            solver.forward_batch_into(&weights, &opts, &mut scratch, &mut results, Par::Rayon)
        };
        // The forward problem checks each row's weights: the first row it refused names its
        // line (an input error). Anything else but "no average" is a bug or a broken mesh:
        // fail whole.
        for (r, (line, w)) in results.iter().zip(&rows) {
            if let Err(e) = r
                && *e != SolveError::NoWeightedAverage
            {
                validate(*line, w.as_ref())?;
                return Err(CliError::failure(format!(
                    "{}:{line}: {e}",
                    args.weights.display()
                )));
            }
        }
        answered += results.len();
        missing += results.iter().filter(|r| r.is_err()).count();
        sink.write(
            &results,
            |r, out| wavg::lines::push_point(out, r),
            |r, row| match r {
                Ok(r) => {
                    row[0] = f64::from(r.point.face);
                    row[1..4].copy_from_slice(&r.point.bary);
                    row[4..7].copy_from_slice(r.position.as_slice());
                }
                Err(_) => row[0] = -1.0,
            },
        )
        .map_err(|e| CliError::failure(format!("{}: {e}", args.problem.output.display())))
    };
    textio::with_threads(args.problem.threads, || {
        let format = Format {
            text: |text, first| {
                let rows = text::parse_weights(text, first)?;
                Ok(rows
                    .into_iter()
                    .map(|(l, w)| (l, WeightRow::Text(w)))
                    .collect())
            },
            npy: |_, row| Ok(WeightRow::Npy(row)),
        };
        stream_queries(&args.weights, &args.problem.output, format, 7, check, solve)
    })??;
    if answered > 0 {
        crate::anchors::warn_if_low(
            1.0 - missing as f64 / answered as f64,
            "weight lines with a weighted average on the surface",
            solver.n_anchors(),
            &args.problem.mesh,
        );
    }
    Ok(())
}

/// One query's weights as read: a parsed text line, or a row of a `.npy` block.
enum WeightRow {
    Text(Vec<f64>),
    Npy(NpyRow),
}

impl AsRef<[f64]> for WeightRow {
    fn as_ref(&self) -> &[f64] {
        match self {
            WeightRow::Text(w) => w,
            WeightRow::Npy(row) => row,
        }
    }
}
