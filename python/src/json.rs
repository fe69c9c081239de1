//! Reports to Python: any serialisable report becomes a `dict` with the CLI's JSON keys.

use pyo3::prelude::*;

use crate::errors::value;

/// `report` as a Python object through JSON (NaN and infinities become None).
pub(crate) fn to_py<T: serde::Serialize>(py: Python<'_>, report: &T) -> PyResult<Py<PyAny>> {
    let text = serde_json::to_string(report).map_err(|e| value(format!("report: {e}")))?;
    Ok(py.import("json")?.call_method1("loads", (text,))?.unbind())
}
