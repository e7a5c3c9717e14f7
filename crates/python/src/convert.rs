//! numpy <-> Rust helpers.

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use paritysim_error::Error;
use pyo3::prelude::*;

/// A contiguous copy-free view if possible, else an owned copy.
pub fn to_vec(a: &PyReadonlyArray1<'_, f64>) -> Vec<f64> {
    match a.as_slice() {
        Ok(s) => s.to_vec(),
        Err(_) => a.as_array().iter().copied().collect(),
    }
}

/// Requires equal lengths, naming both arguments.
pub fn same_len(a: (&str, usize), b: (&str, usize)) -> Result<(), Error> {
    if a.1 != b.1 {
        return Err(Error::Shape(format!(
            "`{}` has {} elements but `{}` has {}; they must match",
            a.0, a.1, b.0, b.1
        )));
    }
    Ok(())
}

/// Builds an `(n, d1, d2, ...)` array from a flat vector without copying it again.
pub fn shaped<'py>(
    py: Python<'py>,
    flat: Vec<f64>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    let a = PyArray1::from_vec(py, flat);
    Ok(a.reshape(shape.to_vec())?.into_any())
}
