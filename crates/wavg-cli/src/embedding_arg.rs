//! The `--embedding FILE` option with the `--no-cache` flag, as the commands that solve on
//! one mesh take them: a given embedding, else the embedding cache's.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use wavg::{Solver, Surface, ValidMesh};

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

/// The mesh with `--embedding` and `--no-cache`: the leading options of the commands that
/// solve on one mesh and take nothing before its embedding (`spline`, `decal`, `bench
/// spline`).
#[derive(clap::Args, Clone, Debug)]
pub struct SurfaceArgs {
    #[command(flatten)]
    pub mesh: crate::mesh_arg::MeshArg,
    #[command(flatten)]
    pub embedding: EmbeddingArg,
}

impl SurfaceArgs {
    /// The solver for this mesh with the anchors of the file `anchors` on its embedding.
    pub fn solver(&self, anchors: &Path) -> Result<Solver, CliError> {
        self.embedding.solver(&self.mesh, anchors)
    }

    /// The surface on `mesh` (this argument's mesh, loaded) with its embedding
    /// ([`crate::apps_common::embed`]).
    pub fn embed(&self, mesh: Arc<ValidMesh>) -> Result<Surface, CliError> {
        crate::apps_common::embed(
            mesh,
            self.embedding.file.as_deref(),
            &self.mesh,
            self.embedding.cache,
        )
    }
}
