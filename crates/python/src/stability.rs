//! Bindings for the stability functions (prefix `stability_`).

use pyo3::prelude::*;

/// Adds the stability functions to the module.
pub fn register(_m: &Bound<'_, PyModule>) -> PyResult<()> {
    Ok(())
}
