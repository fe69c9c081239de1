//! Arguments from Python: any array-like of a suitable dtype becomes a C-contiguous NumPy
//! array of `float64` or `int64` (a copy only when the dtype or the layout differ), checked
//! for shape; errors name the argument and the expected shape and dtype.

use numpy::{PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyDict;

use crate::errors::{type_error, value};

static NUMPY: PyOnceLock<Py<PyModule>> = PyOnceLock::new();

/// The `numpy` module.
pub(crate) fn numpy(py: Python<'_>) -> PyResult<&Bound<'_, PyModule>> {
    Ok(NUMPY
        .get_or_try_init(py, || py.import("numpy").map(Into::into))?
        .bind(py))
}

/// Element kinds an argument accepts.
#[derive(Clone, Copy, PartialEq)]
enum Kind {
    /// Floating point or integer (converted to float64).
    Real,
    /// Integer (converted to int64).
    Int,
}

/// `obj` as a C-contiguous array, after checking its dtype kind.
fn coerce<'py, T: numpy::Element>(
    obj: &Bound<'py, PyAny>,
    name: &str,
    kind: Kind,
    expected: &str,
) -> PyResult<PyReadonlyArrayDyn<'py, T>> {
    let py = obj.py();
    let np = numpy(py)?;
    let arr = np
        .call_method1("asarray", (obj,))
        .map_err(|e| type_error(format!("{name} must be {expected}: {e}")))?;
    let dtype = arr.getattr("dtype")?;
    let k: String = dtype.getattr("kind")?.extract()?;
    let ok = match kind {
        Kind::Real => matches!(k.as_str(), "f" | "i" | "u"),
        Kind::Int => matches!(k.as_str(), "i" | "u"),
    };
    if !ok {
        return Err(type_error(format!(
            "{name} must be {expected}; got an array of dtype {dtype}"
        )));
    }
    if k == "u"
        && kind == Kind::Int
        && arr
            .call_method0("max")
            .is_ok_and(|m| m.extract::<u64>().is_ok_and(|m| m > i64::MAX as u64))
    {
        return Err(value(format!("{name} holds an index too large for int64")));
    }
    let kwargs = PyDict::new(py);
    kwargs.set_item(
        "dtype",
        if kind == Kind::Real {
            "float64"
        } else {
            "int64"
        },
    )?;
    let c = np.call_method("ascontiguousarray", (arr,), Some(&kwargs))?;
    let mut c = c.cast_into::<PyArrayDyn<T>>().map_err(PyErr::from)?;
    // `ascontiguousarray` keeps an unaligned array (a view at an odd byte offset of a
    // buffer, a field of a packed record) as it is, and no slice can be made of one: copy
    // it into an aligned array.
    if !c.is_aligned() {
        c = c
            .call_method0("copy")?
            .cast_into::<PyArrayDyn<T>>()
            .map_err(PyErr::from)?;
    }
    Ok(c.readonly())
}

/// A float64 array of `ndim` dimensions whose trailing dimensions are `tail` (`None`: any).
pub(crate) fn reals<'py>(
    obj: &Bound<'py, PyAny>,
    name: &str,
    ndim: usize,
    tail: &[Option<usize>],
    expected: &str,
) -> PyResult<PyReadonlyArrayDyn<'py, f64>> {
    let a = coerce::<f64>(obj, name, Kind::Real, expected)?;
    check_shape(&a, name, ndim, tail, expected)?;
    Ok(a)
}

/// An int64 array, as [`reals`].
pub(crate) fn ints<'py>(
    obj: &Bound<'py, PyAny>,
    name: &str,
    ndim: usize,
    tail: &[Option<usize>],
    expected: &str,
) -> PyResult<PyReadonlyArrayDyn<'py, i64>> {
    let a = coerce::<i64>(obj, name, Kind::Int, expected)?;
    check_shape(&a, name, ndim, tail, expected)?;
    Ok(a)
}

fn check_shape<T: numpy::Element>(
    a: &PyReadonlyArrayDyn<'_, T>,
    name: &str,
    ndim: usize,
    tail: &[Option<usize>],
    expected: &str,
) -> PyResult<()> {
    let shape = a.shape();
    let tail_ok = shape.len() == ndim
        && shape[1..]
            .iter()
            .zip(tail)
            .all(|(s, t)| t.is_none_or(|t| *s == t));
    if tail_ok {
        Ok(())
    } else {
        Err(value(format!(
            "{name} must be {expected}; got an array of shape {shape:?}"
        )))
    }
}

/// The contiguous data of a coerced array.
pub(crate) fn data<'a, T: numpy::Element>(a: &'a PyReadonlyArrayDyn<'_, T>) -> &'a [T] {
    // Coerced arrays are C-contiguous and aligned.
    a.as_slice().unwrap_or(&[])
}

/// `values` as indices below `bound` (`what` names them in errors).
pub(crate) fn indices(values: &[i64], bound: usize, what: &str) -> PyResult<Vec<u32>> {
    values
        .iter()
        .enumerate()
        .map(|(i, &x)| {
            if x >= 0 && (x as u64) < bound as u64 {
                Ok(x as u32)
            } else {
                Err(value(format!(
                    "{what}[{i}] = {x} is out of range: must be in 0..{bound}"
                )))
            }
        })
        .collect()
}

/// Rejects NaN and infinite values (`what` names them).
pub(crate) fn finite(values: &[f64], what: &str) -> PyResult<()> {
    match values.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) => Err(value(format!(
            "{what} must be finite; element {} (flat, counting from 1, as every message \
             does) is {}",
            i + 1,
            values[i]
        ))),
    }
}

/// A thread count: `None` is all cores (the current rayon pool), 1 the calling thread, at
/// most [`wavg::Par::max_threads`].
pub(crate) fn par(threads: Option<Int>) -> PyResult<wavg::Par> {
    let Some(n) = threads else {
        return Ok(wavg::Par::Rayon);
    };
    let max = wavg::Par::max_threads();
    let n = match n.0 {
        Ok(v) if (1..=max as i128).contains(&v) => v,
        Ok(_) => {
            return Err(value(format!(
                "threads must be None (all cores) or an integer from 1 to {max} (4 per CPU, \
                 at least 64: more only add overhead), got {n}"
            )));
        }
        Err(_) => n.within("threads", 1, max as i128)?,
    };
    wavg::Par::from_threads(Some(n as usize)).map_err(|e| value(format!("threads: {e}")))
}

/// An integer argument as given: any Python `int` (or object with `__index__`), a value
/// beyond 128 bits kept as the nearest 128-bit one, or the type name of anything else
/// (`bool` included), so that the function taking it checks the range and the type with
/// messages naming the argument.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Int(Result<i128, String>);

impl std::fmt::Display for Int {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.0 {
            Ok(i128::MAX) => f.write_str("a larger number"),
            Ok(i128::MIN) => f.write_str("a more negative number"),
            Ok(v) => write!(f, "{v}"),
            Err(t) => write!(f, "a {t}"),
        }
    }
}

impl FromPyObject<'_, '_> for Int {
    type Error = PyErr;

    fn extract(obj: pyo3::Borrowed<'_, '_, PyAny>) -> PyResult<Self> {
        let type_name = || {
            obj.get_type()
                .name()
                .map_or_else(|_| "value".to_owned(), |n| n.to_string())
        };
        if obj.is_instance_of::<pyo3::types::PyBool>() {
            return Ok(Int(Err(type_name())));
        }
        match obj.extract::<i128>() {
            Ok(v) => Ok(Int(Ok(v))),
            Err(e) if e.is_instance_of::<pyo3::exceptions::PyOverflowError>(obj.py()) => {
                let negative = obj.lt(0i32)?;
                Ok(Int(Ok(if negative { i128::MIN } else { i128::MAX })))
            }
            Err(_) => Ok(Int(Err(type_name()))),
        }
    }
}

impl Int {
    /// The integer, when one was given.
    pub(crate) fn value(&self) -> Option<i128> {
        self.0.as_ref().ok().copied()
    }

    /// A value given in Rust (a default).
    pub(crate) const fn of(v: i128) -> Self {
        Int(Ok(v))
    }

    /// The value when it is an integer in `lo..=hi`; otherwise a `TypeError` or
    /// `ValueError` naming `name`.
    pub(crate) fn within(&self, name: &str, lo: i128, hi: i128) -> PyResult<i128> {
        match self.0 {
            Ok(v) if (lo..=hi).contains(&v) => Ok(v),
            Ok(_) => Err(value(format!(
                "{name} must be an integer from {lo} to {hi}, got {self}"
            ))),
            Err(_) => Err(type_error(format!("{name} must be an integer, got {self}"))),
        }
    }

    /// A seed: any integer from 0 to 2^64 - 1.
    pub(crate) fn seed(&self, name: &str) -> PyResult<u64> {
        Ok(self.within(name, 0, u64::MAX as i128)? as u64)
    }
}

/// A new read-only NumPy array of `shape` holding `v`.
pub(crate) fn array<'py, T: numpy::Element>(
    py: Python<'py>,
    v: Vec<T>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    let a = numpy::ndarray::ArrayD::from_shape_vec(shape.to_vec(), v)
        .map_err(|e| value(format!("internal shape error: {e}")))?;
    let a = numpy::PyArray::from_owned_array(py, a).into_any();
    Ok(a)
}
