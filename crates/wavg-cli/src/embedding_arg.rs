//! The `--embedding FILE` option with the `--no-cache` flag, as the commands that solve on
//! one mesh take them: a given embedding, else the embedding cache's.

use std::path::{Path, PathBuf};

use wavg::Solver;

use crate::CliError;
use crate::cache::CacheArg;

/// `--embedding` and `--no-cache`.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct EmbeddingArg {
    /// A .wavg embedding of the mesh (default: the embedding cache's, computed on first
    /// use).
    #[arg(long = "embedding", id = "embedding", value_name = "EMBEDDING")]
    pub file: Option<PathBuf>,
    #[command(flatten)]
    pub cache: CacheArg,
}

impl EmbeddingArg {
    /// The solver for `mesh` with the anchors of the file `anchors` on this embedding
    /// ([`crate::apps_common::solver_for`]).
    pub fn solver(&self, mesh: &str, anchors: &Path) -> Result<Solver, CliError> {
        crate::apps_common::solver_for(mesh, self.file.as_deref(), anchors, self.cache)
    }
}
