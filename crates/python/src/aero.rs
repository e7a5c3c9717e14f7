//! Bindings of paritysim-aero (functions prefixed `aero_`).

use pyo3::prelude::*;

/// Adds the aero functions to the module.
pub fn register(_m: &Bound<'_, PyModule>) -> PyResult<()> {
    Ok(())
}
