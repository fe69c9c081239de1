//! From the forward/inverse arguments to a solver: the mesh, its embedding, the anchors and
//! the thread pool.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use wavg::{EmbeddedMesh, Projector, Solver, Vec8};
use wavg::{SurfacePoint, ValidMesh};

use crate::CliError;
use crate::common::load_valid;
use crate::error::Context;

use super::{PointSpec, located};

/// Arguments shared by `wavg forward` and `wavg inverse`: the mesh, its embedding, the
/// anchors, the output and the thread count.
#[derive(clap::Args)]
pub struct ProblemArgs {
    #[command(flatten)]
    pub mesh: crate::mesh_arg::MeshArg,
    /// Embedding (.wavg from `wavg precompute`); default: the embedding cache's (computed
    /// on first use); `none`: the mesh's 3-D positions.
    #[arg(long)]
    pub embedding: Option<PathBuf>,
    #[command(flatten)]
    pub cache: crate::cache::CacheArg,
    /// Anchors file ('v VERTEX' or 'f FACE B0 B1 B2' per line).
    #[arg(long)]
    pub anchors: PathBuf,
    /// Output file ('-' for stdout).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Worker threads (default: all cores; the limit: docs/limits.md).
    #[arg(long, value_parser = crate::common::parse_threads)]
    pub threads: Option<usize>,
}

impl ProblemArgs {
    /// [`crate::common::check_outputs`] for `-o`, with the query file `queries` among the
    /// inputs.
    pub fn check_output(&self, queries: &Path) -> Result<(), CliError> {
        crate::common::check_outputs(
            &crate::common::inputs(
                [queries, Path::new(&*self.mesh), &self.anchors],
                [&self.embedding],
            ),
            &[("-o", &self.output)],
            false,
        )
    }
}

/// The `--embedding` value that asks for the mesh's 3-D positions as the embedding.
pub const NO_EMBEDDING: &str = "none";

/// The embedded mesh: the `.wavg` embedding when given, else the 3-D positions.
pub fn load_embedded(
    mesh: Arc<ValidMesh>,
    embedding: Option<&Path>,
) -> Result<Arc<EmbeddedMesh>, CliError> {
    let Some(path) = embedding.filter(|p| *p != Path::new(NO_EMBEDDING)) else {
        return Ok(Arc::new(EmbeddedMesh::from_positions(mesh)));
    };
    let e = wavg::embed::file::load(path, &mesh)?;
    let coords: Vec<Vec8> = e.coords.iter().map(|c| Vec8::from(*c)).collect();
    let emb = EmbeddedMesh::new(mesh, coords).context(path.display())?;
    Ok(Arc::new(emb))
}

/// Builds the projector (tangent frames, per-triangle data) for an embedded mesh.
pub fn build_projector(emb: Arc<EmbeddedMesh>) -> Result<Arc<Projector>, CliError> {
    Ok(Projector::new(emb).map(Arc::new)?)
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
            let a = wavg::anchors::spec_anchor(spec).map_err(|m| located(file, line, &m))?;
            wavg::resolve_anchor(mesh, &a).map_err(|e| located(file, line, &e))
        })
        .collect()
}

/// Loads mesh, embedding (the file, `none` for the 3-D positions, or by default the
/// cache's) and anchors, and makes the solver (shared by forward/inverse).
pub fn load_solver(args: &ProblemArgs) -> Result<Solver, CliError> {
    let (mesh, embedding, anchors) = (&*args.mesh, args.embedding.as_deref(), &*args.anchors);
    let mesh = load_valid(mesh)?;
    // Each anchor checked, errors naming its line, before building anything expensive.
    let anchor_list = wavg::anchors::read(anchors, &mesh)?;
    let emb = match embedding {
        Some(path) => load_embedded(mesh, Some(path))?,
        None => {
            let e = crate::cache::embedding(&mesh, &args.mesh, args.cache.no_cache)?;
            let coords: Vec<Vec8> = e.coords.iter().map(|c| Vec8::from(*c)).collect();
            let emb = EmbeddedMesh::new(mesh, coords)?;
            Arc::new(emb)
        }
    };
    let proj = build_projector(emb)?;
    Ok(Solver::new(proj, anchor_list)?)
}

/// Runs `f` on a pool of `threads` threads (rayon's default when `None`).
pub fn with_threads<T: Send>(
    threads: Option<usize>,
    f: impl FnOnce() -> T + Send,
) -> Result<T, CliError> {
    let par = wavg::Par::from_threads(threads)
        .map_err(|_| CliError::input("--threads must be at least 1"))?;
    Ok(par.install(f)?)
}
