//! The applications: splines, correspondences, decals, texture transfer, remeshing and
//! rendering.

use pyo3::prelude::*;

/// Adds the applications to the module.
pub(crate) fn register(_m: &Bound<'_, PyModule>) -> PyResult<()> {
    Ok(())
}
