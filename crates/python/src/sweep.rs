//! Bindings for the sweep functions (prefix `sweep_`).

use pyo3::prelude::*;

/// Adds the sweep functions to the module.
pub fn register(_m: &Bound<'_, PyModule>) -> PyResult<()> {
    Ok(())
}
