//! The formats' summary for `--help`; the formats themselves are described and parsed in
//! `wavg::text` and `wavg::npy`.

pub use wavg::text::PointSpec;

/// The formats' summary for `--help` (the full description is `wavg::text`'s and
/// `wavg::npy`'s).
pub const FORMAT_HELP: &str = "\
FILE FORMATS (plain text, one item per line; '#' starts a comment to the end of the line;
blank lines are skipped; errors name the 1-based physical line):
  anchors / points:  'v VERTEX'  or  'f FACE B0 B1 B2'
      VERTEX and FACE are 0-based indices into the mesh; B0 B1 B2 are barycentric
      coordinates of the face's three corners (finite, each >= -1e-6, summing to 1
      within 1e-6; tiny negatives are clamped and the sum renormalised).
  weights:  N whitespace-separated numbers per line (N = number of anchors), one query
      per line; each line must sum to 1 within 1e-6 unless --normalize is given.
Output lines correspond one-to-one, in order, to the input's non-blank, non-comment lines.
Numbers are written in the shortest form that reads back to the same f64.
Malformed input exits with status 2 and nothing is written (the output file is written to
a temporary file beside it and renamed only on success); '-o -' writes to stdout.
Files stream through in chunks of 65,536 lines (bounded memory).
NUMPY: an input or output whose name ends in .npy is a NumPy array instead: weights n x K
(inverse output: NaN rows where there are no weights); points n x 4 'FACE B0 B1 B2';
forward output n x 7 'FACE B0 B1 B2 X Y Z' (face -1 and NaN where there is no answer).";
