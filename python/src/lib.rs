//! The `wavg._wavg` Python extension module: the facade `wavg` for NumPy arrays. The
//! Python package `wavg` (in `python/wavg`) re-exports it with the pure-Python parts
//! (exceptions, named tuples, the progress bar).
//!
//! Every call that loops over arrays releases the GIL and runs on the library's own
//! thread pools (in a process forked after the import, on a pool of its own: see
//! `pool`); arguments are checked before any work, and a query without an answer is a row
//! of the `ok`/`valid` mask, never an exception. `__version__` is the crate's version.

#![forbid(unsafe_code)]

mod anchors;
mod apps;
mod args;
mod arrays;
mod cache;
mod errors;
mod image;
mod json;
mod pool;
mod progress;
mod remesh;
mod render;
mod solver;
mod surface;

use std::path::PathBuf;

use pyo3::prelude::*;

use crate::pool::DetachRun;

/// read_mesh(path) -> (V (n, 3) float64, F (m, 3) int64)
///
/// Reads a mesh file (.obj, .off, .ply, optionally gzipped as .gz; .gltf or .glb, welded
/// into one surface, ``scene.glb#Name`` for one of its meshes) or a builtin mesh
/// (``builtin:torus``, as the command line takes them): vertex positions and 0-based
/// triangles (polygons are triangulated). The mesh is not validated.
#[pyfunction]
fn read_mesh<'py>(
    py: Python<'py>,
    path: PathBuf,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    errors::require_mesh_file(&path)?;
    let mesh = py
        .detach_run(|| wavg::load_mesh(&path))
        .map_err(errors::lib(py))?;
    arrays::mesh_arrays(py, &mesh)
}

/// write_mesh(path, V, F, uv=None)
///
/// Writes a mesh file in the format its extension names: .obj, .off, .ply (optionally
/// gzipped as .gz), .glb or .gltf (with its buffer in a .bin of the same stem beside it).
/// V (n, 3) float positions, F (m, 3) 0-based triangles, uv optional per-corner texture
/// coordinates (m, 3, 2). The file is written atomically (nothing half-written). glTF
/// stores 32-bit floats and splits a vertex where its corners' texture coordinates differ.
#[pyfunction]
#[pyo3(signature = (path, V, F, uv=None))]
#[allow(non_snake_case)]
fn write_mesh(
    py: Python<'_>,
    path: PathBuf,
    V: &Bound<'_, PyAny>,
    F: &Bound<'_, PyAny>,
    uv: Option<&Bound<'_, PyAny>>,
) -> PyResult<()> {
    let mesh = arrays::mesh_from(V, F, uv, "V", "F")?;
    py.detach_run(|| wavg::mesh::io::save(&path, &mesh))
        .map_err(errors::lib(py))
}

/// The module.
#[pymodule]
fn _wavg(m: &Bound<'_, PyModule>) -> PyResult<()> {
    pool::remember_pid();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<surface::Surface>()?;
    m.add_class::<solver::Solver>()?;
    m.add_function(wrap_pyfunction!(read_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(write_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(anchors::read_anchors, m)?)?;
    m.add_function(wrap_pyfunction!(anchors::write_anchors, m)?)?;
    m.add_function(wrap_pyfunction!(cache::cache_dir, m)?)?;
    m.add_function(wrap_pyfunction!(cache::cache_entries, m)?)?;
    m.add_function(wrap_pyfunction!(surface::_restore_surface, m)?)?;
    m.add_function(wrap_pyfunction!(solver::_restore_solver, m)?)?;
    apps::register(m)?;
    Ok(())
}
