//! Bindings of paritysim-laminate (functions prefixed `laminate_`).

use pyo3::prelude::*;

/// Adds the laminate functions to the module.
pub fn register(_m: &Bound<'_, PyModule>) -> PyResult<()> {
    Ok(())
}
