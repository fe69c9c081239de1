//! Python exceptions for the library's errors. The classes live in `wavg._errors` (Python,
//! so that `InvalidMeshError` can derive from both `WavgError` and `ValueError`); this
//! module maps [`wavg::Error`] onto them.

use std::path::Path;

use pyo3::exceptions::{PyFileNotFoundError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyList;
use wavg::{Error, ErrorKind, MeshError};

static ERRORS: PyOnceLock<Py<PyModule>> = PyOnceLock::new();

/// An instance of the exception class `name` of `wavg._errors` with `message`.
pub(crate) fn raise(py: Python<'_>, name: &str, message: String) -> PyErr {
    let make = || -> PyResult<PyErr> {
        let module = ERRORS.get_or_try_init(py, || py.import("wavg._errors").map(Into::into))?;
        let class = module.bind(py).getattr(name)?;
        Ok(PyErr::from_value(class.call1((message.clone(),))?))
    };
    make().unwrap_or_else(|e| e)
}

/// The Python exception for a library error: `InvalidMeshError` (with `.problems`),
/// `InvalidArgumentError` (a `ValueError`), `WavgIOError` (an `OSError`),
/// `NoSolutionError`, `CancelledError`; all derive from `WavgError`.
pub(crate) fn to_py(py: Python<'_>, e: Error) -> PyErr {
    let message = one_line(&e);
    match e.kind() {
        ErrorKind::InvalidMesh => {
            let err = raise(py, "InvalidMeshError", message);
            let problems: Vec<String> = match &e {
                Error::Mesh(MeshError::Invalid(report)) => {
                    report.problems.iter().map(ToString::to_string).collect()
                }
                other => vec![one_line(other)],
            };
            if let Ok(list) = PyList::new(py, problems) {
                let _ = err.value(py).setattr("problems", list);
            }
            err
        }
        ErrorKind::InvalidArgument => raise(py, "InvalidArgumentError", message),
        ErrorKind::Io => raise(py, "WavgIOError", message),
        ErrorKind::NoSolution => raise(py, "NoSolutionError", message),
        ErrorKind::Cancelled => raise(py, "CancelledError", message),
    }
}

/// The `CancelledError` of a computation stopped by its progress callable.
pub(crate) fn cancelled(py: Python<'_>) -> PyErr {
    raise(
        py,
        "CancelledError",
        "cancelled by the progress callback".into(),
    )
}

/// The error and its causes on one line.
pub(crate) fn one_line(e: &dyn std::error::Error) -> String {
    let mut s = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        let c_s = c.to_string();
        if !s.contains(&c_s) {
            s.push_str(": ");
            s.push_str(&c_s);
        }
        cause = c.source();
    }
    s.replace('\n', "; ")
}

/// Converts any library error (of the facade or a layer) to the Python exception.
pub(crate) fn lib<E: Into<Error>>(py: Python<'_>) -> impl Fn(E) -> PyErr + use<'_, E> {
    move |e| to_py(py, e.into())
}

/// `ValueError` naming the argument.
pub(crate) fn value(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}

/// `TypeError` naming the argument.
pub(crate) fn type_error(message: impl Into<String>) -> PyErr {
    PyTypeError::new_err(message.into())
}

/// `FileNotFoundError` when `path` does not exist (checked before reading, so a missing
/// file is told apart from an unreadable one).
pub(crate) fn require_file(path: &Path) -> PyResult<()> {
    if path.exists() {
        Ok(())
    } else {
        Err(PyFileNotFoundError::new_err((
            2,
            "No such file or directory",
            path.to_string_lossy().into_owned(),
        )))
    }
}

/// The Python exception for an error reading, decoding or encoding a PNG image:
/// `WavgIOError` (an `OSError`), as for meshes and embeddings.
pub(crate) fn png(py: Python<'_>, e: &wavg::apps::AppError) -> PyErr {
    match e {
        wavg::apps::AppError::Image(m) => raise(py, "WavgIOError", m.clone()),
        e => app(py, e),
    }
}

/// The Python exception for an application's error (the message with its causes).
pub(crate) fn app(py: Python<'_>, e: &wavg::apps::AppError) -> PyErr {
    raise(py, "InvalidArgumentError", one_line(e))
}

/// The Python exception for a remeshing error.
pub(crate) fn remesh(py: Python<'_>, e: &wavg::apps::RemeshError) -> PyErr {
    let class = if e.is_invalid_mesh() {
        "InvalidMeshError"
    } else if e.is_no_solution() {
        "NoSolutionError"
    } else {
        "InvalidArgumentError"
    };
    raise(py, class, one_line(e))
}
