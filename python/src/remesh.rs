//! `wavg.Remesher`: semiregular remeshing of a coarse polygon mesh on the surface, with
//! interactive moves of the base vertices.

use numpy::PyUntypedArrayMethods;
use pyo3::prelude::*;

use crate::pool::DetachRun;
use wavg::Vector3;
use wavg::apps::BaseMesh;

use crate::args::{Int, array, data, ints, reals};
use crate::errors::{lib, value};
use crate::surface::Surface;

/// Semiregular remeshing: ``Remesher(S, base_V, base_F, levels=2, smooth=3)``.
///
/// ``base_V (b, 3)`` float vertices on or near the surface, ``base_F`` polygons
/// (``(f, p)`` int array or a list of index lists, 3 to 64 corners, counter-clockwise).
/// ``run()`` splits every polygon ``levels`` times, smooths ``smooth`` steps on the
/// surface (every new vertex a forward problem) and sets ``vertices (N, 3)`` float64 and
/// ``faces`` (quads ``(M, 4)`` int64 when every face has four corners, else a list).
/// ``move_vertex(i, xyz)`` moves base vertex ``i`` to the surface point closest to
/// ``xyz``; the next ``run()`` starts from the previous answers.
#[pyclass(module = "wavg", name = "Remesher")]
pub(crate) struct Remesher {
    inner: wavg::apps::Remesher,
    levels: usize,
    smooth: usize,
    result: Option<wavg::apps::RemeshResult>,
}

#[pymethods]
impl Remesher {
    #[new]
    #[pyo3(
        signature = (S, base_V, base_F, levels=Int::of(wavg::apps::DEFAULT_LEVELS as i128), smooth=Int::of(wavg::apps::DEFAULT_SMOOTH_STEPS as i128)),
        text_signature = "(S, base_V, base_F, levels=2, smooth=3)"
    )]
    #[allow(non_snake_case)]
    fn new(
        py: Python<'_>,
        S: PyRef<'_, Surface>,
        base_V: &Bound<'_, PyAny>,
        base_F: &Bound<'_, PyAny>,
        levels: Int,
        smooth: Int,
    ) -> PyResult<Self> {
        let levels = levels.within("levels", 0, wavg::apps::MAX_LEVELS as i128)?;
        let smooth = smooth.within("smooth", 0, wavg::apps::MAX_SMOOTH_STEPS as i128)?;
        let v = reals(
            base_V,
            "base_V",
            2,
            &[Some(3)],
            "a (b, 3) array of float positions",
        )?;
        let positions = data(&v)
            .chunks_exact(3)
            .map(|p| Vector3::new(p[0], p[1], p[2]))
            .collect();
        let faces = polygons(base_F)?;
        let base = BaseMesh { positions, faces };
        let projector = S.inner.projector().clone();
        let inner = py
            .detach_run(|| wavg::apps::Remesher::new(projector, &base))
            .map_err(lib(py))?;
        Ok(Self {
            inner,
            levels: levels as usize,
            smooth: smooth as usize,
            result: None,
        })
    }

    /// r.run() -> (vertices (N, 3) float64, faces): remeshes (in parallel, without the GIL).
    fn run<'py>(&mut self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let (levels, smooth) = (self.levels, self.smooth);
        let inner = &mut self.inner;
        let r = py
            .detach_run(|| inner.remesh(levels, smooth))
            .map_err(lib(py))?;
        self.result = Some(r);
        Ok((self.vertices(py)?, self.faces(py)?))
    }

    /// r.move_vertex(i, xyz): moves base vertex ``i`` to the surface point closest to ``xyz``
    /// ``(3,)`` float.
    fn move_vertex(&mut self, py: Python<'_>, i: Int, xyz: &Bound<'_, PyAny>) -> PyResult<()> {
        let n = self.inner.base_points().len();
        let i = i.within("i", 0, n as i128 - 1)?;
        let a = reals(xyz, "xyz", 1, &[], "a (3,) array of float coordinates")?;
        let p = data(&a);
        if p.len() != 3 || !p.iter().all(|x| x.is_finite()) {
            return Err(value("xyz must be 3 finite coordinates"));
        }
        let inner = &mut self.inner;
        py.detach_run(|| {
            let (sp, _) = inner.closest_point(&Vector3::new(p[0], p[1], p[2]));
            inner.move_base_vertex(i as usize, sp)
        })
        .map_err(lib(py))
    }

    /// Vertices of the last ``run()``, ``(N, 3)`` float64 (None before the first).
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        match &self.result {
            None => Ok(py.None().into_bound(py)),
            Some(r) => {
                let v: Vec<f64> = r.positions.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
                array(py, v, &[r.positions.len(), 3])
            }
        }
    }

    /// Faces of the last ``run()``: ``(M, p)`` int64 when all have ``p`` corners, else a
    /// list of lists (None before the first run).
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let Some(r) = &self.result else {
            return Ok(py.None().into_bound(py));
        };
        let p = r.faces.first().map_or(0, Vec::len);
        if r.faces.iter().all(|f| f.len() == p) {
            let v: Vec<i64> = r.faces.iter().flatten().map(|&i| i64::from(i)).collect();
            array(py, v, &[r.faces.len(), p])
        } else {
            Ok(pyo3::types::PyList::new(py, r.faces.iter())?.into_any())
        }
    }

    /// The report of the last ``run()`` (keys of ``wavg remesh --json``), or None.
    #[getter]
    fn report(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        match &self.result {
            None => Ok(py.None()),
            Some(r) => crate::json::to_py(py, &self.inner.report(r)),
        }
    }
}

/// Polygons from an `(f, p)` int array or a list of index lists.
fn polygons(obj: &Bound<'_, PyAny>) -> PyResult<Vec<Vec<u32>>> {
    let expected = "an (f, p) int array or a list of polygons (lists of 0-based vertex ids)";
    if let Ok(a) = ints(obj, "base_F", 2, &[None], expected) {
        let p = a.shape()[1];
        return data(&a)
            .chunks(p.max(1))
            .map(|f| f.iter().map(|&x| to_u32(x)).collect())
            .collect();
    }
    let mut out = Vec::new();
    for f in obj
        .try_iter()
        .map_err(|_| crate::errors::type_error(format!("base_F must be {expected}")))?
    {
        let f: Vec<i64> = f?
            .extract()
            .map_err(|_| crate::errors::type_error(format!("base_F must be {expected}")))?;
        out.push(f.into_iter().map(to_u32).collect::<PyResult<Vec<u32>>>()?);
    }
    Ok(out)
}

fn to_u32(x: i64) -> PyResult<u32> {
    u32::try_from(x).map_err(|_| {
        value(format!(
            "base_F holds the index {x}: indices must be 0 or more"
        ))
    })
}
