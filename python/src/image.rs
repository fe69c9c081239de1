//! Images between NumPy `(H, W, 4)` uint8 arrays and the library's RGBA images, and PNG
//! files.

use std::path::PathBuf;

use numpy::{PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use wavg::apps::{Image, MAX_SIDE};

use crate::args::{Int, array};
use crate::errors::{lib, raise, require_file, type_error, value};
use crate::pool::DetachRun;

/// An image argument: an `(H, W, 3)` or `(H, W, 4)` uint8 array (or a PNG path).
pub(crate) fn image_arg(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Image> {
    let py = obj.py();
    if let Ok(path) = obj.extract::<PathBuf>() {
        require_file(&path)?;
        return py.detach_run(|| Image::read_png(&path)).map_err(lib(py));
    }
    let expected = "an (H, W, 3) or (H, W, 4) uint8 image array (or a PNG path)";
    let np = crate::args::numpy(py)?;
    let arr = np
        .call_method1("asarray", (obj,))
        .map_err(|e| type_error(format!("{name} must be {expected}: {e}")))?;
    let dtype: String = arr.getattr("dtype")?.str()?.extract()?;
    if dtype != "uint8" {
        return Err(type_error(format!(
            "{name} must be {expected}; got dtype {dtype}"
        )));
    }
    let arr = np.call_method1("ascontiguousarray", (arr,))?;
    let arr = arr.cast_into::<PyArrayDyn<u8>>().map_err(PyErr::from)?;
    let ro = arr.readonly();
    let shape = ro.shape().to_vec();
    if shape.len() != 3 || !(shape[2] == 3 || shape[2] == 4) {
        return Err(value(format!(
            "{name} must be {expected}; got shape {shape:?}"
        )));
    }
    let (h, w, c) = (shape[0], shape[1], shape[2]);
    if !(1..=MAX_SIDE as usize).contains(&h) || !(1..=MAX_SIDE as usize).contains(&w) {
        return Err(value(format!(
            "{name} must be 1 to {MAX_SIDE} pixels on each side; got {w} x {h}"
        )));
    }
    let px = ro.as_slice().unwrap_or(&[]);
    let pixels = px
        .chunks_exact(c)
        .map(|p| {
            if c == 4 {
                [p[0], p[1], p[2], p[3]]
            } else {
                [p[0], p[1], p[2], 255]
            }
        })
        .collect();
    Ok(Image {
        width: w as u32,
        height: h as u32,
        pixels,
    })
}

/// `(W, H)` of a picture.
pub(crate) fn size_arg(s: (Int, Int), name: &str) -> PyResult<(u32, u32)> {
    let max = i128::from(MAX_SIDE);
    let w = s.0.within(&format!("{name}[0] (width)"), 1, max)?;
    let h = s.1.within(&format!("{name}[1] (height)"), 1, max)?;
    Ok((w as u32, h as u32))
}

/// An image as an `(H, W, 4)` uint8 array.
pub(crate) fn to_array<'py>(py: Python<'py>, img: &Image) -> PyResult<Bound<'py, PyAny>> {
    let v: Vec<u8> = img.pixels.iter().flatten().copied().collect();
    array(py, v, &[img.height as usize, img.width as usize, 4])
}

/// save_png(path, image): writes an ``(H, W, 3|4)`` uint8 image as a PNG file
/// (atomically: a temporary file renamed into place).
#[pyfunction]
pub(crate) fn save_png(py: Python<'_>, path: PathBuf, image: &Bound<'_, PyAny>) -> PyResult<()> {
    let img = image_arg(image, "image")?;
    py.detach_run(|| -> Result<(), String> {
        let mut bytes = Vec::new();
        img.encode_png(&mut bytes).map_err(|e| e.to_string())?;
        let dir = path
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(std::path::Path::new("."));
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
        std::fs::write(&tmp, &bytes)
            .and_then(|_| std::fs::rename(&tmp, &path))
            .map_err(|e| {
                let _ = std::fs::remove_file(&tmp);
                format!("{}: {e}", path.display())
            })
    })
    .map_err(|m| raise(py, "WavgIOError", m))
}

/// read_png(path) -> (H, W, 4) uint8: reads a PNG file as RGBA.
#[pyfunction]
pub(crate) fn read_png<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyAny>> {
    require_file(&path)?;
    let img = py.detach_run(|| Image::read_png(&path)).map_err(lib(py))?;
    to_array(py, &img)
}
