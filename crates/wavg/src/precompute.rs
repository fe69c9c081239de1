//! The precomputation as every door runs it: the options chosen for a mesh when the caller
//! gives none, the checks a mesh must pass first, and the embedding cache in between.

use std::time::Instant;

use wavg_embed::{Embedding, PrecomputeOptions, Progress, Report};
use wavg_mesh::{TriMesh, ValidMesh};

use crate::cache::{Cache, EntryInfo};
use crate::error::{Error, Result};

/// The landmark count the paper uses; meshes with fewer vertices use all of them.
pub const DEFAULT_LANDMARKS: usize = 1000;

/// The precomputation options wavg uses for `mesh` when the caller chooses none: the
/// paper's [`DEFAULT_LANDMARKS`] landmarks (every vertex of a smaller mesh) and the
/// quality check on. Every front end that precomputes without explicit options (`wavg
/// precompute`, the embedding cache of the other commands, `wavg serve`, Python's
/// `Surface.precompute()`, the C ABI's `landmarks = 0`, Blender, `wavg.batch`) calls this,
/// so one mesh gets one embedding whichever door it comes through.
///
/// ```
/// let mesh = wavg::mesh::procedural::icosphere(2);
/// let opts = wavg::default_precompute_options(&mesh);
/// assert_eq!(opts.landmarks, wavg::DEFAULT_LANDMARKS);
/// assert!(opts.quality_pairs > 0);
/// ```
pub fn default_precompute_options(mesh: &TriMesh) -> PrecomputeOptions {
    // The mesh is an argument so that the choice may follow its size; today the paper's
    // settings serve every size (the pipeline scales its own stages with the mesh).
    let _ = mesh;
    PrecomputeOptions {
        landmarks: DEFAULT_LANDMARKS,
        ..PrecomputeOptions::default()
    }
}

/// `options` with a landmark count of 0 replaced by the choice for `mesh`
/// ([`default_precompute_options`]'s): how front ends that take a count spell "choose".
pub fn resolve_landmarks(options: &PrecomputeOptions, mesh: &TriMesh) -> PrecomputeOptions {
    let mut o = options.clone();
    if o.landmarks == 0 {
        o.landmarks = default_precompute_options(mesh).landmarks;
    }
    o
}

/// Why a mesh cannot be embedded, if it cannot: the checks every door runs before the
/// precomputation (one connected component, at least 4 vertices, coordinates in range).
pub fn check_embeddable(mesh: &ValidMesh) -> Result<()> {
    let components = mesh.topology().n_components();
    if components != 1 {
        return Err(Error::Unsuitable(format!(
            "the mesh has {components} connected components; the embedding needs exactly \
             one (keep the largest with `wavg repair --largest-component`)"
        )));
    }
    let n = mesh.n_vertices();
    if n < 4 {
        return Err(Error::Unsuitable(format!(
            "the mesh has {n} vertices; the embedding needs at least 4"
        )));
    }
    if let Some(why) = wavg_mesh::coordinates_out_of_range(mesh) {
        return Err(Error::Unsuitable(why));
    }
    Ok(())
}

/// Computes the 8-D embedding of `mesh` (landmarks, geodesics, MDS, least-squares mesh)
/// after [`check_embeddable`] and a check that the machine has the memory it needs
/// ([`crate::precompute_peak_bytes`] against [`crate::available_memory`]: else
/// [`crate::ErrorKind::OutOfMemory`], before any work; a malformed
/// `WAVG_MEMORY_AVAILABLE` is [`crate::ErrorKind::InvalidArgument`]); `progress` receives per-stage fractions and can cancel
/// ([`crate::ErrorKind::Cancelled`]). A landmark count of 0 means "choose"
/// ([`resolve_landmarks`]).
pub fn precompute(
    mesh: &ValidMesh,
    options: &PrecomputeOptions,
    progress: &dyn Progress,
) -> Result<(Embedding, Report)> {
    check_embeddable(mesh)?;
    let options = resolve_landmarks(options, mesh);
    crate::memory::check_fits(
        mesh.n_vertices(),
        options.landmarks,
        crate::memory::available_memory()?,
    )?;
    Ok(wavg_embed::precompute(mesh, &options, progress)?)
}

/// Where an embedding of [`embedding_cached`] came from: the cache or the computation.
#[derive(Debug)]
pub enum Provenance {
    /// Read from this cache entry.
    Cached(std::path::PathBuf),
    /// Computed now, with the precomputation's report and what became of storing it.
    Computed {
        /// The precomputation's report.
        report: Box<Report>,
        /// The entry it was stored as; an error (for a warning: the embedding is fine)
        /// when the cache could not be written; `None` without a cache.
        stored: Option<Result<std::path::PathBuf>>,
    },
}

/// Where an embedding came from, and what to warn about.
#[derive(Debug)]
pub struct CacheOutcome {
    /// From the cache, or computed (and stored).
    pub provenance: Provenance,
    /// Why a cache entry that existed could not be used (it was computed again and
    /// replaced), for a warning.
    pub unusable_entry: Option<Error>,
}

/// The embedding of `mesh` under `options` (landmarks 0: chosen), and where it came from: read from `cache` when
/// it holds an entry for this mesh and these options, else computed ([`precompute`]) and
/// stored there. `source` names the mesh in the entry's description (a path, or how the
/// caller made it) and `writer` the door (`"cli"`, `"python"`, ...). Without a cache it is
/// computed in memory only. An entry that cannot be read is computed again and replaced; a
/// cache that cannot be written is reported in the result, not as a failure.
pub fn embedding_cached(
    mesh: &ValidMesh,
    options: &PrecomputeOptions,
    cache: Option<&Cache>,
    info: &EntryInfo,
    progress: &dyn Progress,
) -> Result<(Embedding, CacheOutcome)> {
    let options = resolve_landmarks(options, mesh);
    let mut unusable_entry = None;
    if let Some(cache) = cache {
        match cache.load(mesh, &options) {
            Some(Ok((embedding, path))) => {
                let outcome = CacheOutcome {
                    provenance: Provenance::Cached(path),
                    unusable_entry: None,
                };
                return Ok((embedding, outcome));
            }
            Some(Err(e)) => unusable_entry = Some(e),
            None => {}
        }
    }
    let t = Instant::now();
    let (embedding, report) = precompute(mesh, &options, progress)?;
    let seconds = t.elapsed().as_secs_f64();
    let stored = cache.map(|c| c.store(mesh, &options, &embedding, info, seconds));
    let outcome = CacheOutcome {
        provenance: Provenance::Computed {
            report: Box::new(report),
            stored,
        },
        unusable_entry,
    };
    Ok((embedding, outcome))
}
