//! The command line's side of the embedding cache (`wavg::cache`): the `--no-cache` flag,
//! progress bars while an entry is computed, and the lines on stderr that say what
//! happened. Every command that needs an embedding and is not given one uses the
//! library's default options for the mesh (`wavg::default_precompute_options`), so it
//! reads the same entry Python, Blender, `wavg.batch` and `wavg serve` write.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use wavg::cache::{Cache, EntryInfo};
use wavg::{Embedding, Provenance, TriMesh, ValidMesh};

use crate::CliError;
use crate::error::Context;
use crate::precompute::Bars;

/// The door's name in the entries it writes.
pub const WRITER: &str = "cli";

/// The `--no-cache` flag of the commands that use the cache.
#[derive(clap::Args, Clone, Copy, Debug, Default)]
pub struct CacheArg {
    /// Neither read nor write the embedding cache ($WAVG_CACHE_DIR, default
    /// ~/.cache/wavg): compute the embedding in memory.
    #[arg(long)]
    pub no_cache: bool,
}

/// The cache unless `no_cache` (or when no folder can be found).
pub fn open(no_cache: bool) -> Option<Cache> {
    if no_cache { None } else { Cache::from_env() }
}

/// The embedding of `mesh` (named `name` in messages) with the default options: from the
/// cache when an entry exists, else computed (progress bars on a terminal) and stored, with
/// one line on stderr saying where. With `no_cache`, or without a cache folder, it is
/// computed in memory only. A cache entry that cannot be read is computed again and
/// replaced; a cache that cannot be written is a warning, not a failure.
pub fn embedding(mesh: &ValidMesh, name: &str, no_cache: bool) -> Result<Embedding, CliError> {
    let cache = open(no_cache);
    let bars = Bars::new(
        std::io::stderr().is_terminal(),
        Arc::new(AtomicBool::new(false)),
    );
    let t = Instant::now();
    let opts = wavg::default_precompute_options(mesh);
    let r = crate::textio::with_threads(None, || {
        wavg::embedding_cached(
            mesh,
            &opts,
            cache.as_ref(),
            &EntryInfo::new(name, WRITER),
            &bars,
        )
    })?;
    bars.clear();
    let (emb, outcome) = r.context(name)?;
    if let Some(e) = &outcome.unusable_entry {
        eprintln!(
            "wavg: a cached embedding of {name} cannot be used ({}); it was computed again",
            e.message()
        );
    }
    match &outcome.provenance {
        Provenance::Cached(_) => {
            crate::common::step("cache key + load the .wavg (checksum, fingerprint)", t);
        }
        Provenance::Computed { report, stored } => {
            report_stored(name, emb.landmarks.len(), report.seconds, stored.as_ref())
        }
    }
    Ok(emb)
}

/// Says on stderr where a computed embedding was cached, or why it was not.
pub fn report_stored(
    name: &str,
    landmarks: usize,
    seconds: f64,
    stored: Option<&Result<PathBuf, wavg::Error>>,
) {
    match stored {
        Some(Ok(path)) => eprintln!(
            "wavg: embedding of {name} ({landmarks} landmarks, {seconds:.1} s) cached in {}; \
             later runs on this mesh reuse it",
            path.display()
        ),
        Some(Err(e)) => eprintln!(
            "wavg: warning: the embedding could not be cached ({}); set WAVG_CACHE_DIR to a \
             writable folder or pass --no-cache",
            e.message()
        ),
        None => {}
    }
}

/// The cache's embedding of `mesh` (read, not yet validated: it runs beside validation)
/// with the default options, when an entry exists and loads; `None` otherwise (then
/// [`embedding`] says why and computes it).
pub fn lookup(mesh: &TriMesh) -> Option<Embedding> {
    let t = Instant::now();
    let e = Cache::from_env()?
        .load(mesh, &wavg::default_precompute_options(mesh))?
        .ok()
        .map(|(e, _)| e);
    crate::common::step("cache key + load the .wavg (beside validation)", t);
    e
}

/// The cache entry of `mesh` under the default options when it exists (and `no_cache` is
/// false), for commands that load it themselves.
pub fn existing(mesh: &ValidMesh, no_cache: bool) -> Option<PathBuf> {
    let cache = open(no_cache)?;
    let path = cache.path_of(&Cache::key(mesh, &wavg::default_precompute_options(mesh)));
    path.exists().then_some(path)
}
