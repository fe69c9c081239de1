//! Parsing the plain-text point and weight files (no I/O).

use std::fmt;

/// Text of the formats for `--help` (kept next to the parser so they cannot drift apart).
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
a temporary file beside it and renamed only on success); '-o -' writes to stdout.";

/// A malformed line.
#[derive(Debug, Clone, PartialEq)]
pub struct LineError {
    /// 1-based line number.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for LineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}: {}", self.line, self.message)
    }
}

/// A surface point as written in a file (not yet checked against a mesh).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PointSpec {
    /// `v VERTEX`.
    Vertex(u64),
    /// `f FACE B0 B1 B2`.
    Face {
        /// Face index.
        face: u64,
        /// Barycentric coordinates as written.
        bary: [f64; 3],
    },
}

/// The non-blank, non-comment lines of `text` with their 1-based line numbers, each split
/// into whitespace-separated tokens.
fn content_lines(text: &str) -> impl Iterator<Item = (usize, Vec<&str>)> {
    text.lines().enumerate().filter_map(|(i, l)| {
        let l = l.split_once('#').map_or(l, |(a, _)| a);
        let toks: Vec<&str> = l.split_whitespace().collect();
        (!toks.is_empty()).then_some((i + 1, toks))
    })
}

fn number(tok: &str, line: usize, what: &str) -> Result<f64, LineError> {
    let x: f64 = tok.parse().map_err(|_| LineError {
        line,
        message: format!("{what}: '{tok}' is not a number"),
    })?;
    if !x.is_finite() {
        return Err(LineError {
            line,
            message: format!("{what}: '{tok}' is not finite"),
        });
    }
    Ok(x)
}

fn index(tok: &str, line: usize, what: &str) -> Result<u64, LineError> {
    tok.parse().map_err(|_| LineError {
        line,
        message: format!("{what}: '{tok}' is not a non-negative integer"),
    })
}

/// Parses a surface-point file (`v VERTEX` / `f FACE B0 B1 B2` lines).
pub fn parse_points(text: &str) -> Result<Vec<(usize, PointSpec)>, LineError> {
    content_lines(text)
        .map(|(line, t)| {
            let spec = match (t[0], t.len()) {
                ("v", 2) => PointSpec::Vertex(index(t[1], line, "vertex index")?),
                ("f", 5) => PointSpec::Face {
                    face: index(t[1], line, "face index")?,
                    bary: [
                        number(t[2], line, "barycentric B0")?,
                        number(t[3], line, "barycentric B1")?,
                        number(t[4], line, "barycentric B2")?,
                    ],
                },
                ("v", n) => {
                    return Err(LineError {
                        line,
                        message: format!("'v' takes 1 value (VERTEX), got {}", n - 1),
                    });
                }
                ("f", n) => {
                    return Err(LineError {
                        line,
                        message: format!("'f' takes 4 values (FACE B0 B1 B2), got {}", n - 1),
                    });
                }
                (other, _) => {
                    return Err(LineError {
                        line,
                        message: format!(
                            "expected 'v VERTEX' or 'f FACE B0 B1 B2', found '{other}'"
                        ),
                    });
                }
            };
            Ok((line, spec))
        })
        .collect()
}

/// Parses a weights file: every content line is a list of numbers.
pub fn parse_weights(text: &str) -> Result<Vec<(usize, Vec<f64>)>, LineError> {
    content_lines(text)
        .map(|(line, t)| {
            let w = t
                .iter()
                .enumerate()
                .map(|(i, tok)| number(tok, line, &format!("weight {i}")))
                .collect::<Result<Vec<f64>, _>>()?;
            Ok((line, w))
        })
        .collect()
}
