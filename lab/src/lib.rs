//! wavg's lab: timing programs and experiments, one binary each in `src/bin/`; run one
//! with `cargo xtask lab NAME ARGS` (see `lab/README.md`). Not published and not a default
//! workspace member; the figures they produce are in `BENCHMARKS.md` and `lab/TRIED.md`.

#![deny(unreachable_pub)]
#![forbid(unsafe_code)]

use std::path::PathBuf;

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
