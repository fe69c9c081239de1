//! The embedding cache every door shares: the command line, Python, the Blender add-on,
//! `wavg.batch` and `wavg serve` read and fill the same entries.
//!
//! An entry is `KEY.wavg` (the `.wavg` file, whose own fingerprint and checksum are checked
//! on every read) and `KEY.json` (its description: [`EntryMeta`]). `KEY` is 16 hex digits
//! of the mesh fingerprint (positions and faces, as in the `.wavg` header), a dash, and 16
//! of a hash of the precomputation options and the algorithm's revision
//! ([`wavg_embed::PRECOMPUTE_REVISION`]), so an edited mesh, other options or another
//! algorithm never hit an old entry. Both files are written to a temporary file and renamed
//! into place, so processes that compute the same entry at once each leave a whole file,
//! and a reader never sees half of one.
//!
//! ```
//! use wavg::cache::{Cache, EntryInfo};
//! let dir = tempfile::tempdir()?;
//! let cache = Cache::new(dir.path());
//! let mesh = wavg::ValidMesh::new(wavg::mesh::procedural::torus(24, 10, 1.0, 0.4))?;
//! let opts = wavg::PrecomputeOptions { landmarks: 40, quality_pairs: 0, ..Default::default() };
//! let info = EntryInfo::new("torus", "doc");
//! let (first, _) = wavg::embedding_cached(&mesh, &opts, Some(&cache), &info, &wavg::NoProgress)?;
//! let (again, how) = wavg::embedding_cached(&mesh, &opts, Some(&cache), &info, &wavg::NoProgress)?;
//! assert!(matches!(how.provenance, wavg::Provenance::Cached(_)));
//! assert_eq!(first.coords, again.coords);
//! assert_eq!(cache.entries()?.len(), 1);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::path::{Path, PathBuf};
use std::time::{SystemTime, UNIX_EPOCH};

use wavg_embed::file::{FNV_OFFSET, fnv1a64, mesh_fingerprint};
use wavg_embed::{EmbedError, Embedding, PrecomputeOptions};
use wavg_mesh::{TriMesh, ValidMesh};

use crate::error::Result;

/// The environment variable that names the cache folder.
pub const CACHE_DIR_VAR: &str = "WAVG_CACHE_DIR";

/// An embedding cache in one folder.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Cache {
    dir: PathBuf,
}

/// What a caller says about an entry it stores: the mesh's name and the door.
#[derive(Clone, Debug)]
pub struct EntryInfo {
    /// The mesh as the caller names it (a path, or how it was made).
    pub mesh: String,
    /// The front end that computed it: `"cli"`, `"python"`, `"blender"`, `"serve"`,
    /// `"batch"`, `"c"`, or a program's own name.
    pub writer: String,
}

impl EntryInfo {
    /// An entry description.
    pub fn new(mesh: impl Into<String>, writer: impl Into<String>) -> Self {
        Self {
            mesh: mesh.into(),
            writer: writer.into(),
        }
    }
}

/// What `KEY.json` holds.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EntryMeta {
    /// The mesh as the first caller that computed the entry named it.
    pub mesh: String,
    /// Vertices of the mesh.
    pub vertices: usize,
    /// Faces of the mesh.
    pub faces: usize,
    /// Landmarks of the embedding.
    pub landmarks: usize,
    /// Seconds the precomputation took.
    pub seconds: f64,
    /// When the entry was written (seconds since 1970).
    pub created: u64,
    /// The front end that wrote it (empty for entries of older versions).
    #[serde(default)]
    pub writer: String,
}

/// One entry of [`Cache::entries`].
#[derive(Clone, Debug)]
pub struct Entry {
    /// The entry's key (its file names without extension).
    pub key: String,
    /// The `.wavg` file.
    pub path: PathBuf,
    /// Size of the `.wavg` file in bytes.
    pub bytes: u64,
    /// Its description, when `KEY.json` is present and readable.
    pub meta: Option<EntryMeta>,
}

impl Cache {
    /// The cache in `dir` (created when the first entry is stored).
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self { dir: dir.into() }
    }

    /// The cache at [`default_dir`], when there is one.
    pub fn from_env() -> Option<Self> {
        default_dir().map(Self::new)
    }

    /// The cache's folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The entry key of `mesh` under `options` (landmarks as given: resolve a 0 first).
    pub fn key(mesh: &TriMesh, options: &PrecomputeOptions) -> String {
        let described = format!("{options:?} r{}", wavg_embed::PRECOMPUTE_REVISION);
        let o = fnv1a64(FNV_OFFSET, described.as_bytes());
        format!("{:016x}-{o:016x}", mesh_fingerprint(mesh))
    }

    /// The `.wavg` file of `key`, whether or not it exists.
    pub fn path_of(&self, key: &str) -> PathBuf {
        self.dir.join(format!("{key}.wavg"))
    }

    /// The entry of `mesh` under `options` when it exists: `None` without one, else the
    /// embedding and its file, or why the file cannot be used (damaged, another format
    /// version). `mesh` need not be validated yet (the file's fingerprint is checked).
    pub fn load(
        &self,
        mesh: &TriMesh,
        options: &PrecomputeOptions,
    ) -> Option<Result<(Embedding, PathBuf)>> {
        let path = self.path_of(&Self::key(mesh, options));
        if !path.exists() {
            return None;
        }
        Some(
            wavg_embed::file::load(&path, mesh)
                .map(|e| (e, path))
                .map_err(Into::into),
        )
    }

    /// Stores `embedding`, computed for `mesh` under `options` in `seconds`, as an entry
    /// (the `.wavg` first, then its description: an entry is listed only once it can be
    /// used); returns the `.wavg` file.
    pub fn store(
        &self,
        mesh: &ValidMesh,
        options: &PrecomputeOptions,
        embedding: &Embedding,
        info: &EntryInfo,
        seconds: f64,
    ) -> Result<PathBuf> {
        let io = |e: std::io::Error| EmbedError::Io {
            path: self.dir.clone(),
            source: e,
        };
        std::fs::create_dir_all(&self.dir).map_err(io)?;
        let key = Self::key(mesh, options);
        let path = self.path_of(&key);
        wavg_embed::file::save(&path, embedding, mesh)?;
        let meta = EntryMeta {
            mesh: info.mesh.clone(),
            vertices: mesh.n_vertices(),
            faces: mesh.n_faces(),
            landmarks: embedding.landmarks.len(),
            seconds,
            created: SystemTime::now()
                .duration_since(UNIX_EPOCH)
                .map_or(0, |d| d.as_secs()),
            writer: info.writer.clone(),
        };
        let json = serde_json::to_vec_pretty(&meta).map_err(|e| io(e.into()))?;
        let json_path = self.dir.join(format!("{key}.json"));
        wavg_mesh::io::write_atomic(&json_path, |w| w.write_all(&json)).map_err(|e| {
            EmbedError::Io {
                path: json_path.clone(),
                source: e,
            }
        })?;
        Ok(path)
    }

    /// The entries, sorted by key (an absent folder has none).
    pub fn entries(&self) -> Result<Vec<Entry>> {
        let io = |e: std::io::Error| EmbedError::Io {
            path: self.dir.clone(),
            source: e,
        };
        let mut out = Vec::new();
        let list = match std::fs::read_dir(&self.dir) {
            Ok(l) => l,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(out),
            Err(e) => return Err(io(e).into()),
        };
        for entry in list {
            let path = entry.map_err(io)?.path();
            let Some(key) = entry_key(&path) else {
                continue;
            };
            let bytes = std::fs::metadata(&path).map_or(0, |m| m.len());
            let meta = std::fs::read(path.with_extension("json"))
                .ok()
                .and_then(|b| serde_json::from_slice(&b).ok());
            out.push(Entry {
                key: key.to_string(),
                path: path.clone(),
                bytes,
                meta,
            });
        }
        out.sort_by(|a, b| a.key.cmp(&b.key));
        Ok(out)
    }

    /// The `.wavg` files in the folder that are not entries (not named `KEY.wavg`): a
    /// user's own files put there, which [`Cache::clear`] keeps. Sorted; an absent folder
    /// has none.
    pub fn others(&self) -> Result<Vec<PathBuf>> {
        let list = match std::fs::read_dir(&self.dir) {
            Ok(l) => l,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
            Err(e) => {
                return Err(EmbedError::Io {
                    path: self.dir.clone(),
                    source: e,
                }
                .into());
            }
        };
        let mut out: Vec<PathBuf> = list
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|x| x == "wavg") && entry_key(p).is_none())
            .collect();
        out.sort();
        Ok(out)
    }

    /// Removes every entry (the files the cache named, `KEY.wavg` and `KEY.json`; other
    /// files in the folder are kept: [`Cache::others`]); returns how many and their
    /// `.wavg` bytes.
    pub fn clear(&self) -> Result<(usize, u64)> {
        let entries = self.entries()?;
        let mut freed = 0;
        for e in &entries {
            for ext in ["wavg", "json"] {
                let p = self.dir.join(format!("{}.{ext}", e.key));
                match std::fs::remove_file(&p) {
                    Ok(()) => {}
                    Err(err) if err.kind() == std::io::ErrorKind::NotFound => {}
                    Err(err) => {
                        return Err(EmbedError::Io {
                            path: p,
                            source: err,
                        }
                        .into());
                    }
                }
            }
            freed += e.bytes;
        }
        Ok((entries.len(), freed))
    }
}

/// The key of an entry's `.wavg` file: its name is `KEY.wavg` with `KEY` as
/// [`Cache::key`] makes it (16 lowercase hex digits, a dash, 16 more); `None` for any
/// other file.
fn entry_key(path: &Path) -> Option<&str> {
    let name = path.file_name()?.to_str()?;
    let key = name.strip_suffix(".wavg")?;
    let hex = |s: &str| s.len() == 16 && s.bytes().all(|b| matches!(b, b'0'..=b'9' | b'a'..=b'f'));
    let (mesh, options) = key.split_once('-')?;
    (hex(mesh) && hex(options)).then_some(key)
}

/// The cache folder: `$WAVG_CACHE_DIR` when set, else the platform's user cache folder
/// (`$XDG_CACHE_HOME/wavg` or `~/.cache/wavg` on Linux and other Unix systems,
/// `~/Library/Caches/wavg` on macOS, `%LOCALAPPDATA%\wavg\cache` on Windows); `None` when
/// none of them can be found.
pub fn default_dir() -> Option<PathBuf> {
    let var = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    if let Some(d) = var(CACHE_DIR_VAR) {
        return Some(d);
    }
    if cfg!(windows) {
        return var("LOCALAPPDATA").map(|d| d.join("wavg").join("cache"));
    }
    if cfg!(target_os = "macos") {
        return var("HOME").map(|d| d.join("Library").join("Caches").join("wavg"));
    }
    var("XDG_CACHE_HOME")
        .map(|d| d.join("wavg"))
        .or_else(|| var("HOME").map(|d| d.join(".cache").join("wavg")))
}
