//! Meshes between NumPy arrays and the library: `(V, F, uv)` in, `(V, F)` out, and the
//! embedding's `.wavg` bytes (for pickling).

use numpy::PyUntypedArrayMethods;
use pyo3::prelude::*;
use wavg::mesh::TexCoords;
use wavg::{TriMesh, Vector3};

use crate::args::{array, data, finite, indices, ints, reals};
use crate::errors::{lib, value};
use crate::pool::DetachRun;

/// `(V, F)` of a mesh as NumPy arrays.
pub(crate) fn mesh_arrays<'py>(
    py: Python<'py>,
    mesh: &TriMesh,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let v: Vec<f64> = mesh
        .positions
        .iter()
        .flat_map(|p| [p.x, p.y, p.z])
        .collect();
    let f: Vec<i64> = mesh
        .triangles
        .iter()
        .flat_map(|t| t.map(i64::from))
        .collect();
    Ok((
        array(py, v, &[mesh.positions.len(), 3])?,
        array(py, f, &[mesh.triangles.len(), 3])?,
    ))
}

/// A mesh from `V (n, 3)`, `F (m, 3)` and optional per-corner `uv (m, 3, 2)`.
pub(crate) fn mesh_from(
    v: &Bound<'_, PyAny>,
    f: &Bound<'_, PyAny>,
    uv: Option<&Bound<'_, PyAny>>,
    vname: &str,
    fname: &str,
) -> PyResult<TriMesh> {
    let va = reals(
        v,
        vname,
        2,
        &[Some(3)],
        "an (n, 3) array of float vertex positions",
    )?;
    let fa = ints(
        f,
        fname,
        2,
        &[Some(3)],
        "an (m, 3) array of integer vertex ids",
    )?;
    let vs = data(&va);
    finite(vs, vname)?;
    let n = va.shape()[0];
    let ids = indices(data(&fa), n, fname)?;
    let positions = vs
        .chunks_exact(3)
        .map(|p| Vector3::new(p[0], p[1], p[2]))
        .collect();
    let triangles = ids.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    let mut mesh = TriMesh::new(positions, triangles);
    if let Some(uv) = uv.filter(|u| !u.is_none()) {
        let m = fa.shape()[0];
        let ua = reals(
            uv,
            "uv",
            3,
            &[Some(3), Some(2)],
            "an (m, 3, 2) array of per-corner texture coordinates",
        )?;
        if ua.shape()[0] != m {
            return Err(value(format!(
                "uv must have one row per face: shape ({m}, 3, 2); got {:?}",
                ua.shape()
            )));
        }
        finite(data(&ua), "uv")?;
        mesh.uv = Some(TexCoords {
            coords: data(&ua)
                .chunks_exact(2)
                .map(|c| [c[0], c[1]].into())
                .collect(),
            faces: (0..m as u32)
                .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
                .collect(),
        });
    }
    Ok(mesh)
}

/// Embedding bytes (the `.wavg` format) of a surface, when it has one.
pub(crate) fn embedding_bytes(py: Python<'_>, s: &wavg::Surface) -> PyResult<Option<Vec<u8>>> {
    py.detach_run(|| {
        s.embedding()
            .map(|e| wavg::embed::file::encode(e, s.mesh().mesh()))
            .transpose()
    })
    .map_err(lib(py))
}
