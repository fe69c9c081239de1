//! The plain-text formats of `wavg forward` / `wavg inverse` and atomic output files.
//!
//! Input files have one item per line. `#` starts a comment that runs to the end of the
//! line; blank (or comment-only) lines are skipped. Line numbers in errors count every
//! physical line from 1.
//!
//! * Surface points (anchors, query points): `v VERTEX` (a mesh vertex, 0-based) or
//!   `f FACE B0 B1 B2` (0-based face, barycentric coordinates of its three corners).
//! * Weights: whitespace-separated decimal numbers, one query per line.

use std::fmt;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use wavg_mesh::{SurfacePoint, ValidMesh};
use wavg_solve::{Anchor, EmbeddedMesh, Projector, Solver, Vec8};

use crate::CliError;
use crate::common::{load_valid, one_line};

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
a temporary file beside it and renamed only on success); '-o -' writes to stdout.
Files stream through in chunks of 65,536 lines (bounded memory).
NUMPY: an input or output whose name ends in .npy is a NumPy array instead: weights n x K
(inverse output: NaN rows where there are no weights); points n x 4 'FACE B0 B1 B2';
forward output n x 7 'FACE B0 B1 B2 X Y Z' (face -1 and NaN where there is no answer).";

pub use wavg::text::PointSpec;

/// Reads a whole text file, mapping failures to exit status 2.
pub fn read_text(path: &Path) -> Result<String, CliError> {
    std::fs::read_to_string(path).map_err(|e| CliError::input(format!("{}: {e}", path.display())))
}

/// Writes `body`'s output to `path` atomically (temporary file in the same folder, renamed
/// on success) or to stdout when `path` is `-`. On any error nothing is left at `path`.
pub fn write_atomic(
    path: &Path,
    body: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), CliError> {
    let fail = |e: &dyn fmt::Display| CliError::failure(format!("{}: {e}", path.display()));
    if path == Path::new("-") {
        let stdout = std::io::stdout();
        let mut w = std::io::BufWriter::new(stdout.lock());
        body(&mut w)
            .and_then(|()| w.flush())
            .map_err(|e| fail(&e))?;
        return Ok(());
    }
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let tmp = tempfile::NamedTempFile::new_in(dir).map_err(|e| fail(&e))?;
    {
        let mut w = std::io::BufWriter::new(tmp.as_file());
        body(&mut w)
            .and_then(|()| w.flush())
            .map_err(|e| fail(&e))?;
    }
    tmp.persist(path).map_err(|e| fail(&e.error))?;
    Ok(())
}

/// Arguments shared by `wavg forward` and `wavg inverse`: the mesh, its embedding, the
/// anchors, the output and the thread count.
#[derive(clap::Args)]
pub struct ProblemArgs {
    /// Mesh file (.obj/.off/.ply, optionally .gz) or builtin:NAME.
    #[arg(long)]
    pub mesh: String,
    /// Embedding (.wavg from `wavg precompute`); default: the mesh's 3-D positions.
    #[arg(long)]
    pub embedding: Option<PathBuf>,
    /// Anchors file ('v VERTEX' or 'f FACE B0 B1 B2' per line).
    #[arg(long)]
    pub anchors: PathBuf,
    /// Output file ('-' for stdout).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
}

/// The embedded mesh: the `.wavg` embedding when given, else the 3-D positions.
pub fn load_embedded(
    mesh: Arc<ValidMesh>,
    embedding: Option<&Path>,
) -> Result<Arc<EmbeddedMesh>, CliError> {
    let Some(path) = embedding else {
        return Ok(Arc::new(EmbeddedMesh::from_positions(mesh)));
    };
    let e = wavg_embed::file::load(path, &mesh).map_err(|e| CliError::input(one_line(&e)))?;
    let coords: Vec<Vec8> = e.coords.iter().map(|c| Vec8::from(*c)).collect();
    let emb = EmbeddedMesh::new(mesh, coords)
        .map_err(|e| CliError::input(format!("{}: {}", path.display(), one_line(&e))))?;
    Ok(Arc::new(emb))
}

/// Builds the projector (tangent frames, per-triangle data) for an embedded mesh.
pub fn build_projector(emb: Arc<EmbeddedMesh>) -> Result<Arc<Projector>, CliError> {
    Projector::new(emb)
        .map(Arc::new)
        .map_err(|e| CliError::failure(one_line(&e)))
}

/// Resolves parsed point specs against `mesh`; errors name `file` and the line.
pub fn resolve_points(
    mesh: &ValidMesh,
    specs: &[(usize, PointSpec)],
    file: &Path,
) -> Result<Vec<SurfacePoint>, CliError> {
    specs
        .iter()
        .map(|&(line, spec)| {
            let a = spec_anchor(spec).map_err(|m| located(file, line, &m))?;
            wavg_solve::resolve_anchor(mesh, &a).map_err(|e| located(file, line, &e))
        })
        .collect()
}

/// A spec as an [`Anchor`] (indices must fit in 32 bits).
pub fn spec_anchor(spec: PointSpec) -> Result<Anchor, String> {
    let idx =
        |i: u64, what: &str| u32::try_from(i).map_err(|_| format!("{what} {i} is out of range"));
    Ok(match spec {
        PointSpec::Vertex(v) => Anchor::Vertex(idx(v, "vertex")?),
        PointSpec::Face { face, bary } => {
            Anchor::Point(SurfacePoint::new(idx(face, "face")?, bary))
        }
    })
}

/// An input error at `file:line` (exit status 2).
pub fn located(file: &Path, line: usize, msg: &dyn fmt::Display) -> CliError {
    CliError::input(format!("{}:{line}: {}", file.display(), one_line(msg)))
}

/// Reads and parses a point file, mapping errors to `file:line` input errors.
pub fn read_points(file: &Path) -> Result<Vec<(usize, PointSpec)>, CliError> {
    wavg::text::parse_points(&read_text(file)?, 1).map_err(|e| located(file, e.line, &e.message))
}

/// Loads mesh, embedding and anchors, and makes the solver (shared by forward/inverse).
pub fn load_solver(
    mesh: &str,
    embedding: Option<&Path>,
    anchors: &Path,
) -> Result<Solver, CliError> {
    let specs = read_points(anchors)?;
    if specs.is_empty() {
        return Err(CliError::input(format!(
            "{}: no anchors",
            anchors.display()
        )));
    }
    let mesh = load_valid(mesh)?;
    let anchor_list = specs
        .iter()
        .map(|&(line, s)| spec_anchor(s).map_err(|m| located(anchors, line, &m)))
        .collect::<Result<Vec<_>, _>>()?;
    // Validate each anchor with its line number before building anything expensive.
    for (&(line, _), a) in specs.iter().zip(&anchor_list) {
        wavg_solve::resolve_anchor(&mesh, a).map_err(|e| located(anchors, line, &e))?;
    }
    let emb = load_embedded(mesh, embedding)?;
    let proj = build_projector(emb)?;
    Solver::new(proj, anchor_list).map_err(|e| CliError::input(one_line(&e)))
}

/// Runs `f` on a pool of `threads` threads (rayon's default when `None`).
pub fn with_threads<T: Send>(
    threads: Option<usize>,
    f: impl FnOnce() -> T + Send,
) -> Result<T, CliError> {
    match threads {
        None => Ok(f()),
        Some(0) => Err(CliError::input("--threads must be at least 1")),
        Some(t) => rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .map(|p| p.install(f))
            .map_err(|e| CliError::failure(format!("cannot start {t} threads: {e}"))),
    }
}

/// Writes numbers separated by single spaces.
pub fn write_numbers(w: &mut dyn Write, xs: impl IntoIterator<Item = f64>) -> std::io::Result<()> {
    let mut buf = Vec::new();
    wavg::text::push_numbers(&mut buf, xs);
    w.write_all(&buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atomic_write_leaves_nothing_on_error() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("out.txt");
        let r = write_atomic(&out, |w| {
            w.write_all(b"half")?;
            Err(std::io::Error::other("boom"))
        });
        assert!(r.is_err());
        assert!(!out.exists());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        write_atomic(&out, |w| write_numbers(w, [1.0, 0.1, -2.5e-300])).unwrap();
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "1.0 0.1 -2.5e-300");
    }
}
