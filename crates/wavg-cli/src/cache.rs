//! The embedding cache: every command that needs an embedding and is not given one reads
//! it from `$WAVG_CACHE_DIR` (default `$XDG_CACHE_HOME/wavg`, else `~/.cache/wavg`), or
//! computes it once and stores it there.
//!
//! An entry is `KEY.wavg` (the `.wavg` file, whose own fingerprint and checksum are checked
//! on every read) and `KEY.json` (what `wavg cache list` shows). `KEY` is the mesh
//! fingerprint (positions and faces, as in the `.wavg` header) and a hash of the
//! precompute options, so an edited mesh or other options never hit an old entry. Both
//! files are written to a temporary file and renamed into place, so processes that compute
//! the same entry at once each leave a whole file, and a reader never sees half of one.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::{Instant, SystemTime, UNIX_EPOCH};

use wavg::embed::file::{FNV_OFFSET, fnv1a64, mesh_hash};
use wavg::{Embedding, PrecomputeOptions, TriMesh, ValidMesh};

use crate::CliError;
use crate::error::Context;
use crate::precompute::Bars;

/// The `--no-cache` flag of the commands that use the cache.
#[derive(clap::Args, Clone, Copy, Debug, Default)]
pub struct CacheArg {
    /// Neither read nor write the embedding cache ($WAVG_CACHE_DIR, default
    /// ~/.cache/wavg): compute the embedding in memory.
    #[arg(long)]
    pub no_cache: bool,
}

/// The cache folder: `$WAVG_CACHE_DIR`, else `$XDG_CACHE_HOME/wavg`, else
/// `$HOME/.cache/wavg`; `None` when none of them is set.
pub fn dir() -> Option<PathBuf> {
    let var = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    var("WAVG_CACHE_DIR")
        .or_else(|| var("XDG_CACHE_HOME").map(|d| d.join("wavg")))
        .or_else(|| var("HOME").map(|d| d.join(".cache").join("wavg")))
}

/// The options of the embedding a command computes when it is given none: a tenth of the
/// vertices as landmarks (50 to 1000), no quality check.
pub fn default_options(n_vertices: usize) -> PrecomputeOptions {
    PrecomputeOptions {
        landmarks: (n_vertices / 10).clamp(50, 1000),
        quality_pairs: 0,
        ..Default::default()
    }
}

/// The entry name of `mesh` under `opts`: 16 hex digits of the mesh fingerprint, a dash,
/// 16 of the options' hash.
pub fn key(mesh: &TriMesh, opts: &PrecomputeOptions) -> String {
    let o = fnv1a64(FNV_OFFSET, format!("{opts:?}").as_bytes());
    format!("{:016x}-{o:016x}", mesh_hash(mesh))
}

/// What `KEY.json` holds.
#[derive(serde::Serialize, serde::Deserialize)]
pub struct Meta {
    /// The mesh as the first command that computed the entry named it.
    pub mesh: String,
    /// Vertices and faces of the mesh.
    pub vertices: usize,
    pub faces: usize,
    /// Landmarks of the embedding.
    pub landmarks: usize,
    /// Seconds the precomputation took.
    pub seconds: f64,
    /// When the entry was written (seconds since 1970).
    pub created: u64,
}

/// The embedding of `mesh` (named `name` in messages) with [`default_options`]: from the
/// cache when an entry exists, else computed (progress bars on a terminal) and stored, with
/// one line on stderr saying where. With `no_cache`, or without a cache folder, it is
/// computed in memory only. A cache entry that cannot be read is computed again and
/// replaced; a cache that cannot be written is a warning, not a failure.
pub fn embedding(mesh: &ValidMesh, name: &str, no_cache: bool) -> Result<Embedding, CliError> {
    let opts = default_options(mesh.n_vertices());
    let folder = if no_cache { None } else { dir() };
    let Some(folder) = folder else {
        return compute(mesh, name, &opts).map(|(e, _)| e);
    };
    let t = Instant::now();
    let key = key(mesh, &opts);
    let t = crate::common::step("cache key (mesh fingerprint)", t);
    let path = folder.join(format!("{key}.wavg"));
    if path.exists() {
        match wavg::embed::file::load(&path, mesh) {
            Ok(e) => {
                crate::common::step("load the .wavg (checksum, fingerprint)", t);
                return Ok(e);
            }
            Err(e) => eprintln!(
                "wavg: the cached embedding {} cannot be used ({}); computing it again",
                path.display(),
                wavg::Error::from(e).message()
            ),
        }
    }
    let (emb, seconds) = compute(mesh, name, &opts)?;
    match store(&folder, &key, &emb, mesh, name, seconds) {
        Ok(()) => eprintln!(
            "wavg: embedding of {name} ({} landmarks, {seconds:.1} s) cached in {}; later \
             runs on this mesh reuse it",
            emb.landmarks.len(),
            path.display()
        ),
        Err(e) => eprintln!(
            "wavg: warning: the embedding could not be cached in {} ({e}); set \
             WAVG_CACHE_DIR to a writable folder or pass --no-cache",
            folder.display()
        ),
    }
    Ok(emb)
}

/// The cache's embedding of `mesh` (read, not yet validated: it runs beside validation)
/// with [`default_options`], when an entry exists and loads; `None` otherwise (then
/// [`embedding`] says why and computes it).
pub fn lookup(mesh: &TriMesh) -> Option<Embedding> {
    let t = Instant::now();
    let path = dir()?.join(format!(
        "{}.wavg",
        key(mesh, &default_options(mesh.n_vertices()))
    ));
    let e = wavg::embed::file::load(&path, mesh).ok();
    crate::common::step("cache key + load the .wavg (beside validation)", t);
    e
}

/// The cache entry of `mesh` under [`default_options`] when it exists (and `no_cache` is
/// false), for commands that load it themselves.
pub fn existing(mesh: &ValidMesh, no_cache: bool) -> Option<PathBuf> {
    let folder = if no_cache { None } else { dir() }?;
    let path = folder.join(format!(
        "{}.wavg",
        key(mesh, &default_options(mesh.n_vertices()))
    ));
    path.exists().then_some(path)
}

/// Stores `emb`, computed with [`default_options`] in `seconds` by a command that
/// precomputes itself, as the cache entry of `mesh` (nothing with `no_cache` or without a
/// cache folder); one line on stderr says where, or why not (a warning, not a failure).
pub fn store_computed(mesh: &ValidMesh, name: &str, emb: &Embedding, seconds: f64, no_cache: bool) {
    let Some(folder) = (if no_cache { None } else { dir() }) else {
        return;
    };
    let key = key(mesh, &default_options(mesh.n_vertices()));
    match store(&folder, &key, emb, mesh, name, seconds) {
        Ok(()) => eprintln!(
            "wavg: embedding of {name} cached in {}; later runs on this mesh reuse it",
            folder.join(format!("{key}.wavg")).display()
        ),
        Err(e) => eprintln!(
            "wavg: warning: the embedding could not be cached in {} ({e})",
            folder.display()
        ),
    }
}

/// Precomputes with progress bars on stderr when it is a terminal; returns the seconds.
fn compute(
    mesh: &ValidMesh,
    name: &str,
    opts: &PrecomputeOptions,
) -> Result<(Embedding, f64), CliError> {
    let bars = Bars::new(
        std::io::stderr().is_terminal(),
        Arc::new(AtomicBool::new(false)),
    );
    let t = Instant::now();
    let r = crate::textio::with_threads(None, || wavg::embed::precompute(mesh, opts, &bars))?;
    bars.clear();
    let (emb, _) = r.context(name)?;
    Ok((emb, t.elapsed().as_secs_f64()))
}

/// Writes `KEY.wavg` and `KEY.json` atomically (the `.wavg` first: an entry is listed
/// only once it can be used).
fn store(
    folder: &Path,
    key: &str,
    emb: &Embedding,
    mesh: &ValidMesh,
    name: &str,
    seconds: f64,
) -> Result<(), String> {
    std::fs::create_dir_all(folder).map_err(|e| e.to_string())?;
    wavg::embed::file::save(&folder.join(format!("{key}.wavg")), emb, mesh)
        .map_err(|e| wavg::Error::from(e).message())?;
    let meta = Meta {
        mesh: name.to_string(),
        vertices: mesh.n_vertices(),
        faces: mesh.n_faces(),
        landmarks: emb.landmarks.len(),
        seconds,
        created: SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map_or(0, |d| d.as_secs()),
    };
    let json = serde_json::to_vec_pretty(&meta).map_err(|e| e.to_string())?;
    wavg::mesh::io::write_atomic(&folder.join(format!("{key}.json")), |w| w.write_all(&json))
        .map_err(|e| e.to_string())
}

/// The entries of `folder`: (key, size of the `.wavg` in bytes, its metadata when
/// readable), sorted by key.
pub fn entries(folder: &Path) -> std::io::Result<Vec<(String, u64, Option<Meta>)>> {
    let mut out = Vec::new();
    let list = match std::fs::read_dir(folder) {
        Ok(l) => l,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(out),
        Err(e) => return Err(e),
    };
    for entry in list {
        let path = entry?.path();
        if path.extension().is_none_or(|x| x != "wavg") {
            continue;
        }
        let Some(key) = path.file_stem().and_then(|s| s.to_str()) else {
            continue;
        };
        let size = std::fs::metadata(&path).map_or(0, |m| m.len());
        let meta = std::fs::read(path.with_extension("json"))
            .ok()
            .and_then(|b| serde_json::from_slice(&b).ok());
        out.push((key.to_string(), size, meta));
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn key_follows_the_mesh_and_the_options() {
        let a = ValidMesh::new(wavg::mesh::procedural::icosphere(1)).unwrap();
        let mut moved = wavg::mesh::procedural::icosphere(1);
        moved.positions[3].x += 1e-9;
        let b = ValidMesh::new(moved).unwrap();
        let o = default_options(a.n_vertices());
        let other = PrecomputeOptions {
            seed: 7,
            ..o.clone()
        };
        assert_eq!(key(&a, &o), key(&a, &o.clone()));
        assert_ne!(key(&a, &o), key(&b, &o));
        assert_ne!(key(&a, &o), key(&a, &other));
        assert_eq!(key(&a, &o).len(), 33);
    }
}
