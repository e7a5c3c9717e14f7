//! Errors into Python exceptions by one exhaustive `match` ([`class_name`]): a new
//! `paritysim_error::Error` variant does not compile until it has a class.
//!
//! The classes need multiple bases (`ParitysimError` and `ValueError`, ...), so they are plain
//! Python (`paritysim/_exceptions.py`), re-exported here as `paritysim._core.<Name>`.

use paritysim_error::Error;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;

/// The Python module defining the exception classes.
const MODULE: &str = "paritysim._exceptions";

/// The exception class of each error variant: exhaustive, no wildcard.
fn class_name(err: &Error) -> &'static str {
    match err {
        Error::InvalidParameter { .. } | Error::InvalidSpec(_) => "InvalidParameterError",
        Error::OutOfDomain { .. } => "OutOfDomainError",
        Error::Geometry(_) => "GeometryError",
        Error::Shape(_) => "ShapeError",
        Error::Constraint(_) => "ConstraintError",
        Error::Singular(_) => "SingularError",
        Error::Integration { .. } => "IntegrationError",
        Error::Cancelled => "CancelledError",
        Error::Attributed { error, .. } => class_name(error),
    }
}

static CLASSES: PyOnceLock<Py<PyModule>> = PyOnceLock::new();

fn classes(py: Python<'_>) -> PyResult<&Bound<'_, PyModule>> {
    let module = CLASSES.get_or_try_init(py, || Ok::<_, PyErr>(py.import(MODULE)?.unbind()))?;
    Ok(module.bind(py))
}

/// Adds `ParitysimError` and its subclasses to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let classes = classes(m.py())?;
    for name in classes.getattr("__all__")?.extract::<Vec<String>>()? {
        m.add(&name, classes.getattr(&name)?)?;
    }
    Ok(())
}

/// Converts a paritysim error into the matching Python exception, with attributes
/// `kind`, `field` (invalid parameters), `problems` (every `(field, value, allowed)` of an
/// invalid spec) and `time`, `state` (integration failures).
pub fn to_pyerr(err: Error) -> PyErr {
    Python::attach(|py| build(py, &err).unwrap_or_else(|e| e))
}

fn build(py: Python<'_>, err: &Error) -> PyResult<PyErr> {
    let class = classes(py)?.getattr(class_name(err))?;
    let instance = class.call1((err.to_string(),))?;
    instance.setattr("kind", err.kind())?;
    instance.setattr("field", err.field())?;
    if let Error::Attributed {
        field,
        value,
        allowed,
        ..
    } = err
    {
        instance.setattr("problems", vec![(field.to_string(), value, allowed)])?;
    }
    match err.cause() {
        Error::Integration { time, state, .. } => {
            instance.setattr("time", *time)?;
            instance.setattr("state", state.clone())?;
        }
        Error::InvalidSpec(problems) => {
            let list: Vec<(&str, &str, &str)> = problems
                .iter()
                .map(|p| (p.field.as_str(), p.value.as_str(), p.allowed.as_str()))
                .collect();
            instance.setattr("problems", list)?;
        }
        Error::InvalidParameter {
            field,
            value,
            allowed,
        } => {
            instance.setattr("problems", vec![(field.to_string(), value, allowed)])?;
        }
        _ => {}
    }
    Ok(PyErr::from_value(instance))
}

/// `.map_err(to_pyerr)` in one word.
pub trait IntoPyResult<T> {
    /// Converts the error into a Python exception.
    fn py_err(self) -> PyResult<T>;
}

impl<T> IntoPyResult<T> for Result<T, Error> {
    fn py_err(self) -> PyResult<T> {
        self.map_err(to_pyerr)
    }
}
