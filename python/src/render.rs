//! `wavg.render`: a picture of a surface with curves, points and a colouring.

use numpy::PyUntypedArrayMethods;
use pyo3::prelude::*;

use crate::pool::DetachRun;
use wavg::Vector3;
use wavg::apps::{Colouring, Overlays, RenderOptions, View};

use crate::args::{Int, data, reals};
use crate::errors::{lib, value};
use crate::image::{image_arg, size_arg, to_array};
use crate::surface::Surface;

/// 3-D points of a curve or point set: an `(p, 3)` array, or a `wavg.Points` (its answered
/// rows).
fn xyz_rows(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<Vector3<f64>>> {
    let obj = if obj.hasattr("xyz")? && obj.hasattr("ok")? {
        obj.getattr("xyz")?
    } else {
        obj.clone()
    };
    let a = reals(
        &obj,
        name,
        2,
        &[Some(3)],
        "a (p, 3) array of float 3-D points or a wavg.Points",
    )?;
    Ok(data(&a)
        .chunks_exact(3)
        .map(|p| Vector3::new(p[0], p[1], p[2]))
        .filter(|p| p.iter().all(|x| x.is_finite()))
        .collect())
}

/// render(S, size=(800, 600), view=(35, 20), curves=(), points=None, texture=None,
/// scalar=None, wireframe=False) -> (H, W, 4) uint8
///
/// A shaded picture of the surface seen from ``view`` = (azimuth, elevation) in degrees,
/// ``size`` = (width, height) pixels. ``curves``: polylines, each a ``(p, 3)`` array or a
/// ``wavg.Points`` (unanswered rows skipped); ``points``: ``(p, 3)`` dots; ``texture``: an
/// ``(H, W, 3|4)`` uint8 image through the surface's texture coordinates; ``scalar``: one
/// float per vertex ``(n,)`` coloured with viridis; ``wireframe``: the polygons' edges (a
/// surface opened from a file with quads leaves out their diagonals). Save it with
/// ``wavg.save_png``.
#[pyfunction]
#[pyo3(
    signature = (S, size=(Int::of(800), Int::of(600)), view=(35.0, 20.0), curves=None, points=None, texture=None, scalar=None, wireframe=false),
    text_signature = "(S, size=(800, 600), view=(35, 20), curves=(), points=None, texture=None, scalar=None, wireframe=False)"
)]
#[allow(non_snake_case, clippy::too_many_arguments)]
pub(crate) fn render<'py>(
    py: Python<'py>,
    S: PyRef<'py, Surface>,
    size: (Int, Int),
    view: (f64, f64),
    curves: Option<&Bound<'py, PyAny>>,
    points: Option<&Bound<'py, PyAny>>,
    texture: Option<&Bound<'py, PyAny>>,
    scalar: Option<&Bound<'py, PyAny>>,
    wireframe: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let (width, height) = size_arg(size, "size")?;
    if !(view.0.is_finite() && view.1.is_finite() && (-90.0..=90.0).contains(&view.1)) {
        return Err(value(format!(
            "view must be (azimuth, elevation) in degrees, elevation -90 to 90; got {view:?}"
        )));
    }
    let mut overlays = Overlays {
        polygons: S.polygons.to_vec(),
        ..Default::default()
    };
    if let Some(c) = curves.filter(|c| !c.is_none()) {
        for (i, curve) in c.try_iter()?.enumerate() {
            overlays
                .curves
                .push(xyz_rows(&curve?, &format!("curves[{i}]"))?);
        }
    }
    if let Some(p) = points.filter(|p| !p.is_none()) {
        overlays.points = xyz_rows(p, "points")?;
    }
    if texture.is_some_and(|t| !t.is_none()) && scalar.is_some_and(|s| !s.is_none()) {
        return Err(value("give texture or scalar, not both"));
    }
    let mesh = S.inner.mesh().clone();
    let tex = texture
        .filter(|t| !t.is_none())
        .map(|t| image_arg(t, "texture"))
        .transpose()?;
    let sc = match scalar.filter(|s| !s.is_none()) {
        Some(s) => {
            let a = reals(
                s,
                "scalar",
                1,
                &[],
                "an (n,) array of float values, one per vertex",
            )?;
            if a.shape()[0] != mesh.n_vertices() {
                return Err(value(format!(
                    "scalar must have one value per vertex: shape ({},); got {:?}",
                    mesh.n_vertices(),
                    a.shape()
                )));
            }
            Some(data(&a).to_vec())
        }
        None => None,
    };
    let colouring = match (&tex, &sc) {
        (Some(t), _) => Colouring::Texture(t),
        (_, Some(s)) => Colouring::Scalars(s),
        _ => Colouring::Plain,
    };
    let opts = RenderOptions {
        width,
        height,
        view: View {
            azimuth: view.0,
            elevation: view.1,
        },
        wireframe,
        ..Default::default()
    };
    let img = py
        .detach_run(|| wavg::apps::render(mesh.mesh(), &colouring, &overlays, &opts))
        .map_err(lib(py))?;
    to_array(py, &img)
}
