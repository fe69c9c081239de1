//! `wavg.read_anchors` and `wavg.write_anchors`: anchors files (`wavg::anchors`, the files
//! `wavg anchors` writes and every command reads) in the forms `wavg.Solver` takes.

use std::path::PathBuf;

use pyo3::prelude::*;
use wavg::Anchor;

use crate::args::array;
use crate::errors::{require_file, to_py};
use crate::pool::DetachRun;
use crate::solver::anchors_within;
use crate::surface::Surface;

/// Indices in a file fit in 32 bits.
const INDEX_BOUND: usize = 1 << 32;

/// read_anchors(path, surface) -> (k,) int64 | (faces (k,) int64, bary (k, 3) float64)
///
/// Reads an anchors file (one ``v VERTEX`` or ``f FACE B0 B1 B2`` per line, 0-based,
/// ``#`` comments; what ``wavg anchors`` writes) and checks it against ``surface``. Returns
/// the anchors as ``wavg.Solver`` takes them: vertex ids when every line is a vertex, else
/// surface points (a vertex as a face of it and its corner's barycentrics). A malformed
/// line, an index out of range, bad barycentrics or a file without anchors raise
/// ``InvalidArgumentError`` (a ``ValueError``) whose message starts ``FILE:LINE:``; a
/// missing file ``FileNotFoundError``, an unreadable one ``WavgIOError``.
#[pyfunction]
pub(crate) fn read_anchors(
    py: Python<'_>,
    path: PathBuf,
    surface: PyRef<'_, Surface>,
) -> PyResult<Py<PyAny>> {
    require_file(&path)?;
    let s = &surface.inner;
    let anchors = py
        .detach_run(|| wavg::anchors::read(&path, s.mesh()))
        .map_err(|e| to_py(py, e))?;
    let k = anchors.len();
    let ids: Option<Vec<i64>> = anchors
        .iter()
        .map(|a| match a {
            Anchor::Vertex(v) => Some(i64::from(*v)),
            Anchor::Point(_) => None,
        })
        .collect();
    if let Some(ids) = ids {
        return Ok(array(py, ids, &[k])?.unbind());
    }
    let mut faces = Vec::with_capacity(k);
    let mut bary = Vec::with_capacity(3 * k);
    for a in &anchors {
        let p = match a {
            Anchor::Vertex(v) => s.vertex_point(*v).map_err(|e| to_py(py, e))?,
            Anchor::Point(p) => *p,
        };
        faces.push(i64::from(p.face));
        bary.extend(p.bary);
    }
    let pair = (array(py, faces, &[k])?, array(py, bary, &[k, 3])?);
    Ok(pair.into_pyobject(py)?.into_any().unbind())
}

/// write_anchors(path, anchors) -> None
///
/// Writes an anchors file atomically (the format :func:`read_anchors` and ``wavg``'s
/// commands read): ``anchors`` as ``wavg.Solver`` takes them, ``(k,)`` integer vertex ids
/// (``v`` lines) or a pair ``(faces (k,), bary (k, 3))`` (``f`` lines, numbers in their
/// shortest round-trip form). Bad arguments raise ``ValueError`` or ``TypeError`` naming
/// them; a failed write ``WavgIOError``, leaving nothing at ``path``.
#[pyfunction]
pub(crate) fn write_anchors(
    py: Python<'_>,
    path: PathBuf,
    anchors: &Bound<'_, PyAny>,
) -> PyResult<()> {
    let a = anchors_within(anchors, "anchors", INDEX_BOUND, INDEX_BOUND)?;
    py.detach_run(|| wavg::anchors::write(&path, &a))
        .map_err(|e| to_py(py, e))
}
