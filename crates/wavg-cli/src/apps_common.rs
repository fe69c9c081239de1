//! What the application commands share: a solver for control points or anchors given in
//! the anchors format, on a mesh with a loaded or freshly precomputed embedding.

use std::path::Path;

use wavg::{NoProgress, PrecomputeOptions, Progress, Solver, Surface};

use crate::CliError;
use crate::common::{load_valid, one_line};
use crate::textio::{located, read_points, spec_anchor};

/// Loads the mesh, the embedding (`.wavg`, or precomputed in memory with a tenth of the
/// vertices as landmarks, 50 to 1000) and the anchors, each error naming its file and line.
pub fn solver_for(
    mesh: &str,
    embedding: Option<&Path>,
    anchors: &Path,
) -> Result<Solver, CliError> {
    solver_with_progress(mesh, embedding, anchors, &NoProgress)
}

/// [`solver_for`], reporting the precomputation's stages to `progress`.
pub fn solver_with_progress(
    mesh: &str,
    embedding: Option<&Path>,
    anchors: &Path,
    progress: &dyn Progress,
) -> Result<Solver, CliError> {
    let specs = read_points(anchors)?;
    if specs.is_empty() {
        return Err(CliError::input(format!("{}: no points", anchors.display())));
    }
    let mesh = load_valid(mesh)?;
    let list = specs
        .iter()
        .map(|&(line, s)| spec_anchor(s).map_err(|m| located(anchors, line, &m)))
        .collect::<Result<Vec<_>, _>>()?;
    for (&(line, _), a) in specs.iter().zip(&list) {
        wavg::solve::points::resolve(&mesh, a).map_err(|e| located(anchors, line, &e))?;
    }
    let mut surface = Surface::from_valid(mesh).map_err(|e| CliError::failure(one_line(&e)))?;
    match embedding {
        Some(path) => surface
            .load_embedding(path)
            .map_err(|e| CliError::input(one_line(&e)))?,
        None => {
            let landmarks = (surface.n_vertices() / 10).clamp(50, 1000);
            let opts = PrecomputeOptions {
                landmarks,
                quality_pairs: 0,
                ..Default::default()
            };
            surface
                .precompute(&opts, progress)
                .map_err(|e| CliError::failure(one_line(&e)))?;
        }
    }
    surface
        .solver(list)
        .map_err(|e| CliError::input(one_line(&e)))
}
