//! Python's side of the embedding cache (`wavg::cache`): the `cache=` argument of
//! `Surface.precompute` and `Surface.load_cached`, the report of where an embedding came
//! from, and the module functions `cache_dir()` and `cache_entries()`.

use std::path::PathBuf;

use pyo3::prelude::*;
use wavg::cache::Cache;
use wavg::{CacheOutcome, EmbeddingSummary, Provenance};

use crate::errors::{lib, value};

/// The door's name in the entries it writes.
pub(crate) const WRITER: &str = "python";

/// The cache a `cache=` argument names: `None` (the default) the user cache for a surface
/// read from a file (`auto`) and none otherwise, `True` the user cache, `False` none, a
/// path that folder.
pub(crate) fn resolve(cache: Option<&Bound<'_, PyAny>>, auto: bool) -> PyResult<Option<Cache>> {
    let Some(c) = cache.filter(|c| !c.is_none()) else {
        return Ok(if auto { Cache::from_env() } else { None });
    };
    if let Ok(on) = c.extract::<bool>() {
        return Ok(if on { Cache::from_env() } else { None });
    }
    let path: PathBuf = c.extract().map_err(|_| {
        value(format!(
            "cache must be None, True, False or a folder path; got {}",
            c.get_type()
                .name()
                .map_or_else(|_| "?".into(), |n| n.to_string())
        ))
    })?;
    Ok(Some(Cache::new(path)))
}

/// The report `Surface.precompute` returns: the precomputation's (the keys of `wavg
/// precompute --json`) when it ran, else what the cached embedding says of itself; both
/// with `cached` (bool) and `cache_path` (the entry, or None). Warns (`UserWarning`) when an
/// entry could not be used or written. `embedding` is the surface's summary, not its
/// embedding: a cache hit is reported without copying the coordinates.
pub(crate) fn report(
    py: Python<'_>,
    outcome: &CacheOutcome,
    embedding: Option<EmbeddingSummary>,
    n: (usize, usize),
) -> PyResult<Py<PyAny>> {
    let warn = |msg: String| -> PyResult<()> {
        py.import("warnings")?.call_method1("warn", (msg,))?;
        Ok(())
    };
    if let Some(e) = &outcome.unusable_entry {
        warn(format!(
            "a cached embedding could not be used ({}); it was computed again",
            e.message()
        ))?;
    }
    let (mut v, cached, path) = match &outcome.provenance {
        Provenance::Computed { report, stored } => {
            let v = serde_json::to_value(report.as_ref()).map_err(|e| value(e.to_string()))?;
            let path = match stored {
                Some(Ok(p)) => Some(p.clone()),
                Some(Err(e)) => {
                    warn(format!(
                        "the embedding could not be cached ({}); set WAVG_CACHE_DIR to a \
                         writable folder or pass cache=False",
                        e.message()
                    ))?;
                    None
                }
                None => None,
            };
            (v, false, path)
        }
        Provenance::Cached(p) => {
            let e = embedding.ok_or_else(|| value("no embedding"))?;
            let mut v = serde_json::to_value(e).map_err(|e| value(e.to_string()))?;
            v["vertices"] = n.0.into();
            v["faces"] = n.1.into();
            (v, true, Some(p.clone()))
        }
    };
    v["cached"] = cached.into();
    v["cache_path"] = path.map(|p| p.display().to_string()).into();
    crate::json::to_py(py, &v)
}

/// wavg.cache_dir() -> str | None: the folder of the embedding cache every way into wavg
/// shares (``$WAVG_CACHE_DIR``, else the platform's user cache folder), or None when none
/// can be found.
#[pyfunction]
pub(crate) fn cache_dir() -> Option<String> {
    wavg::cache::default_dir().map(|d| d.display().to_string())
}

/// wavg.cache_entries(folder=None) -> list[dict]: the entries of the embedding cache
/// (``folder``, default :func:`cache_dir`), as ``wavg cache list --json`` lists them: key,
/// bytes, path, mesh, vertices, faces, landmarks, seconds, created, writer (None where the
/// entry's description is missing).
#[pyfunction]
#[pyo3(signature = (folder=None))]
pub(crate) fn cache_entries(py: Python<'_>, folder: Option<PathBuf>) -> PyResult<Py<PyAny>> {
    let Some(cache) = folder.map(Cache::new).or_else(Cache::from_env) else {
        return crate::json::to_py(py, &Vec::<serde_json::Value>::new());
    };
    let list = cache.entries().map_err(lib(py))?;
    let rows: Vec<serde_json::Value> = list
        .iter()
        .map(|e| {
            let mut v = e.meta.as_ref().map_or_else(
                || {
                    serde_json::json!({
                        "mesh": null, "vertices": null, "faces": null, "landmarks": null,
                        "seconds": null, "created": null, "writer": null,
                    })
                },
                |m| serde_json::to_value(m).unwrap_or_default(),
            );
            v["key"] = e.key.clone().into();
            v["bytes"] = e.bytes.into();
            v["path"] = e.path.display().to_string().into();
            v
        })
        .collect();
    crate::json::to_py(py, &rows)
}
