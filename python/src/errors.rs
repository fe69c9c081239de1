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

/// The Python exception for a library error, the one table from error kinds to classes:
/// `InvalidMeshError` (with `.problems`), `InvalidArgumentError` (a `ValueError`),
/// `WavgIOError` (an `OSError`, for failed reads and writes), `NoSolutionError`,
/// `CancelledError`, `OutOfMemoryError` (a `MemoryError`: a precomputation the machine
/// cannot hold, refused before it starts), and `WavgError` itself (the base of them all) for a failure of the
/// library on valid input.
pub(crate) fn to_py(py: Python<'_>, e: Error) -> PyErr {
    let message = e.message();
    match e.kind() {
        ErrorKind::InvalidMesh => {
            let err = raise(py, "InvalidMeshError", message);
            let problems: Vec<String> = match &e {
                Error::Mesh(MeshError::Invalid(report)) => {
                    report.problems.iter().map(ToString::to_string).collect()
                }
                other => vec![other.message()],
            };
            if let Ok(list) = PyList::new(py, problems) {
                let _ = err.value(py).setattr("problems", list);
            }
            err
        }
        ErrorKind::InvalidArgument => raise(py, "InvalidArgumentError", message),
        ErrorKind::Io | ErrorKind::Write => raise(py, "WavgIOError", message),
        ErrorKind::NoSolution => raise(py, "NoSolutionError", message),
        ErrorKind::Cancelled => raise(py, "CancelledError", message),
        ErrorKind::Internal => raise(py, "WavgError", message),
        ErrorKind::OutOfMemory => raise(py, "OutOfMemoryError", message),
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
/// [`require_file`] for a mesh path, whose `#NAME` suffix (one mesh of a glTF file) is not
/// part of the file's name.
pub(crate) fn require_mesh_file(path: &Path) -> PyResult<()> {
    if wavg::builtin_name(path).is_some() {
        return Ok(());
    }
    require_file(&wavg::mesh::io::gltf::split_mesh_name(path).0)
}

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
