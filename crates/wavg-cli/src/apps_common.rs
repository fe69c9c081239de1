//! What the application commands share: a solver for control points or anchors given in
//! the anchors format, on a mesh with a loaded or freshly precomputed embedding (with a
//! progress bar on a terminal).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use wavg::{Anchor, Embedding, Solver, Surface, ValidMesh};

use crate::CliError;
use crate::cache::CacheArg;
use crate::common::{load_mesh, validate};

/// Flags of the commands that relate two surfaces through anchors paired line by line
/// (correspond, morph, transfer-texture).
#[derive(clap::Args)]
pub struct PairArgs {
    /// Source mesh (.obj/.off/.ply, optionally .gz; .gltf/.glb, FILE#NAME for one mesh) or
    /// builtin:NAME.
    #[arg(long)]
    pub source: String,
    /// Target mesh.
    #[arg(long)]
    pub target: String,
    /// Anchors on the source (`v VERTEX` or `f FACE B0 B1 B2` per line).
    #[arg(long)]
    pub source_anchors: PathBuf,
    /// Anchors on the target, paired line by line with the source's (same count).
    #[arg(long)]
    pub target_anchors: PathBuf,
    /// A .wavg embedding of the source (default: the embedding cache's, computed on first
    /// use).
    #[arg(long)]
    pub source_embedding: Option<PathBuf>,
    /// A .wavg embedding of the target (default: the embedding cache's).
    #[arg(long)]
    pub target_embedding: Option<PathBuf>,
    #[command(flatten)]
    pub cache: CacheArg,
    /// Worker threads (default: all cores; the limit: docs/limits.md).
    #[arg(long, value_parser = crate::common::parse_threads)]
    pub threads: Option<usize>,
}

/// Loads the mesh, the embedding (`.wavg`, or the cache's) and the anchors, each error
/// naming its file and line.
pub fn solver_for(
    mesh: &str,
    embedding: Option<&Path>,
    anchors: &Path,
    cache: CacheArg,
) -> Result<Solver, CliError> {
    let lookup = embedding.is_none() && !cache.no_cache;
    let (valid, list, cached) = mesh_and_anchors_with(mesh, anchors, lookup)?;
    let surface = match cached {
        Some(e) => surface_of(valid, e)?,
        None => embed(valid, embedding, mesh, cache)?,
    };
    let t = std::time::Instant::now();
    let solver = surface.solver(list).map_err(CliError::from);
    crate::common::step("solver", t);
    solver
}

/// The mesh (no embedding yet: see [`embed`]) and the anchors of `anchors`, checked
/// against it, so bad input fails before any precomputation.
pub fn mesh_and_anchors(
    mesh: &str,
    anchors: &Path,
) -> Result<(Arc<ValidMesh>, Vec<Anchor>), CliError> {
    mesh_and_anchors_with(mesh, anchors, false).map(|(m, a, _)| (m, a))
}

/// The mesh, the anchors and the cache's embedding when it was looked up and found.
type MeshAnchorsCached = (Arc<ValidMesh>, Vec<Anchor>, Option<Embedding>);

/// [`mesh_and_anchors`], with `lookup` also the embedding cache's entry for the mesh
/// ([`crate::cache::lookup`]), read on a second thread while the mesh is validated.
fn mesh_and_anchors_with(
    name: &str,
    anchors: &Path,
    lookup: bool,
) -> Result<MeshAnchorsCached, CliError> {
    let t = std::time::Instant::now();
    let raw = load_mesh(name)?;
    crate::common::step("read + parse the mesh", t);
    let (mesh, cached) = if lookup {
        std::thread::scope(|s| {
            let cached = s.spawn(|| crate::cache::lookup(&raw));
            let mesh = validate(name, raw.clone());
            (mesh, cached.join().ok().flatten())
        })
    } else {
        (validate(name, raw), None)
    };
    let mesh = mesh?;
    let list = wavg::anchors::read(anchors, &mesh)?;
    Ok((mesh, list, cached))
}

/// The surface on `mesh` (named `name` in messages) with the embedding of the file
/// `embedding`, or else the embedding cache's (see [`crate::cache::embedding`]: computed on
/// first use).
pub fn embed(
    mesh: Arc<ValidMesh>,
    embedding: Option<&Path>,
    name: &str,
    cache: CacheArg,
) -> Result<Surface, CliError> {
    let e = match embedding {
        Some(path) => wavg::embed::file::load(path, &mesh)?,
        None => crate::cache::embedding(&mesh, name, cache.no_cache)?,
    };
    surface_of(mesh, e)
}

/// The surface on `mesh` with the embedding `e` (its projector built here).
fn surface_of(mesh: Arc<ValidMesh>, e: Embedding) -> Result<Surface, CliError> {
    let t = std::time::Instant::now();
    let s = Surface::from_valid_with_embedding(mesh, e).map_err(CliError::from);
    crate::common::step("projector (embedded mesh, BVH)", t);
    s
}
