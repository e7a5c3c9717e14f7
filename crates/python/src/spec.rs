//! Bindings of paritysim-spec and of `simulate`.
//!
//! A spec crosses the boundary as JSON text: Python's `json` module turns the dataclasses'
//! plain data into it and the spec crate validates it (every problem, with dotted paths).
//! JSON rather than walking the dict here: no hand-written reader, no extra dependency
//! (`pythonize`), and a spec is small (tens of microseconds against milliseconds of
//! simulation).

use numpy::PyArray1;
use paritysim_dynamics::{CancelFlag, Device, SimulationResult};
use paritysim_error::{Error, Result};
use paritysim_spec::{Simulation, paths, schema};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::IntoPyResult;

/// A validated spec from JSON text.
pub(crate) fn parse(json: &str) -> Result<Simulation> {
    paritysim_spec::from_json(json).map(|(s, _)| s)
}

/// The dynamics model of a JSON spec.
pub(crate) fn device(json: &str) -> Result<Device> {
    parse(json)?.device()
}

fn to_json<T: serde::Serialize>(value: &T) -> String {
    serde_json::to_string(value).expect("plain data serialises")
}

/// The JSON Schema of a spec (draft 2020-12), as JSON text.
#[pyfunction]
fn spec_schema() -> String {
    schema::schema_json()
}

/// Defaults of the tagged-enum specs (`Drivetrain`, `Aero`, `Waveform`), as JSON text.
#[pyfunction]
fn spec_defaults() -> String {
    to_json(&serde_json::json!({
        "Drivetrain": paritysim_spec::Drivetrain::default(),
        "Aero": paritysim_spec::Aero::default(),
        "Waveform": paritysim_spec::Waveform::default(),
    }))
}

/// Validates a JSON spec; returns its canonical JSON (defaults filled in, current names) and
/// the deprecation notes of old spellings.
#[pyfunction]
fn spec_normalize(json: &str) -> PyResult<(String, Vec<String>)> {
    let (spec, notes) = paritysim_spec::from_json(json).py_err()?;
    Ok((spec.to_json(), notes))
}

/// Parses TOML text into canonical JSON plus deprecation notes.
#[pyfunction]
fn spec_from_toml(text: &str) -> PyResult<(String, Vec<String>)> {
    let (spec, notes) = paritysim_spec::from_toml(text).py_err()?;
    Ok((spec.to_json(), notes))
}

/// A JSON spec as TOML text.
#[pyfunction]
fn spec_to_toml(json: &str) -> PyResult<String> {
    Ok(parse(json).py_err()?.to_toml())
}

/// Every parameter path of a JSON spec: `(path, unit, allowed, value as JSON)`.
#[pyfunction]
fn spec_paths(json: &str) -> PyResult<Vec<(String, String, String, String)>> {
    let spec = parse(json).py_err()?;
    Ok(paths::spec_paths(&spec)
        .into_iter()
        .map(|p| (p.path, p.unit, p.allowed, to_json(&p.value)))
        .collect())
}

/// Applies `{path: value}` (values as a JSON object) to a JSON spec; returns the canonical
/// JSON of the result and the deprecation notes of the paths.
#[pyfunction]
fn spec_apply(json: &str, values: &str) -> PyResult<(String, Vec<String>)> {
    let spec = parse(json).py_err()?;
    let values: serde_json::Map<String, serde_json::Value> = serde_json::from_str(values)
        .map_err(|e| Error::invalid("values", e.to_string(), "a JSON object of path: value"))
        .py_err()?;
    let listed = paths::spec_paths(&spec);
    let params = values
        .keys()
        .map(|k| paths::resolve_in(&spec, &listed, k))
        .collect::<Result<Vec<_>>>()
        .py_err()?;
    let pairs: Vec<_> = params.iter().zip(values.values()).collect();
    let out = paths::apply(&spec, &pairs).py_err()?;
    Ok((
        out.to_json(),
        params.into_iter().flat_map(|p| p.notes).collect(),
    ))
}

/// "a known name: did you mean `x`? (valid: ...)" for `word` among `valid` (edit distance).
#[pyfunction]
fn spec_suggestion(word: &str, valid: Vec<String>) -> String {
    schema::suggestion(word, valid.iter().map(String::as_str))
}

/// Validates a JSON spec and builds its model; returns `(n_wings, n_dof)`.
#[pyfunction]
fn validate_spec(json: &str) -> PyResult<(usize, usize)> {
    let (device, _) = parse(json).and_then(|s| s.model()).py_err()?;
    Ok((device.n_wings(), device.n_dof()))
}

/// What `simulate` returns.
#[pyclass(module = "paritysim._core", frozen)]
pub struct SimulationOutput {
    result: SimulationResult,
}

#[pymethods]
impl SimulationOutput {
    /// Sample times (ms).
    #[getter]
    fn time_ms<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.result.trajectory.time)
    }

    /// Trajectory columns, name -> array.
    #[getter]
    fn columns<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let out = PyDict::new(py);
        for (name, values) in &self.result.trajectory.columns {
            out.set_item(name, PyArray1::from_slice(py, values))?;
        }
        Ok(out)
    }

    /// Scalar metrics, name -> value.
    #[getter]
    fn metrics(&self) -> Vec<(String, f64)> {
        self.result.metrics.clone()
    }

    /// Cycles simulated before recording.
    #[getter]
    fn cycles_run(&self) -> usize {
        self.result.cycles_run
    }

    /// Whether the steady-state tolerance was met.
    #[getter]
    fn converged(&self) -> bool {
        self.result.converged
    }

    /// Drive period (ms; NaN without a periodic drive).
    #[getter]
    fn period_ms(&self) -> f64 {
        self.result.period_ms
    }

    /// Relative residual of the steady state before recording (NaN without a drive).
    #[getter]
    fn residual(&self) -> f64 {
        self.result.residual
    }

    /// Floquet multipliers `(re, im)` from Newton shooting (empty for transient runs).
    #[getter]
    fn multipliers(&self) -> Vec<(f64, f64)> {
        self.result
            .multipliers
            .iter()
            .map(|m| (m.re, m.im))
            .collect()
    }
}

/// How often a waiting call checks for Python signals (Ctrl-C).
const SIGNAL_POLL: std::time::Duration = std::time::Duration::from_millis(20);

/// Runs `work` on a worker thread with the GIL released while this thread checks Python's
/// signals every [`SIGNAL_POLL`]: on Ctrl-C (or any handler raising) `cancel` is set, the
/// worker stops at its next budget check and the handler's exception is returned.
pub(crate) fn interruptible<T: Send>(
    py: Python<'_>,
    cancel: &CancelFlag,
    work: impl FnOnce() -> Result<T> + Send,
) -> PyResult<T> {
    let (out, interrupted) = py.detach(|| {
        std::thread::scope(|scope| {
            let (done_tx, done_rx) = std::sync::mpsc::channel::<()>();
            let worker = scope.spawn(move || {
                let out = work();
                let _ = done_tx.send(());
                out
            });
            let mut interrupted = None;
            loop {
                match done_rx.recv_timeout(SIGNAL_POLL) {
                    Err(std::sync::mpsc::RecvTimeoutError::Timeout) if interrupted.is_none() => {
                        if let Err(e) = Python::attach(|py| py.check_signals()) {
                            cancel.cancel();
                            interrupted = Some(e);
                        }
                    }
                    Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
                    _ => break,
                }
            }
            let out = worker.join().unwrap_or_else(|_| {
                Err(Error::Integration {
                    time: f64::NAN,
                    state: Vec::new(),
                    reason: "internal error (panic) in the simulation thread".into(),
                })
            });
            (out, interrupted)
        })
    });
    match interrupted {
        Some(e) => Err(e),
        None => out.py_err(),
    }
}

/// Simulates a JSON spec on a worker thread (GIL released); Ctrl-C stops it within a few
/// tens of milliseconds and raises `KeyboardInterrupt`.
#[pyfunction]
fn simulate(py: Python<'_>, json: &str) -> PyResult<SimulationOutput> {
    let spec = parse(json).py_err()?;
    let (device, mut options) = spec.model().py_err()?;
    let cancel = CancelFlag::new();
    options.cancel = Some(cancel.clone());
    // A spec with a moving body flies (paritysim-flight); otherwise the fixed-body engine.
    let result = interruptible(py, &cancel, || spec.run(&device, &options))?;
    Ok(SimulationOutput { result })
}

/// Adds the spec and simulation functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<SimulationOutput>()?;
    m.add_function(wrap_pyfunction!(spec_schema, m)?)?;
    m.add_function(wrap_pyfunction!(spec_defaults, m)?)?;
    m.add_function(wrap_pyfunction!(spec_normalize, m)?)?;
    m.add_function(wrap_pyfunction!(spec_from_toml, m)?)?;
    m.add_function(wrap_pyfunction!(spec_to_toml, m)?)?;
    m.add_function(wrap_pyfunction!(spec_paths, m)?)?;
    m.add_function(wrap_pyfunction!(spec_apply, m)?)?;
    m.add_function(wrap_pyfunction!(validate_spec, m)?)?;
    m.add_function(wrap_pyfunction!(spec_suggestion, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    Ok(())
}
