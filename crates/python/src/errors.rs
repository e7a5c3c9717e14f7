//! The Python exception tree, mirroring `paritysim_error::Error` 1:1.
//!
//! The classes need multiple bases (`ParitysimError` and `ValueError`, ...), which
//! `create_exception!` cannot express, so they are built once with `type(name, bases, ns)`.

use paritysim_error::Error;
use pyo3::exceptions::{PyArithmeticError, PyException, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple, PyType};

/// `(class name, error kind, builtin base, docstring)`; the base class comes first.
const TREE: [(&str, &str, &str, &str); 8] = [
    (
        "InvalidParameterError",
        "InvalidParameter",
        "ValueError",
        "A parameter is non-finite or outside its allowed range; `.field` names it.",
    ),
    (
        "OutOfDomainError",
        "OutOfDomain",
        "ValueError",
        "Valid parameters, but the configuration is unreachable (e.g. a joint limit).",
    ),
    (
        "GeometryError",
        "Geometry",
        "ValueError",
        "A geometric description (outline, layup) is malformed.",
    ),
    (
        "ShapeError",
        "Shape",
        "ValueError",
        "Arrays or matrices have mismatching or wrong dimensions.",
    ),
    (
        "ConstraintError",
        "Constraint",
        "ValueError",
        "A constraint matrix is rank deficient or the initial state violates it.",
    ),
    (
        "SingularError",
        "Singular",
        "ArithmeticError",
        "A linear system is singular at this configuration.",
    ),
    (
        "IntegrationError",
        "Integration",
        "RuntimeError",
        "Time integration failed; `.time` and `.state` say where.",
    ),
    (
        "CancelledError",
        "Cancelled",
        "",
        "The work was cancelled by the caller.",
    ),
];

struct Classes {
    base: Py<PyType>,
    by_kind: Vec<(&'static str, &'static str, Py<PyType>)>,
}

static CLASSES: PyOnceLock<Classes> = PyOnceLock::new();

fn make_class<'py>(
    py: Python<'py>,
    name: &str,
    bases: Bound<'py, PyTuple>,
    doc: &str,
) -> PyResult<Py<PyType>> {
    let ns = PyDict::new(py);
    ns.set_item("__module__", "paritysim._core")?;
    ns.set_item("__doc__", doc)?;
    let class = py.get_type::<PyType>().call1((name, bases, ns))?;
    Ok(class.cast_into::<PyType>()?.unbind())
}

fn classes(py: Python<'_>) -> PyResult<&Classes> {
    CLASSES.get_or_try_init(py, || {
        let base = make_class(
            py,
            "ParitysimError",
            PyTuple::new(py, [py.get_type::<PyException>()])?,
            "Root of every error raised by paritysim.",
        )?;
        let mut by_kind = Vec::new();
        for (name, kind, builtin, doc) in TREE {
            let base_bound = base.bind(py).clone();
            let bases = match builtin {
                "ValueError" => PyTuple::new(py, [base_bound, py.get_type::<PyValueError>()])?,
                "ArithmeticError" => {
                    PyTuple::new(py, [base_bound, py.get_type::<PyArithmeticError>()])?
                }
                "RuntimeError" => PyTuple::new(py, [base_bound, py.get_type::<PyRuntimeError>()])?,
                _ => PyTuple::new(py, [base_bound])?,
            };
            by_kind.push((name, kind, make_class(py, name, bases, doc)?));
        }
        Ok(Classes { base, by_kind })
    })
}

/// Adds `ParitysimError` and its subclasses to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    let c = classes(py)?;
    m.add("ParitysimError", c.base.bind(py))?;
    for (name, _, class) in &c.by_kind {
        m.add(*name, class.bind(py))?;
    }
    Ok(())
}

/// Converts a paritysim error into the matching Python exception, with attributes
/// `kind`, `field` (invalid parameters) and `time`, `state` (integration failures).
pub fn to_pyerr(err: Error) -> PyErr {
    Python::attach(|py| match build(py, &err) {
        Ok(e) => e,
        Err(e) => e,
    })
}

fn build(py: Python<'_>, err: &Error) -> PyResult<PyErr> {
    let c = classes(py)?;
    let class = c
        .by_kind
        .iter()
        .find(|(_, kind, _)| *kind == err.kind())
        .map(|(_, _, class)| class.bind(py).clone())
        .unwrap_or_else(|| c.base.bind(py).clone());
    let instance = class.call1((err.to_string(),))?;
    instance.setattr("kind", err.kind())?;
    instance.setattr("field", err.field())?;
    if let Error::Integration { time, state, .. } = err {
        instance.setattr("time", *time)?;
        instance.setattr("state", state.clone())?;
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
