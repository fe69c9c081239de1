//! wavg's lab: timing programs and experiments, one binary each in `src/bin/`; run one
//! with `cargo xtask lab NAME ARGS` (see `lab/README.md`). Not published and not a default
//! workspace member; the figures they produce are in `BENCHMARKS.md` and `lab/TRIED.md`.

#![deny(unreachable_pub)]
#![forbid(unsafe_code)]

use std::path::{Path, PathBuf};
use std::sync::Arc;

use wavg_mesh::ValidMesh;
use wavg_solve::{EmbeddedMesh, Projector, Vec8};

/// The meshes a script runs on: the paths in `args` or, without any, `defaults` in the
/// shared data folder's `meshes/` (`None`, with a message, when that folder is missing).
pub fn mesh_paths(args: &[String], defaults: &[&str], script: &str) -> Option<Vec<PathBuf>> {
    if !args.is_empty() {
        return Some(args.iter().map(PathBuf::from).collect());
    }
    let dir = wavg_testdata::require_data_dir(script)?;
    Some(
        defaults
            .iter()
            .map(|m| dir.join("meshes").join(m))
            .collect(),
    )
}

/// The mesh `spec` names (a file or `builtin:NAME`) and the projector over its embedding
/// read from `embedding` (a `.wavg` of that mesh): the set-up of the programs that time
/// the solvers on a stored embedding. Panics with the reason on any failure.
pub fn mesh_and_projector(spec: &str, embedding: &str) -> (Arc<ValidMesh>, Arc<Projector>) {
    let mesh = match spec.strip_prefix("builtin:") {
        Some(name) => wavg_mesh::procedural::builtin(name).unwrap_or_else(|e| panic!("{e}")),
        None => wavg_mesh::io::load(Path::new(spec)).unwrap_or_else(|e| panic!("{spec}: {e}")),
    };
    let mesh = Arc::new(ValidMesh::new(mesh).unwrap_or_else(|e| panic!("{spec}: {e}")));
    let e = wavg_embed::file::load(Path::new(embedding), &mesh)
        .unwrap_or_else(|e| panic!("{embedding}: {e}"));
    let coords = e.coords.iter().map(|c| Vec8::from(*c)).collect();
    let emb = EmbeddedMesh::new(mesh.clone(), coords).unwrap_or_else(|e| panic!("{e}"));
    let proj = Projector::new(Arc::new(emb)).unwrap_or_else(|e| panic!("{e}"));
    (mesh, Arc::new(proj))
}
