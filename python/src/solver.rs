//! `wavg.Solver`: forward and inverse problems for one anchor set, in parallel batches
//! without the GIL.

use numpy::{PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;

use crate::pool::DetachRun;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyList, PyTuple};
use wavg::{Anchor, ForwardOptions, ForwardResult, SolveError, SurfacePoint};

use crate::args::{Int, array, data, finite, indices, ints, par, reals};
use crate::errors::{lib, to_py, type_error, value};
use crate::surface::Surface;

static TYPES: PyOnceLock<Py<PyModule>> = PyOnceLock::new();

/// The class `name` of `wavg._types` (the named tuples).
pub(crate) fn named_tuple<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
    TYPES
        .get_or_try_init(py, || py.import("wavg._types").map(Into::into))?
        .bind(py)
        .getattr(name)
}

/// Forward and inverse problems for one set of anchors on a surface.
///
/// ``Solver(S, anchors)``: ``anchors`` is ``(k,)`` integer vertex ids, or a tuple
/// ``(faces (k,) int, bary (k, 3) float)`` of surface points. The solver keeps the
/// surface's embedding as it was when the solver was made.
#[pyclass(module = "wavg", name = "Solver")]
pub(crate) struct Solver {
    pub(crate) inner: wavg::Solver,
    pub(crate) surface: Py<Surface>,
    /// The surface (mesh and embedding) as it was when the solver was made: what a pickled
    /// or copied solver is rebuilt from, whatever `surface` computed or loaded since.
    pub(crate) made_from: wavg::Surface,
}

/// Surface points from `faces (q,)` and `bary (q, 3)`, checked against `n_faces`.
pub(crate) fn points(
    faces: &Bound<'_, PyAny>,
    bary: &Bound<'_, PyAny>,
    n_faces: usize,
    fname: &str,
    bname: &str,
) -> PyResult<Vec<SurfacePoint>> {
    let fa = ints(faces, fname, 1, &[], "a (q,) array of integer face ids")?;
    let ba = reals(
        bary,
        bname,
        2,
        &[Some(3)],
        "a (q, 3) array of float barycentric coordinates",
    )?;
    if fa.shape()[0] != ba.shape()[0] {
        return Err(value(format!(
            "{fname} and {bname} must have the same length; got {} and {}",
            fa.shape()[0],
            ba.shape()[0]
        )));
    }
    let f = indices(data(&fa), n_faces, fname)?;
    let b = data(&ba);
    finite(b, bname)?;
    Ok(f.iter()
        .zip(b.chunks_exact(3))
        .map(|(&f, b)| SurfacePoint::new(f, [b[0], b[1], b[2]]))
        .collect())
}

/// Anchors from vertex ids `(k,)` or a pair `(faces, bary)`.
pub(crate) fn anchors(
    s: &wavg::Surface,
    obj: &Bound<'_, PyAny>,
    name: &str,
) -> PyResult<Vec<Anchor>> {
    anchors_within(obj, name, s.n_vertices(), s.n_faces())
}

/// Anchors from vertex ids `(k,)` or a pair `(faces, bary)`, with vertex ids below
/// `n_vertices` and face ids below `n_faces`.
pub(crate) fn anchors_within(
    obj: &Bound<'_, PyAny>,
    name: &str,
    n_vertices: usize,
    n_faces: usize,
) -> PyResult<Vec<Anchor>> {
    if let Ok(t) = obj.cast::<PyTuple>() {
        if t.len() == 2 {
            let second = t.get_item(1)?;
            let is_pair = crate::args::numpy(obj.py())?
                .call_method1("ndim", (&second,))
                .and_then(|d| d.extract::<usize>())
                .is_ok_and(|d| d == 2);
            if is_pair {
                let p = points(
                    &t.get_item(0)?,
                    &second,
                    n_faces,
                    &format!("{name}[0]"),
                    &format!("{name}[1]"),
                )?;
                return Ok(p.into_iter().map(Anchor::Point).collect());
            }
        }
    }
    let a = ints(
        obj,
        name,
        1,
        &[],
        "a (k,) array of integer vertex ids or a pair (faces (k,), bary (k, 3))",
    )?;
    Ok(indices(data(&a), n_vertices, name)?
        .into_iter()
        .map(Anchor::Vertex)
        .collect())
}

/// One anchor: a vertex id or a pair `(face, bary (3,))`.
fn one_anchor(s: &wavg::Surface, obj: &Bound<'_, PyAny>) -> PyResult<Anchor> {
    if let Some(v) = obj.extract::<Int>()?.value().map(Int::of) {
        let v = v.within("vertex_or_point", 0, s.n_vertices() as i128 - 1)?;
        return Ok(Anchor::Vertex(v as u32));
    }
    let (f, b): (Bound<'_, PyAny>, Bound<'_, PyAny>) = obj.extract().map_err(|_| {
        type_error(
            "vertex_or_point must be a vertex id (int) or a pair (face: int, bary: (3,) floats)",
        )
    })?;
    let f: i64 = f
        .extract()
        .map_err(|_| type_error("vertex_or_point[0] must be an int face id"))?;
    let faces = PyList::new(obj.py(), [f])?;
    let bary = PyList::new(obj.py(), [b])?;
    let p = points(
        faces.as_any(),
        bary.as_any(),
        s.n_faces(),
        "vertex_or_point[0]",
        "vertex_or_point[1]",
    )?;
    Ok(Anchor::Point(p[0]))
}

/// Forward results as `Points(face, bary, xyz, ok)`; `squeeze` drops the query axis.
pub(crate) fn points_tuple<'py>(
    py: Python<'py>,
    out: &[Result<ForwardResult, SolveError>],
    squeeze: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let q = out.len();
    let (face, bary, xyz, ok) = py.detach_run(|| {
        let mut face = Vec::with_capacity(q);
        let mut bary = Vec::with_capacity(3 * q);
        let mut xyz = Vec::with_capacity(3 * q);
        let mut ok = Vec::with_capacity(q);
        for r in out {
            match r {
                Ok(r) => {
                    face.push(i64::from(r.point.face));
                    bary.extend(r.point.bary);
                    xyz.extend([r.position.x, r.position.y, r.position.z]);
                    ok.push(true);
                }
                Err(_) => {
                    face.push(-1);
                    bary.extend([f64::NAN; 3]);
                    xyz.extend([f64::NAN; 3]);
                    ok.push(false);
                }
            }
        }
        (face, bary, xyz, ok)
    });
    let class = named_tuple(py, "Points")?;
    if squeeze {
        let f = face[0].into_pyobject(py)?.into_any();
        let o = pyo3::types::PyBool::new(py, ok[0]).to_owned().into_any();
        return class.call1((f, array(py, bary, &[3])?, array(py, xyz, &[3])?, o));
    }
    class.call1((
        array(py, face, &[q])?,
        array(py, bary, &[q, 3])?,
        array(py, xyz, &[q, 3])?,
        array(py, ok, &[q])?,
    ))
}

/// The caller's `out` array for `q` rows of `k` weights: float64, C-contiguous, writable.
fn out_rows<'py>(
    o: &Bound<'py, PyAny>,
    q: usize,
    k: usize,
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    let expected = format!("a writable C-contiguous ({q}, {k}) float64 array");
    let a = o
        .cast::<numpy::PyArray2<f64>>()
        .map_err(|_| type_error(format!("out must be {expected}")))?;
    if a.shape() != [q, k] || !a.is_c_contiguous() {
        return Err(value(format!(
            "out must be {expected}; got shape {:?}{}",
            a.shape(),
            if a.is_c_contiguous() {
                ""
            } else {
                ", not C-contiguous"
            }
        )));
    }
    Ok(a.clone())
}

impl Solver {
    /// Forward problems for the rows of `w` (`(q, k)`, or `(k,)` for one).
    pub(crate) fn forward_rows<'py>(
        &self,
        py: Python<'py>,
        w: &Bound<'py, PyAny>,
        threads: Option<Int>,
        name: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let k = self.inner.n_anchors();
        let expected = format!("a ({k},) or (q, {k}) array of float weights (one per anchor)");
        let squeeze = reals_ndim(w)? == 1;
        let a = if squeeze {
            reals(w, name, 1, &[], &expected)?
        } else {
            reals(w, name, 2, &[Some(k)], &expected)?
        };
        if squeeze && a.shape()[0] != k {
            return Err(value(format!(
                "{name} must be {expected}; got shape {:?}",
                a.shape()
            )));
        }
        let par = par(threads)?;
        let flat = data(&a);
        let rows: Vec<&[f64]> = flat.chunks_exact(k.max(1)).collect();
        // Malformed weights refuse the call, as in every door; rows without an answer are
        // `ok` False.
        if let Err((i, e)) = wavg::check_weight_rows(&rows, k, wavg::Normalization::Reject) {
            return Err(value(if squeeze {
                format!("{name}: {}", e.message())
            } else {
                format!("{name} row {}: {}", i + 1, e.message())
            }));
        }
        let mut out = Vec::new();
        let mut scratch = wavg::ForwardScratch::default();
        py.detach_run(|| {
            self.inner.forward_batch_into(
                &rows,
                &ForwardOptions::default(),
                &mut scratch,
                &mut out,
                par,
            )
        })
        .map_err(lib(py))?;
        points_tuple(py, &out, squeeze)
    }
}

/// The number of dimensions of an array-like (2 when unknown, for the error message).
fn reals_ndim(obj: &Bound<'_, PyAny>) -> PyResult<usize> {
    Ok(crate::args::numpy(obj.py())?
        .call_method1("ndim", (obj,))
        .and_then(|d| d.extract::<usize>())
        .unwrap_or(2)
        .clamp(1, 2))
}

#[pymethods]
impl Solver {
    #[new]
    fn new(
        py: Python<'_>,
        surface: Bound<'_, Surface>,
        anchors: &Bound<'_, PyAny>,
    ) -> PyResult<Self> {
        let s = surface.borrow().inner.clone();
        let a = self::anchors(&s, anchors, "anchors")?;
        if a.is_empty() {
            return Err(value("anchors must hold at least one anchor; got none"));
        }
        let inner = py.detach_run(|| s.solver(a)).map_err(|e| to_py(py, e))?;
        Ok(Self {
            inner,
            surface: surface.unbind(),
            made_from: s,
        })
    }

    /// sol.forward(W, threads=None) -> Points(face, bary, xyz, ok)
    ///
    /// The weighted averages of the anchors: ``W`` is ``(q, k)`` float weights (one row per
    /// query, one column per anchor; any float dtype and layout), or ``(k,)`` for one
    /// query. Returns ``wavg.Points``: ``face (q,) int64``, ``bary (q, 3) float64``,
    /// ``xyz (q, 3) float64``, ``ok (q,) bool``; a row without an answer (no weighted
    /// average) has ``face == -1`` and NaN. Weights that are not finite or do not sum to 1
    /// raise ``ValueError`` naming the first such row (counting from 1), as every door
    /// refuses them. For ``(k,)`` weights, ``face`` and ``ok`` are scalars and ``bary``, ``xyz``
    /// ``(3,)``. Runs in parallel without the GIL (``threads``: None = all cores).
    #[pyo3(signature = (W, threads=None))]
    #[allow(non_snake_case)]
    fn forward<'py>(
        &self,
        py: Python<'py>,
        W: &Bound<'py, PyAny>,
        threads: Option<Int>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.forward_rows(py, W, threads, "W")
    }

    /// sol.inverse(faces, bary, verified=True, threads=None, out=None) -> (W (q, k) float64, ok (q,) bool)
    ///
    /// Generalised barycentric weights of surface points ``faces (q,) int``, ``bary (q, 3)
    /// float``. With ``verified`` (default) the weights are checked by the forward problem
    /// (the paper's where they return to the point, else an offset-penalised solution that
    /// does); where none returns, or there are no weights, ``ok`` is False and the row is
    /// NaN (as ``wavg inverse --verified`` prints ``none not-reached``). Without
    /// ``verified``, the paper's weights; ``ok`` False only for NaN rows. Parallel without the GIL (``threads``: None = all
    /// cores). ``out``: a writable C-contiguous ``(q, k) float64`` array to fill and return
    /// as ``W`` (saves allocating and first touching a new one in repeated calls).
    #[pyo3(signature = (faces, bary, verified=true, threads=None, out=None))]
    fn inverse<'py>(
        &self,
        py: Python<'py>,
        faces: &Bound<'py, PyAny>,
        bary: &Bound<'py, PyAny>,
        verified: bool,
        threads: Option<Int>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let pts = points(faces, bary, self.inner.mesh().n_faces(), "faces", "bary")?;
        let par = par(threads)?;
        let k = self.inner.n_anchors();
        let q = pts.len();
        let w = match out {
            Some(o) => out_rows(o, q, k)?,
            None => numpy::PyArray2::<f64>::zeros(py, [q, k], false),
        };
        let mut rw = w.try_readwrite().map_err(|e| value(format!("out: {e}")))?;
        let rows = rw.as_slice_mut().map_err(|e| value(format!("out: {e}")))?;
        let ok = py
            .detach_run(|| -> Result<_, SolveError> {
                if !verified {
                    let status = self.inner.inverse_rows_into(&pts, rows, par)?;
                    return Ok(status.iter().map(Result::is_ok).collect());
                }
                let mut batch = wavg::BatchWeights::default();
                let mut trips = Vec::new();
                self.inner.inverse_verified_batch_into(
                    &pts,
                    wavg::DEFAULT_TOLERANCE,
                    &mut batch,
                    &mut trips,
                    par,
                )?;
                // As `wavg inverse --verified` (`none not-reached`) and the C ABI: weights
                // that do not return to their point are none.
                let mut ok = Vec::with_capacity(q);
                for (i, row) in rows.chunks_exact_mut(k.max(1)).enumerate().take(q) {
                    match (batch.get(i), &trips[i]) {
                        (Ok(r), Ok(wavg::RoundTrip::Paper | wavg::RoundTrip::Penalized(_))) => {
                            row.copy_from_slice(r);
                            ok.push(true);
                        }
                        _ => {
                            row.fill(f64::NAN);
                            ok.push(false);
                        }
                    }
                }
                Ok(ok)
            })
            .map_err(lib(py))?;
        drop(rw);
        Ok((w.into_any(), array(py, ok, &[q])?))
    }

    /// sol.set_anchor(i, vertex_or_point): replaces anchor ``i`` by a vertex id or a pair
    /// ``(face, bary (3,))``.
    fn set_anchor(
        &mut self,
        py: Python<'_>,
        i: Int,
        vertex_or_point: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let k = self.inner.n_anchors();
        let i = i.within("i", 0, k as i128 - 1)? as usize;
        let a = one_anchor(&self.made_from, vertex_or_point)?;
        self.inner.anchors_mut().set(i, a).map_err(lib(py))
    }

    /// Number of anchors ``k``.
    #[getter]
    fn anchor_count(&self) -> usize {
        self.inner.n_anchors()
    }

    /// The surface this solver was made on.
    #[getter]
    fn surface(&self, py: Python<'_>) -> Py<Surface> {
        self.surface.clone_ref(py)
    }

    /// The anchors as surface points: ``(faces (k,) int64, bary (k, 3) float64)``.
    #[getter]
    fn anchor_points<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let k = self.inner.n_anchors();
        let mut f = Vec::with_capacity(k);
        let mut b = Vec::with_capacity(3 * k);
        for i in 0..k {
            let p = self.inner.anchors().point(i).map_err(lib(py))?;
            f.push(i64::from(p.face));
            b.extend(p.bary);
        }
        Ok((array(py, f, &[k])?, array(py, b, &[k, 3])?))
    }

    fn __repr__(&self) -> String {
        format!("wavg.Solver({} anchors)", self.inner.n_anchors())
    }

    /// Pickling: the surface and each anchor (vertex id, or -1 with a face and barycentrics).
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let mut ids = Vec::new();
        let mut faces = Vec::new();
        let mut bary = Vec::new();
        for a in self.inner.anchors().anchors() {
            match a {
                Anchor::Vertex(v) => {
                    ids.push(i64::from(*v));
                    faces.push(0i64);
                    bary.extend([0.0; 3]);
                }
                Anchor::Point(p) => {
                    ids.push(-1);
                    faces.push(i64::from(p.face));
                    bary.extend(p.bary);
                }
            }
        }
        let k = ids.len();
        let restore = py.import("wavg._wavg")?.getattr("_restore_solver")?;
        // The surface as the solver saw it: `self.surface` may have a newer embedding.
        let snapshot = Surface {
            inner: self.made_from.clone(),
            polygons: self.surface.borrow(py).polygons.clone(),
            source: None,
            busy: Default::default(),
        };
        let args = (
            Py::new(py, snapshot)?,
            array(py, ids, &[k])?,
            array(py, faces, &[k])?,
            array(py, bary, &[k, 3])?,
            self.inner.gamma(),
        )
            .into_pyobject(py)?;
        Ok((restore, args))
    }

    /// A deep copy's surface is the one the solver was made from, as a pickled copy's.
    fn __deepcopy__(&self, py: Python<'_>, _memo: &Bound<'_, PyAny>) -> PyResult<Self> {
        let snapshot = Surface {
            inner: self.made_from.clone(),
            polygons: self.surface.borrow(py).polygons.clone(),
            source: None,
            busy: Default::default(),
        };
        Ok(Self {
            inner: self.inner.clone(),
            surface: Py::new(py, snapshot)?,
            made_from: self.made_from.clone(),
        })
    }

    fn __copy__(&self, py: Python<'_>) -> Self {
        Self {
            inner: self.inner.clone(),
            surface: self.surface.clone_ref(py),
            made_from: self.made_from.clone(),
        }
    }
}

/// Rebuilds a pickled solver.
#[pyfunction]
pub(crate) fn _restore_solver(
    py: Python<'_>,
    surface: Bound<'_, Surface>,
    ids: &Bound<'_, PyAny>,
    faces: &Bound<'_, PyAny>,
    bary: &Bound<'_, PyAny>,
    gamma: f64,
) -> PyResult<Solver> {
    let s = surface.borrow().inner.clone();
    let ids = ints(ids, "ids", 1, &[], "(k,) int")?;
    let pts = points(faces, bary, s.n_faces(), "faces", "bary")?;
    let a: Vec<Anchor> = data(&ids)
        .iter()
        .zip(pts)
        .map(|(&v, p)| {
            if v >= 0 {
                Anchor::Vertex(v as u32)
            } else {
                Anchor::Point(p)
            }
        })
        .collect();
    let mut inner = py.detach_run(|| s.solver(a)).map_err(|e| to_py(py, e))?;
    inner.set_gamma(gamma).map_err(lib(py))?;
    Ok(Solver {
        inner,
        surface: surface.unbind(),
        made_from: s,
    })
}
