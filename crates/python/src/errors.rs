//! The Python exception tree, mapped from `paritysim_error::Error` by one exhaustive `match`
//! ([`class_of`]): a new variant does not compile until it has a class.
//!
//! The classes need multiple bases (`ParitysimError` and `ValueError`, ...), which
//! `create_exception!` cannot express, so they are built once with `type(name, bases, ns)`.

use paritysim_error::Error;
use pyo3::exceptions::{PyArithmeticError, PyException, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple, PyType};

/// The exception classes below `ParitysimError`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Class {
    InvalidParameter,
    OutOfDomain,
    Geometry,
    Shape,
    Constraint,
    Singular,
    Integration,
    Cancelled,
}

/// The builtin base a class adds to `ParitysimError`.
enum Builtin {
    Value,
    Arithmetic,
    Runtime,
    None,
}

const CLASSES: [Class; 8] = [
    Class::InvalidParameter,
    Class::OutOfDomain,
    Class::Geometry,
    Class::Shape,
    Class::Constraint,
    Class::Singular,
    Class::Integration,
    Class::Cancelled,
];

impl Class {
    fn info(self) -> (&'static str, Builtin, &'static str) {
        match self {
            Class::InvalidParameter => (
                "InvalidParameterError",
                Builtin::Value,
                "A parameter is non-finite or outside its allowed range; `.field` names it \
                 (`.problems` lists every invalid field of a spec).",
            ),
            Class::OutOfDomain => (
                "OutOfDomainError",
                Builtin::Value,
                "Valid parameters, but the configuration is unreachable (e.g. a joint limit).",
            ),
            Class::Geometry => (
                "GeometryError",
                Builtin::Value,
                "A geometric description (outline, layup) is malformed.",
            ),
            Class::Shape => (
                "ShapeError",
                Builtin::Value,
                "Arrays or matrices have mismatching or wrong dimensions.",
            ),
            Class::Constraint => (
                "ConstraintError",
                Builtin::Value,
                "A constraint matrix is rank deficient or the initial state violates it.",
            ),
            Class::Singular => (
                "SingularError",
                Builtin::Arithmetic,
                "A linear system is singular at this configuration.",
            ),
            Class::Integration => (
                "IntegrationError",
                Builtin::Runtime,
                "Time integration failed; `.time` and `.state` say where.",
            ),
            Class::Cancelled => (
                "CancelledError",
                Builtin::None,
                "The work was cancelled by the caller.",
            ),
        }
    }
}

/// The class of each error variant: exhaustive, no wildcard.
fn class_of(err: &Error) -> Class {
    match err {
        Error::InvalidParameter { .. } | Error::InvalidSpec(_) => Class::InvalidParameter,
        Error::OutOfDomain { .. } => Class::OutOfDomain,
        Error::Geometry(_) => Class::Geometry,
        Error::Shape(_) => Class::Shape,
        Error::Constraint(_) => Class::Constraint,
        Error::Singular(_) => Class::Singular,
        Error::Integration { .. } => Class::Integration,
        Error::Cancelled => Class::Cancelled,
        Error::Attributed { error, .. } => class_of(error),
    }
}

struct Tree {
    base: Py<PyType>,
    classes: Vec<Py<PyType>>,
}

static TREE: PyOnceLock<Tree> = PyOnceLock::new();

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

fn tree(py: Python<'_>) -> PyResult<&Tree> {
    TREE.get_or_try_init(py, || {
        let base = make_class(
            py,
            "ParitysimError",
            PyTuple::new(py, [py.get_type::<PyException>()])?,
            "Root of every error raised by paritysim.",
        )?;
        let mut classes = Vec::new();
        for class in CLASSES {
            let (name, builtin, doc) = class.info();
            let b = base.bind(py).clone();
            let bases = match builtin {
                Builtin::Value => PyTuple::new(py, [b, py.get_type::<PyValueError>()])?,
                Builtin::Arithmetic => PyTuple::new(py, [b, py.get_type::<PyArithmeticError>()])?,
                Builtin::Runtime => PyTuple::new(py, [b, py.get_type::<PyRuntimeError>()])?,
                Builtin::None => PyTuple::new(py, [b])?,
            };
            classes.push(make_class(py, name, bases, doc)?);
        }
        Ok(Tree { base, classes })
    })
}

/// Adds `ParitysimError` and its subclasses to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    let t = tree(py)?;
    m.add("ParitysimError", t.base.bind(py))?;
    for (class, py_class) in CLASSES.iter().zip(&t.classes) {
        m.add(class.info().0, py_class.bind(py))?;
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
    let t = tree(py)?;
    let index = CLASSES
        .iter()
        .position(|c| *c == class_of(err))
        .expect("every class is in CLASSES");
    let instance = t.classes[index].bind(py).call1((err.to_string(),))?;
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
            let list: Vec<(String, String, String)> = problems
                .iter()
                .map(|p| (p.field.clone(), p.value.clone(), p.allowed.clone()))
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
