//! The applications with the names of the commands: `spline`, `correspond`, `decal`,
//! `transfer_texture` (rendering and remeshing are in their own modules).

use numpy::PyUntypedArrayMethods;
use pyo3::prelude::*;

use crate::pool::DetachRun;
use wavg::apps::{
    CorrespondOptions, Image, SplineKind, TransferOptions, ValidityTest, correspond_vertices,
    decal_vertex_uv, evaluate_spline,
};

use crate::args::{Int, array, data, finite, par, reals};
use crate::errors::{lib, to_py, value};
use crate::solver::{anchors, named_tuple, points_tuple};
use crate::surface::Surface;
use crate::{image, remesh, render};

/// Adds the applications to the module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(spline, m)?)?;
    m.add_function(wrap_pyfunction!(correspond, m)?)?;
    m.add_function(wrap_pyfunction!(decal, m)?)?;
    m.add_function(wrap_pyfunction!(transfer_texture, m)?)?;
    m.add_function(wrap_pyfunction!(render::render, m)?)?;
    m.add_function(wrap_pyfunction!(image::save_png, m)?)?;
    m.add_function(wrap_pyfunction!(image::read_png, m)?)?;
    m.add_class::<remesh::Remesher>()?;
    Ok(())
}

/// A solver on `s` for the anchors `obj` (vertex ids or `(faces, bary)`).
fn solver_for(
    py: Python<'_>,
    s: &wavg::Surface,
    obj: &Bound<'_, PyAny>,
    name: &str,
) -> PyResult<wavg::Solver> {
    let a = anchors(s, obj, name)?;
    if a.is_empty() {
        return Err(value(format!(
            "{name} must hold at least one anchor; got none"
        )));
    }
    py.detach_run(|| s.solver(a)).map_err(|e| to_py(py, e))
}

/// spline(S, control, samples=500, degree=3, closed=False, bezier=False, threads=None) -> Points
///
/// A curve on the surface through the control points ``control`` (``(k,)`` vertex ids or
/// ``(faces (k,), bary (k, 3))``), in order: a uniform B-spline of ``degree`` (clamped,
/// or periodic with ``closed``), or with ``bezier`` a Bézier curve of degree ``k - 1``.
/// Returns ``samples`` points uniform in the curve parameter as ``wavg.Points``
/// (``face (samples,)``, ``bary``, ``xyz (samples, 3)``, ``ok``).
#[pyfunction]
#[pyo3(
    signature = (S, control, samples=Int::of(wavg::apps::DEFAULT_SPLINE_SAMPLES as i128), degree=Int::of(wavg::apps::DEFAULT_SPLINE_DEGREE as i128), closed=false, bezier=false, threads=None),
    text_signature = "(S, control, samples=500, degree=3, closed=False, bezier=False, threads=None)"
)]
#[allow(non_snake_case, clippy::too_many_arguments)]
fn spline<'py>(
    py: Python<'py>,
    S: PyRef<'py, Surface>,
    control: &Bound<'py, PyAny>,
    samples: Int,
    degree: Int,
    closed: bool,
    bezier: bool,
    threads: Option<Int>,
) -> PyResult<Bound<'py, PyAny>> {
    let samples = samples.within("samples", 1, 10_000_000)?;
    let degree = degree.within("degree", 1, 64)?;
    let solver = solver_for(py, &S.inner, control, "control")?;
    let kind = if bezier {
        SplineKind::Bezier
    } else {
        SplineKind::BSpline {
            degree: degree as usize,
            closed,
        }
    };
    let par = par(threads)?;
    let curve = py
        .detach_run(|| {
            par.install(|| {
                evaluate_spline(&solver, kind, samples as usize, wavg::apps::SPLINE_CHUNK)
            })
        })
        .map_err(lib(py))?
        .map_err(lib(py))?;
    points_tuple(py, &curve.samples, false)
}

/// correspond(src, dst, src_anchors, dst_anchors, validity="local", verified=True,
/// max_negative=-0.1, max_stretch=4.0, threads=None) -> Correspondence
///
/// Maps every vertex of ``src`` onto ``dst`` (both embedded ``Surface``s) through paired
/// anchors (anchor ``i`` of ``src_anchors`` corresponds to anchor ``i`` of
/// ``dst_anchors``): the inverse problem on the source, the forward problem on the target.
/// ``validity``: ``"local"`` (the image agrees with its neighbours' and the weights
/// round-trip) or ``"paper"`` (the weights round-trip and none is below
/// ``max_negative``). Returns ``wavg.Correspondence(face (n,), bary (n, 3), xyz (n, 3),
/// valid (n,), reason (n,), report)``; ``report`` has the keys of
/// ``wavg correspond --json``.
#[pyfunction]
#[pyo3(
    signature = (src, dst, src_anchors, dst_anchors, validity="local", verified=true, max_negative=CorrespondOptions::default().max_negative, max_stretch=CorrespondOptions::default().max_stretch, threads=None),
    text_signature = "(src, dst, src_anchors, dst_anchors, validity=\"local\", verified=True, max_negative=-0.1, max_stretch=4.0, threads=None)"
)]
#[allow(clippy::too_many_arguments)]
fn correspond<'py>(
    py: Python<'py>,
    src: PyRef<'py, Surface>,
    dst: PyRef<'py, Surface>,
    src_anchors: &Bound<'py, PyAny>,
    dst_anchors: &Bound<'py, PyAny>,
    validity: &str,
    verified: bool,
    max_negative: f64,
    max_stretch: f64,
    threads: Option<Int>,
) -> PyResult<Bound<'py, PyAny>> {
    let test = match validity {
        "local" => ValidityTest::Local,
        "paper" => ValidityTest::Paper,
        other => {
            return Err(value(format!(
                "validity must be \"local\" or \"paper\", got {other:?}"
            )));
        }
    };
    let opts = CorrespondOptions {
        verified,
        max_negative,
        test,
        max_stretch,
    };
    opts.check().map_err(|e| value(e.to_string()))?;
    let ss = solver_for(py, &src.inner, src_anchors, "src_anchors")?;
    let ts = solver_for(py, &dst.inner, dst_anchors, "dst_anchors")?;
    if ss.n_anchors() != ts.n_anchors() {
        return Err(value(format!(
            "src_anchors has {} anchors and dst_anchors {}; they are paired and must agree",
            ss.n_anchors(),
            ts.n_anchors()
        )));
    }
    let par = par(threads)?;
    let t = std::time::Instant::now();
    let map = py
        .detach_run(|| par.install(|| correspond_vertices(&ss, &ts, &opts)))
        .map_err(lib(py))?
        .map_err(lib(py))?;
    let seconds = t.elapsed().as_secs_f64();
    let n = map.mapped.len();
    let mut face = Vec::with_capacity(n);
    let mut bary = Vec::with_capacity(3 * n);
    let mut xyz = Vec::with_capacity(3 * n);
    let mut valid = Vec::with_capacity(n);
    let mut reason = Vec::with_capacity(n);
    for (m, v) in map.mapped.iter().zip(&map.validity) {
        match &m.target {
            Ok(r) => {
                face.push(i64::from(r.point.face));
                bary.extend(r.point.bary);
                xyz.extend([r.position.x, r.position.y, r.position.z]);
            }
            Err(_) => {
                face.push(-1);
                bary.extend([f64::NAN; 3]);
                xyz.extend([f64::NAN; 3]);
            }
        }
        valid.push(*v == wavg::apps::Validity::Valid);
        reason.push(v.reason());
    }
    let valid_count = map.valid();
    let mut report = serde_json::Map::new();
    for part in [
        serde_json::to_value(&map.distortion),
        serde_json::to_value(map.timings),
    ] {
        if let Ok(serde_json::Value::Object(o)) = part {
            report.extend(o);
        }
    }
    let extra = serde_json::json!({
        "source": null,
        "target": null,
        "anchors": ss.n_anchors(),
        "source_vertices": n,
        "valid": valid_count,
        "valid_fraction": map.valid_fraction(),
        "validity": validity,
        "verified": verified,
        "reasons": map.reason_counts(),
        "seconds": seconds,
        "setup_seconds": 0.0,
        "vertices_per_s": n as f64 / seconds.max(1e-12),
        "cpu_seconds": null,
        "vertices_per_cpu_s": null,
        "ground_truth": null,
    });
    if let serde_json::Value::Object(o) = extra {
        report.extend(o);
    }
    let report = crate::json::to_py(py, &report)?;
    let np = crate::args::numpy(py)?;
    let reason = np.call_method1("array", (reason,))?;
    named_tuple(py, "Correspondence")?.call1((
        array(py, face, &[n])?,
        array(py, bary, &[n, 3])?,
        array(py, xyz, &[n, 3])?,
        array(py, valid, &[n])?,
        reason,
        report,
    ))
}

/// decal(S, anchors, uv, max_negative=-0.1, threads=None) -> (uv (n, 2) float64, valid (n,) bool)
///
/// Places a decal: anchor ``i`` (``(k,)`` vertex ids or ``(faces, bary)``) gets the
/// texture coordinates ``uv[i]`` (``(k, 2)`` float), and every vertex gets the weighted
/// combination with its inverse-problem weights. ``valid`` is False where the weights do
/// not round-trip or one is below ``max_negative`` (``uv`` is then NaN).
#[pyfunction]
#[pyo3(signature = (S, anchors, uv, max_negative=wavg::apps::DEFAULT_MAX_NEGATIVE, threads=None))]
#[allow(non_snake_case)]
fn decal<'py>(
    py: Python<'py>,
    S: PyRef<'py, Surface>,
    anchors: &Bound<'py, PyAny>,
    uv: &Bound<'py, PyAny>,
    max_negative: f64,
    threads: Option<Int>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let solver = solver_for(py, &S.inner, anchors, "anchors")?;
    let k = solver.n_anchors();
    let ua = reals(
        uv,
        "uv",
        2,
        &[Some(2)],
        &format!("a ({k}, 2) array of float texture coordinates"),
    )?;
    if ua.shape()[0] != k {
        return Err(value(format!(
            "uv must be a ({k}, 2) array (one (u, v) per anchor); got shape {:?}",
            ua.shape()
        )));
    }
    finite(data(&ua), "uv")?;
    wavg::apps::check_max_negative(max_negative).map_err(|e| value(e.to_string()))?;
    let pairs: Vec<[f64; 2]> = data(&ua).chunks_exact(2).map(|c| [c[0], c[1]]).collect();
    let par = par(threads)?;
    let d = py
        .detach_run(|| par.install(|| decal_vertex_uv(&solver, &pairs, max_negative)))
        .map_err(lib(py))?
        .map_err(lib(py))?;
    let n = d.uv.len();
    let mut out = Vec::with_capacity(2 * n);
    let mut valid = Vec::with_capacity(n);
    for (p, &m) in d.uv.iter().zip(&d.marked) {
        if m {
            out.extend([f64::NAN; 2]);
        } else {
            out.extend(*p);
        }
        valid.push(!m);
    }
    Ok((array(py, out, &[n, 2])?, array(py, valid, &[n])?))
}

/// transfer_texture(src, src_texture, dst, src_anchors, dst_anchors, size=None,
/// verified=True, stride=4, threads=None) -> (H, W, 4) uint8
///
/// Transfers ``src_texture`` (``(H, W, 3|4)`` uint8 image on the source's texture
/// coordinates, or a PNG path) onto the target's texture layout through paired anchors.
/// Both surfaces need texture coordinates (``Surface.open`` of an .obj with ``vt``, or
/// ``Surface(V, F, uv=...)``). ``size``: ``(W, H)`` of the result (default: the source
/// texture's). Texels nothing maps to have alpha 0.
#[pyfunction]
#[pyo3(signature = (src, src_texture, dst, src_anchors, dst_anchors, size=None, verified=true, stride=Int::of(TransferOptions::default().stride as i128), threads=None), text_signature = "(src, src_texture, dst, src_anchors, dst_anchors, size=None, verified=True, stride=4, threads=None)")]
#[allow(clippy::too_many_arguments)]
fn transfer_texture<'py>(
    py: Python<'py>,
    src: PyRef<'py, Surface>,
    src_texture: &Bound<'py, PyAny>,
    dst: PyRef<'py, Surface>,
    src_anchors: &Bound<'py, PyAny>,
    dst_anchors: &Bound<'py, PyAny>,
    size: Option<(Int, Int)>,
    verified: bool,
    stride: Int,
    threads: Option<Int>,
) -> PyResult<Bound<'py, PyAny>> {
    let texture: Image = image::image_arg(src_texture, "src_texture")?;
    let (width, height) = match size {
        None => (texture.width, texture.height),
        Some(s) => image::size_arg(s, "size")?,
    };
    let stride = stride.within("stride", 1, wavg::apps::MAX_STRIDE.into())?;
    let ss = solver_for(py, &src.inner, src_anchors, "src_anchors")?;
    let ts = solver_for(py, &dst.inner, dst_anchors, "dst_anchors")?;
    let opts = TransferOptions {
        width,
        height,
        verified,
        stride: stride as u32,
        ..Default::default()
    };
    let par = par(threads)?;
    let out = py
        .detach_run(|| {
            par.install(|| wavg::apps::transfer_texture(&ss, &texture, &ts, &opts, &|_, _| {}))
        })
        .map_err(lib(py))?
        .map_err(lib(py))?;
    image::to_array(py, &out.image)
}
