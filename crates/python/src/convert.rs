//! The two generic conversions of the boundary: JSON text into a serde input record, and any
//! `Serialize` result into Python objects (numeric arrays become numpy arrays).

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use paritysim_error::Error;
use pyo3::IntoPyObjectExt;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use serde::Serialize;
use serde::de::DeserializeOwned;
use serde_json::Value;

/// Defines the module's `#[pyfunction]`s and its `register` (which also adds `class`es,
/// `const`ants and hand-written `extra` functions). Each body runs with the GIL released (through
/// `run`: [`detached`] by default, `crate::spec::cancellable` for long calls that Ctrl-C must
/// stop) and returns a `paritysim_error::Result`; with `-> T` the value converts as `T`, without, it is a
/// `Serialize` record converted by [`to_py`]. Array arguments are [`Floats`] / [`Table`].
macro_rules! bindings {
    (@fn $run:path; $(#[$attr:meta])* $name:ident($($arg:ident: $ty:ty),*) -> $ret:ty $body:block) => {
        #[pyfunction]
        $(#[$attr])*
        fn $name(py: Python<'_>, $($arg: $ty),*) -> PyResult<$ret> {
            $run(py, || -> paritysim_error::Result<$ret> { $body })
        }
    };
    (@fn $run:path; $(#[$attr:meta])* $name:ident($($arg:ident: $ty:ty),*) $body:block) => {
        #[pyfunction]
        $(#[$attr])*
        fn $name<'py>(py: Python<'py>, $($arg: $ty),*) -> PyResult<Bound<'py, PyAny>> {
            let out = $run(py, || -> paritysim_error::Result<_> { $body })?;
            $crate::convert::to_py(py, &out)
        }
    };
    (
        run $run:path;
        $(class $class:ty;)*
        $(const $const_name:literal = $const_value:expr;)*
        $(extra $extra:ident;)*
        $($(#[$attr:meta])* fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)? $body:block)*
    ) => {
        $(bindings!(@fn $run; $(#[$attr])* $name($($arg: $ty),*) $(-> $ret)? $body);)*

        /// Adds this module's functions, classes and constants.
        pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
            $(m.add_class::<$class>()?;)*
            $(m.add($const_name, $const_value)?;)*
            $(m.add_function(wrap_pyfunction!($extra, m)?)?;)*
            $(m.add_function(wrap_pyfunction!($name, m)?)?;)*
            Ok(())
        }
    };
    // Without `run`: the GIL is released, Ctrl-C waits for the call (short calls).
    ($($rest:tt)*) => {
        bindings!(run $crate::convert::detached; $($rest)*);
    };
}
pub(crate) use bindings;

/// Runs a short core call with the GIL released.
pub(crate) fn detached<T: Send>(
    py: Python<'_>,
    work: impl FnOnce() -> paritysim_error::Result<T> + Send,
) -> PyResult<T> {
    crate::errors::IntoPyResult::py_err(py.detach(work))
}

/// A contiguous copy-free view if possible, else an owned copy.
pub fn to_vec(a: &PyReadonlyArray1<'_, f64>) -> Vec<f64> {
    match a.as_slice() {
        Ok(s) => s.to_vec(),
        Err(_) => a.as_array().iter().copied().collect(),
    }
}

/// A float64 numpy vector argument, copied so the call can release the GIL.
pub struct Floats(pub Vec<f64>);

impl<'py> FromPyObject<'py> for Floats {
    fn extract_bound(ob: &Bound<'py, PyAny>) -> PyResult<Self> {
        Ok(Floats(to_vec(&ob.extract::<PyReadonlyArray1<'py, f64>>()?)))
    }
}

impl std::ops::Deref for Floats {
    type Target = Vec<f64>;
    fn deref(&self) -> &Vec<f64> {
        &self.0
    }
}

/// A float64 numpy `(n, k)` matrix argument, copied row-major.
pub struct Table {
    data: Vec<f64>,
    cols: usize,
}

impl<'py> FromPyObject<'py> for Table {
    fn extract_bound(ob: &Bound<'py, PyAny>) -> PyResult<Self> {
        let a = ob.extract::<PyReadonlyArray2<'py, f64>>()?;
        let v = a.as_array();
        Ok(Table {
            data: v.iter().copied().collect(),
            cols: v.ncols(),
        })
    }
}

impl Table {
    /// The rows, requiring `N` columns.
    ///
    /// # Errors
    /// [`Error::Shape`] naming the argument `name` when the column count differs.
    pub fn rows<const N: usize>(&self, name: &str) -> Result<Vec<[f64; N]>, Error> {
        if self.cols != N {
            let n = self.data.len().checked_div(self.cols).unwrap_or(0);
            let shape = [n, self.cols];
            return Err(Error::Shape(format!(
                "`{name}` must have shape (n, {N}), got {shape:?}"
            )));
        }
        Ok(self
            .data
            .chunks_exact(N)
            .map(|r| std::array::from_fn(|j| r[j]))
            .collect())
    }
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

/// Parses `text` as the record `T` (which denies unknown fields).
///
/// # Errors
/// [`Error::InvalidParameter`] on `field`: an unknown key is named with the nearest valid one
/// (`paritysim_spec::schema::suggestion`), other mismatches carry serde's message.
pub fn from_json<T: DeserializeOwned>(field: &str, text: &str) -> Result<T, Error> {
    serde_json::from_str(text).map_err(|e| {
        let msg = e.to_string();
        // serde_json: "unknown field `k`, expected one of `a`, `b` at line 1 column 9".
        let quoted: Vec<&str> = msg.split('`').skip(1).step_by(2).collect();
        match quoted.split_first() {
            Some((key, valid)) if msg.starts_with("unknown field") => Error::invalid(
                if field.is_empty() {
                    key.to_string()
                } else {
                    format!("{field}.{key}")
                },
                "<unknown field>",
                paritysim_spec::schema::suggestion(key, valid.iter().copied()),
            ),
            _ => Error::invalid(
                field.to_string(),
                msg,
                "a record matching the documented fields",
            ),
        }
    })
}

/// Any serialisable result as Python objects: structs and maps become dicts, rectangular
/// arrays of numbers (or of booleans) numpy arrays of that shape (`null` in a float array is
/// NaN), other arrays lists, a non-finite scalar None.
pub fn to_py<'py, T: Serialize>(py: Python<'py>, value: &T) -> PyResult<Bound<'py, PyAny>> {
    let v = serde_json::to_value(value)
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?;
    value_to_py(py, &v)
}

fn value_to_py<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    match v {
        Value::Null => Ok(py.None().into_bound(py)),
        Value::Bool(b) => b.into_bound_py_any(py),
        Value::Number(n) => match n.as_i64() {
            Some(i) => i.into_bound_py_any(py),
            None => n.as_f64().into_bound_py_any(py),
        },
        Value::String(s) => s.into_bound_py_any(py),
        Value::Array(items) => match numeric_array(py, v)? {
            Some(a) => Ok(a),
            None => {
                let list: PyResult<Vec<_>> = items.iter().map(|x| value_to_py(py, x)).collect();
                Ok(PyList::new(py, list?)?.into_any())
            }
        },
        Value::Object(map) => {
            let d = PyDict::new(py);
            for (k, x) in map {
                d.set_item(k, value_to_py(py, x)?)?;
            }
            Ok(d.into_any())
        }
    }
}

/// Collects the leaves of a rectangular nested array; false if it is ragged or holds strings
/// or objects.
fn leaves<'a>(
    v: &'a Value,
    depth: usize,
    shape: &mut Vec<usize>,
    out: &mut Vec<&'a Value>,
) -> bool {
    match v {
        Value::Array(items) => {
            if depth == shape.len() && out.is_empty() {
                shape.push(items.len());
            } else if shape.get(depth) != Some(&items.len()) {
                return false;
            }
            items.iter().all(|x| leaves(x, depth + 1, shape, out))
        }
        Value::String(_) | Value::Object(_) => false,
        _ => {
            out.push(v);
            depth == shape.len()
        }
    }
}

fn numeric_array<'py>(py: Python<'py>, v: &Value) -> PyResult<Option<Bound<'py, PyAny>>> {
    let (mut shape, mut out) = (Vec::new(), Vec::new());
    if !leaves(v, 0, &mut shape, &mut out) {
        return Ok(None);
    }
    let a = if !out.is_empty() && out.iter().all(|x| x.is_boolean()) {
        let flat: Vec<bool> = out.iter().map(|x| x.as_bool() == Some(true)).collect();
        PyArray1::from_vec(py, flat).reshape(shape)?.into_any()
    } else if !out.is_empty() && out.iter().all(|x| x.as_i64().is_some()) {
        let flat: Vec<i64> = out.iter().filter_map(|x| x.as_i64()).collect();
        PyArray1::from_vec(py, flat).reshape(shape)?.into_any()
    } else if out.iter().all(|x| x.is_number() || x.is_null()) {
        let flat: Vec<f64> = out.iter().map(|x| x.as_f64().unwrap_or(f64::NAN)).collect();
        PyArray1::from_vec(py, flat).reshape(shape)?.into_any()
    } else {
        return Ok(None);
    };
    Ok(Some(a))
}
