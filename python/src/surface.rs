//! `wavg.Surface`: a validated mesh with its 8-D embedding, from arrays or a file.

use std::path::PathBuf;

use pyo3::prelude::*;

use crate::pool::DetachRun;
use pyo3::types::{PyBytes, PyTuple};
use wavg::PrecomputeOptions;

use crate::args::{self, Int, array, data, indices, ints};
use crate::arrays::{embedding_bytes, mesh_arrays, mesh_from};
use crate::errors::{require_file, to_py, value};
use crate::progress;

/// A triangle mesh with its embedding in R^8, the object every question starts from.
///
/// ``Surface(V, F, uv=None)``: ``V`` vertex positions ``(n, 3)`` (any float or integer
/// dtype), ``F`` counter-clockwise triangles ``(m, 3)`` of 0-based vertex ids (any integer
/// dtype), ``uv`` optional per-corner texture coordinates ``(m, 3, 2)``. The mesh must be
/// an oriented manifold (``InvalidMeshError`` lists its problems otherwise). Until
/// ``precompute`` or ``load_embedding``, the 3-D positions serve as the embedding.
#[pyclass(module = "wavg", name = "Surface")]
pub(crate) struct Surface {
    pub(crate) inner: wavg::Surface,
    /// The polygon of the mesh file each triangle came from (`Surface.open`; empty when
    /// every triangle is its own polygon): `render`'s wireframe leaves out the diagonals
    /// that triangulating the file's quads added.
    pub(crate) polygons: std::sync::Arc<Vec<u32>>,
    /// The mesh file it was read from (`Surface.open`): such a surface uses the embedding
    /// cache by default, and names its entries by this path.
    pub(crate) source: Option<String>,
    /// Set while `precompute` runs (it replaces the embedding when it returns): a second
    /// precompute or a `load_embedding` meanwhile is refused rather than overwritten.
    pub(crate) busy: Busy,
}

/// A flag shared by a surface and its running precompute; copies get their own.
#[derive(Default)]
pub(crate) struct Busy(std::sync::Arc<std::sync::atomic::AtomicBool>);

impl Busy {
    /// Sets the flag until the returned guard drops; an error if it is already set.
    fn claim(&self) -> PyResult<BusyGuard> {
        use std::sync::atomic::Ordering;
        self.0
            .compare_exchange(false, true, Ordering::AcqRel, Ordering::Acquire)
            .map_err(|_| {
                pyo3::exceptions::PyRuntimeError::new_err(
                    "a precompute is already running on this surface",
                )
            })?;
        Ok(BusyGuard(self.0.clone()))
    }

    fn is_set(&self) -> bool {
        self.0.load(std::sync::atomic::Ordering::Acquire)
    }
}

/// Clears its [`Busy`] flag when dropped (on every way out of `precompute`).
struct BusyGuard(std::sync::Arc<std::sync::atomic::AtomicBool>);

impl Drop for BusyGuard {
    fn drop(&mut self) {
        self.0.store(false, std::sync::atomic::Ordering::Release);
    }
}

/// The most points one `sample_points` call draws (32 bytes each in the answer).
const MAX_POINTS: usize = 100_000_000;

#[pymethods]
impl Surface {
    #[new]
    #[pyo3(signature = (V, F, uv=None))]
    #[allow(non_snake_case)]
    fn new(
        py: Python<'_>,
        V: &Bound<'_, PyAny>,
        F: &Bound<'_, PyAny>,
        uv: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let mesh = mesh_from(V, F, uv, "V", "F")?;
        let inner = py
            .detach_run(|| wavg::Surface::from_mesh(mesh))
            .map_err(|e| to_py(py, e))?;
        Ok(Self {
            inner,
            polygons: Default::default(),
            source: None,
            busy: Busy::default(),
        })
    }

    /// Surface.open(path, embedding=None) -> Surface
    ///
    /// Reads a mesh file (.obj, .off, .ply, optionally .gz; .gltf or .glb, welded into one
    /// surface, ``scene.glb#Name`` for one of its meshes; texture coordinates of .obj and
    /// glTF are kept) or a builtin mesh (``builtin:torus``, as the command line takes
    /// them) and, when ``embedding`` names a ``.wavg`` file, its embedding.
    #[staticmethod]
    #[pyo3(signature = (path, embedding=None))]
    fn open(py: Python<'_>, path: PathBuf, embedding: Option<PathBuf>) -> PyResult<Self> {
        crate::errors::require_mesh_file(&path)?;
        if let Some(e) = &embedding {
            require_file(e)?;
        }
        let (inner, notes) = py
            .detach_run(|| {
                let (mesh, notes) = wavg::load_mesh_with_notes(&path)?;
                let mesh = wavg::ValidMesh::new(mesh)?;
                wavg::Surface::from_valid_and_file(mesh, embedding.as_deref()).map(|s| (s, notes))
            })
            .map_err(|e| to_py(py, e))?;
        Ok(Self {
            inner,
            polygons: std::sync::Arc::new(notes.polygon_of),
            source: Some(path.display().to_string()),
            busy: Busy::default(),
        })
    }

    /// Surface.from_trimesh(mesh) -> Surface
    ///
    /// A surface from a ``trimesh.Trimesh`` (its ``vertices`` and ``faces``; trimesh itself
    /// is not needed by wavg).
    #[staticmethod]
    fn from_trimesh(py: Python<'_>, mesh: &Bound<'_, PyAny>) -> PyResult<Self> {
        let v = mesh.getattr("vertices").map_err(|_| {
            crate::errors::type_error("mesh must have .vertices and .faces (a trimesh.Trimesh)")
        })?;
        let f = mesh.getattr("faces").map_err(|_| {
            crate::errors::type_error("mesh must have .vertices and .faces (a trimesh.Trimesh)")
        })?;
        Self::new(py, &v, &f, None)
    }

    /// S.precompute(landmarks=None, seed=0, threads=None, progress=True, cache=None) -> dict
    ///
    /// Computes the 8-D embedding (landmarks, geodesic distances, MDS, least-squares mesh)
    /// and uses it from now on; returns the report (the keys of ``wavg precompute --json``,
    /// plus ``cached`` and ``cache_path``). ``landmarks``: None (or 0) for the library's
    /// choice for this mesh, the one every way into wavg makes (the paper's 1000).
    /// ``cache``: the embedding cache every way into wavg shares (``wavg cache list``
    /// shows it): None (the default) uses it for a surface read with ``Surface.open`` and
    /// not for one made from arrays, True always, False never, a folder path that folder.
    /// With a cache, an entry for this mesh and these options is read instead of computed
    /// (the report then holds what the entry says of itself, with ``cached`` True), and a
    /// computed embedding is stored there. ``threads``: None for all cores. ``progress``:
    /// True draws a text bar on a terminal, False nothing, a callable ``(stage: str, done:
    /// int, total: int)`` is called at the start, at every new stage and about ten times a
    /// second in between (also while the progress stands still) and cancels
    /// (``CancelledError``) by returning ``False`` (any false value but None, such as
    /// NumPy's ``False_``; None goes on). Ctrl-C stops it within a second
    /// (``KeyboardInterrupt``). Any other value of ``progress`` (a number, a string) is a
    /// ``TypeError``. A cancelled call returns at once; the abandoned work stops
    /// at its next checkpoint in the background. On any error the surface is unchanged.
    /// While it runs, another thread's ``precompute`` or ``load_embedding`` of this surface
    /// raises ``RuntimeError`` (the other methods go on with the current embedding).
    #[pyo3(
        signature = (landmarks=None, seed=Int::of(0), threads=None, progress=None, cache=None),
        text_signature = "($self, landmarks=None, seed=0, threads=None, progress=True, cache=None)"
    )]
    #[allow(clippy::too_many_arguments)]
    fn precompute(
        slf: &Bound<'_, Self>,
        py: Python<'_>,
        landmarks: Option<Int>,
        seed: Int,
        threads: Option<Int>,
        progress: Option<Bound<'_, PyAny>>,
        cache: Option<Bound<'_, PyAny>>,
    ) -> PyResult<Py<PyAny>> {
        let landmarks = match landmarks {
            Some(l) => l.within("landmarks", 0, u32::MAX as i128)?,
            None => 0,
        };
        let seed = seed.seed("seed")?;
        let par = args::par(threads)?;
        let (cache, info) = {
            let me = slf.borrow();
            let name = me.source.clone().unwrap_or_else(|| "<arrays>".into());
            (
                crate::cache::resolve(cache.as_ref(), me.source.is_some())?,
                wavg::cache::EntryInfo::new(name, crate::cache::WRITER),
            )
        };
        let bar = match &progress {
            None => true,
            Some(p) if p.is_callable() => false,
            Some(p) => p.extract::<bool>().map_err(|_| {
                pyo3::exceptions::PyTypeError::new_err(format!(
                    "progress must be True, False, None or a callable (stage, done, total), \
                     got {}",
                    p.repr()
                        .map_or_else(|_| "another value".into(), |r| r.to_string())
                ))
            })?,
        };
        let callback: Option<Bound<'_, PyAny>> =
            if let Some(p) = progress.filter(|p| p.is_callable()) {
                Some(p)
            } else if bar {
                let bar = py
                    .import("wavg._progress")?
                    .getattr("terminal_bar")?
                    .call0()?;
                (!bar.is_none()).then_some(bar)
            } else {
                None
            };
        let (mut s, _busy) = {
            let me = slf.borrow();
            (me.inner.clone(), me.busy.claim()?)
        };
        let opts = PrecomputeOptions {
            landmarks: landmarks as usize,
            seed,
            ..wavg::default_precompute_options(s.mesh())
        };
        let result = progress::watch(
            py,
            callback.as_ref(),
            move |p| {
                par.install(|| {
                    s.precompute_cached(&opts, cache.as_ref(), &info, p)
                        .map(|r| (r, s))
                })
            },
            |r| matches!(r, Ok(Ok(_))),
        );
        if let Some(bar) = &callback {
            if bar.hasattr("close")? {
                bar.call_method0("close")?;
            }
        }
        let (outcome, s) = result?
            .map_err(|e| value(format!("threads: {e}")))?
            .map_err(|e| to_py(py, e))?;
        let n = (s.n_vertices(), s.n_faces());
        let report = crate::cache::report(py, &outcome, s.embedding_summary(), n)?;
        slf.borrow_mut().inner = s;
        Ok(report)
    }

    /// S.load_cached(landmarks=None, seed=0, cache=True) -> bool
    ///
    /// Uses the embedding cache's entry for this mesh and these options (the arguments of
    /// ``precompute``, ``cache`` likewise but on by default) when there is one: True when
    /// it was loaded, False when there is none (nothing computed). An entry that exists but
    /// does not load raises as ``load_embedding`` does.
    #[pyo3(signature = (landmarks=None, seed=Int::of(0), cache=None))]
    fn load_cached(
        &mut self,
        py: Python<'_>,
        landmarks: Option<Int>,
        seed: Int,
        cache: Option<Bound<'_, PyAny>>,
    ) -> PyResult<bool> {
        let landmarks = match landmarks {
            Some(l) => l.within("landmarks", 0, u32::MAX as i128)?,
            None => 0,
        };
        let seed = seed.seed("seed")?;
        let Some(cache) = crate::cache::resolve(cache.as_ref(), true)? else {
            return Ok(false);
        };
        if self.busy.is_set() {
            return Err(pyo3::exceptions::PyRuntimeError::new_err(
                "a precompute is running on this surface (it replaces the embedding when it \
                 returns); load the embedding after it",
            ));
        }
        let mut s = self.inner.clone();
        let opts = wavg::resolve_landmarks(
            &PrecomputeOptions {
                landmarks: landmarks as usize,
                seed,
                ..wavg::default_precompute_options(s.mesh())
            },
            s.mesh(),
        );
        let found = py.detach_run(|| match cache.load(s.mesh(), &opts) {
            None => Ok(false),
            Some(r) => {
                let (e, _) = r?;
                s.set_embedding(e).map(|()| true)
            }
        });
        let found = found.map_err(|e| to_py(py, e))?;
        if found {
            self.inner = s;
        }
        Ok(found)
    }

    /// S.load_embedding(path): reads a ``.wavg`` embedding computed for this mesh (its
    /// fingerprint is checked) and uses it from now on. ``RuntimeError`` while a
    /// ``precompute`` of this surface runs in another thread.
    fn load_embedding(&mut self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        if self.busy.is_set() {
            return Err(pyo3::exceptions::PyRuntimeError::new_err(
                "a precompute is running on this surface (it replaces the embedding when it \
                 returns); load the embedding after it",
            ));
        }
        require_file(&path)?;
        let mut s = self.inner.clone();
        py.detach_run(|| s.load_embedding(&path))
            .map_err(|e| to_py(py, e))?;
        self.inner = s;
        Ok(())
    }

    /// S.save_embedding(path): writes the embedding to a ``.wavg`` file (atomically).
    fn save_embedding(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        // As `wavg precompute`: a mesh file's name is a mistake that would destroy a mesh.
        if wavg::mesh::Format::from_path(&path).is_ok() {
            return Err(value(format!(
                "path {} has a mesh file's extension; the embedding is a .wavg file",
                path.display()
            )));
        }
        py.detach_run(|| self.inner.save_embedding(&path))
            .map_err(|e| to_py(py, e))
    }

    /// Vertex positions, ``(n, 3)`` float64 (a copy).
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(mesh_arrays(py, self.inner.mesh().mesh())?.0)
    }

    /// Triangles, ``(m, 3)`` int64 (a copy).
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(mesh_arrays(py, self.inner.mesh().mesh())?.1)
    }

    /// Per-corner texture coordinates ``(m, 3, 2)`` float64, or None.
    #[getter]
    fn uv<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        let mesh = self.inner.mesh().mesh();
        mesh.uv
            .as_ref()
            .map(|uv| {
                let v: Vec<f64> = uv
                    .faces
                    .iter()
                    .flat_map(|t| {
                        t.iter().flat_map(|&i| {
                            let c = uv.coords[i as usize];
                            [c.x, c.y]
                        })
                    })
                    .collect();
                array(py, v, &[uv.faces.len(), 3, 2])
            })
            .transpose()
    }

    /// The embedding, ``(n, 8)`` float64, or None before ``precompute``/``load_embedding``.
    #[getter]
    fn embedding<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        // From the projector's coordinates (the surface keeps one copy).
        self.inner
            .has_embedding()
            .then(|| {
                let c = self.inner.embedded_coords();
                let v: Vec<f64> = c.iter().flat_map(|c| c.iter().copied()).collect();
                array(py, v, &[c.len(), 8])
            })
            .transpose()
    }

    /// Landmark vertex ids of the embedding, ``(L,)`` int64 (empty without one).
    #[getter]
    fn landmarks<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let l: Vec<i64> = self
            .inner
            .landmarks()
            .iter()
            .map(|&v| i64::from(v))
            .collect();
        let n = l.len();
        array(py, l, &[n])
    }

    /// Number of vertices.
    #[getter]
    fn vertex_count(&self) -> usize {
        self.inner.n_vertices()
    }

    /// Number of triangles.
    #[getter]
    fn face_count(&self) -> usize {
        self.inner.n_faces()
    }

    /// True once an embedding was computed or loaded.
    #[getter]
    fn has_embedding(&self) -> bool {
        self.inner.has_embedding()
    }

    /// S.vertex_points(ids) -> (faces (q,) int64, bary (q, 3) float64)
    ///
    /// Vertices as surface points: a face of each vertex and the barycentrics of its corner.
    fn vertex_points<'py>(
        &self,
        py: Python<'py>,
        ids: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let a = ints(ids, "ids", 1, &[], "a (q,) array of integer vertex ids")?;
        let ids = indices(data(&a), self.inner.n_vertices(), "ids")?;
        let s = &self.inner;
        let (faces, bary) = py
            .detach_run(|| {
                let mut faces = Vec::with_capacity(ids.len());
                let mut bary = Vec::with_capacity(3 * ids.len());
                for v in ids {
                    let p = s.vertex_point(v)?;
                    faces.push(i64::from(p.face));
                    bary.extend(p.bary);
                }
                Ok((faces, bary))
            })
            .map_err(|e| to_py(py, e))?;
        let q = faces.len();
        Ok((array(py, faces, &[q])?, array(py, bary, &[q, 3])?))
    }

    /// S.spread_anchors(k, seed=0) -> (k,) int64: ``k`` vertices spread over the surface by
    /// farthest-point sampling in its embedding (a good default anchor set): what ``wavg
    /// anchors --count k --seed seed`` writes for the same embedding.
    #[pyo3(signature = (k, seed=Int::of(0)), text_signature = "($self, k, seed=0)")]
    fn spread_anchors<'py>(
        &self,
        py: Python<'py>,
        k: Int,
        seed: Int,
    ) -> PyResult<Bound<'py, PyAny>> {
        let k = k.within("k", 1, self.inner.n_vertices() as i128)? as usize;
        let seed = seed.seed("seed")?;
        let s = &self.inner;
        let a = py
            .detach_run(|| s.spread_anchors(k, seed))
            .map_err(|e| to_py(py, e))?;
        let v: Vec<i64> = a
            .iter()
            .map(|a| match a {
                wavg::Anchor::Vertex(v) => i64::from(*v),
                wavg::Anchor::Point(_) => -1,
            })
            .collect();
        array(py, v, &[k])
    }

    /// S.sample_points(n, seed=0) -> (faces (n,) int64, bary (n, 3) float64): ``n`` random
    /// surface points, uniform by area and seeded (the points ``wavg bench roundtrip
    /// --seed S`` draws with seed ``S + 1``).
    #[pyo3(signature = (n, seed=Int::of(0)), text_signature = "($self, n, seed=0)")]
    fn sample_points<'py>(
        &self,
        py: Python<'py>,
        n: Int,
        seed: Int,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let n = n.within("n", 0, MAX_POINTS as i128)? as usize;
        let seed = seed.seed("seed")?;
        let mesh = self.inner.mesh();
        let (faces, bary) = py
            .detach_run(|| {
                let pts = wavg::sampling::uniform_surface_points(mesh, n, seed)?;
                let faces: Vec<i64> = pts.iter().map(|p| i64::from(p.face)).collect();
                let bary: Vec<f64> = pts.iter().flat_map(|p| p.bary).collect();
                Ok((faces, bary))
            })
            .map_err(|e: wavg::SolveError| to_py(py, e.into()))?;
        Ok((array(py, faces, &[n])?, array(py, bary, &[n, 3])?))
    }

    fn __repr__(&self) -> String {
        format!(
            "wavg.Surface({} vertices, {} faces, {})",
            self.inner.n_vertices(),
            self.inner.n_faces(),
            if self.inner.has_embedding() {
                "embedded"
            } else {
                "no embedding"
            }
        )
    }

    /// Pickling: the mesh arrays and the embedding's `.wavg` bytes.
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let (v, f) = mesh_arrays(py, self.inner.mesh().mesh())?;
        let uv = self.uv(py)?;
        let emb = embedding_bytes(py, &self.inner)?.map(|b| PyBytes::new(py, &b));
        let restore = py.import("wavg._wavg")?.getattr("_restore_surface")?;
        // The file's polygons, so that a wireframe still leaves out triangulation edges.
        let polygons = (!self.polygons.is_empty()).then(|| self.polygons.to_vec());
        Ok((
            restore,
            PyTuple::new(
                py,
                [
                    v,
                    f,
                    uv.into_pyobject(py)?.into_any(),
                    emb.into_pyobject(py)?.into_any(),
                    polygons.into_pyobject(py)?.into_any(),
                ],
            )?,
        ))
    }

    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Self {
        // Immutable mesh and embedding are shared; later changes replace them.
        Self {
            inner: self.inner.clone(),
            polygons: self.polygons.clone(),
            source: self.source.clone(),
            busy: Busy::default(),
        }
    }

    fn __copy__(&self) -> Self {
        Self {
            inner: self.inner.clone(),
            polygons: self.polygons.clone(),
            source: self.source.clone(),
            busy: Busy::default(),
        }
    }
}

/// Rebuilds a pickled surface.
#[pyfunction]
#[pyo3(signature = (v, f, uv, embedding, polygons=None))]
pub(crate) fn _restore_surface(
    py: Python<'_>,
    v: &Bound<'_, PyAny>,
    f: &Bound<'_, PyAny>,
    uv: &Bound<'_, PyAny>,
    embedding: Option<&[u8]>,
    polygons: Option<Vec<u32>>,
) -> PyResult<Surface> {
    let mut s = Surface::new(py, v, f, Some(uv))?;
    if let Some(p) = polygons {
        if p.len() != s.inner.n_faces() {
            return Err(value(format!(
                "the pickled surface has {} polygon ids for {} triangles",
                p.len(),
                s.inner.n_faces()
            )));
        }
        s.polygons = std::sync::Arc::new(p);
    }
    if let Some(bytes) = embedding {
        let inner = &mut s.inner;
        py.detach_run(|| -> wavg::Result<()> {
            let e = wavg::embed::file::decode(
                bytes,
                inner.mesh().mesh(),
                std::path::Path::new("<pickle>"),
            )?;
            inner.set_embedding(e)
        })
        .map_err(|e| to_py(py, e))?;
    }
    Ok(s)
}
