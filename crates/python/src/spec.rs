//! Bindings of paritysim-spec and of `simulate`.
//!
//! A spec crosses the boundary as JSON text: Python's `json` module turns the dataclasses'
//! plain data into it and the spec crate validates it (every problem, with dotted paths).
//! JSON rather than walking the dict here: no hand-written reader, no extra dependency
//! (`pythonize`), and a spec is small (tens of microseconds against milliseconds of
//! simulation).

use numpy::PyArray1;
use paritysim_dynamics::integrate::budget;
use paritysim_dynamics::{CancelFlag, Device};
use paritysim_error::Result;
use paritysim_spec::watch::{run_inline, run_watched};
use paritysim_spec::{Simulation, paths, schema};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::bindings;
use crate::errors::IntoPyResult;

/// A validated spec from JSON text.
pub(crate) fn parse(json: &str) -> Result<Simulation> {
    paritysim_spec::from_json(json).map(|(s, _)| s)
}

/// The dynamics model of a JSON spec.
pub(crate) fn device(json: &str) -> Result<Device> {
    parse(json)?.device()
}

/// A spec's canonical JSON and its deprecation notes.
type Canonical = (String, Vec<String>);

bindings! {
    class SimulationOutput;
    extra simulate;
    extra simulate_controlled;

    /// The JSON Schema of a spec (draft 2020-12), as JSON text.
    fn spec_schema() -> String {
        Ok(schema::schema_json())
    }

    /// Defaults of the tagged-enum specs (`Drivetrain`, `Aero`, `Waveform`), as JSON text.
    fn spec_defaults() -> String {
        Ok(schema::tagged_defaults_json())
    }

    /// Validates a JSON spec: its canonical JSON (defaults filled in, current names) and the
    /// deprecation notes of old spellings.
    fn spec_normalize(json: &str) -> Canonical {
        paritysim_spec::from_json(json).map(|(spec, notes)| (spec.to_json(), notes))
    }

    /// Parses TOML text into canonical JSON plus deprecation notes.
    fn spec_from_toml(text: &str) -> Canonical {
        paritysim_spec::from_toml(text).map(|(spec, notes)| (spec.to_json(), notes))
    }

    /// A JSON spec as TOML text.
    fn spec_to_toml(json: &str) -> String {
        Ok(parse(json)?.to_toml())
    }

    /// Every parameter path of a JSON spec: `(path, unit, allowed, value as JSON)`.
    fn spec_paths(json: &str) -> Vec<(String, String, String, String)> {
        let listed = paths::spec_paths(&parse(json)?).into_iter();
        Ok(listed.map(|p| (p.path, p.unit, p.allowed, p.value.to_string())).collect())
    }

    /// Applies `{path: value}` (a JSON object) to a JSON spec: the result's canonical JSON and
    /// the deprecation notes of the paths.
    fn spec_apply(json: &str, values: &str) -> Canonical {
        let (out, notes) = paths::apply_json(&parse(json)?, values)?;
        Ok((out.to_json(), notes))
    }

    /// The allowed text of an unknown `word` among `valid` (`schema::suggestion_for`): `what`
    /// it must be, the nearest name and a handful of close ones; `listed_by` says where the
    /// whole list is.
    #[pyo3(signature = (word, valid, what = "a known name", listed_by = None))]
    fn spec_suggestion(word: &str, valid: Vec<String>, what: &str, listed_by: Option<String>) -> String {
        let valid = valid.iter().map(String::as_str);
        Ok(schema::suggestion_for(word, valid, what, listed_by.as_deref()))
    }

    /// At most `limit` names of `valid` close to `word`, nearest first (`schema::close`).
    fn spec_close_names(word: &str, valid: Vec<String>, limit: usize) -> Vec<String> {
        let near = schema::close(word, valid.iter().map(String::as_str), limit);
        Ok(near.into_iter().map(str::to_string).collect())
    }

    /// Validates a JSON spec and builds its model: `(n_wings, n_dof)`.
    fn validate_spec(json: &str) -> (usize, usize) {
        let (device, _) = parse(json)?.model()?;
        Ok((device.n_wings(), device.n_dof()))
    }
}

/// What `simulate` returns (`SimulationResult` with numpy trajectory columns).
#[pyclass(module = "paritysim._core", frozen, get_all)]
pub struct SimulationOutput {
    time_ms: Py<PyArray1<f64>>,
    columns: Py<PyDict>,
    metrics: Vec<(String, f64)>,
    cycles_run: usize,
    converged: bool,
    period_ms: f64,
    residual: f64,
    multipliers: Vec<(f64, f64)>,
    orbit_cycles: usize,
}

/// How often a waiting call checks for Python signals (Ctrl-C).
const SIGNAL_POLL: std::time::Duration = std::time::Duration::from_millis(20);

/// Runs `work` on a worker thread with the GIL released while this thread checks Python's
/// signals every [`SIGNAL_POLL`] (`paritysim_spec::watch::run_watched`): on Ctrl-C (or any
/// handler raising) `cancel` is set and the handler's exception is returned.
pub(crate) fn interruptible<T: Send>(
    py: Python<'_>,
    cancel: &CancelFlag,
    work: impl FnOnce() -> Result<T> + Send,
) -> PyResult<T> {
    let signals = || Python::attach(|py| py.check_signals());
    py.detach(|| run_watched(cancel, SIGNAL_POLL, signals, work))?
        .py_err()
}

/// [`interruptible`] for work that stays on this thread (one simulation): run here with the
/// GIL released, Python's signals checked from the work's budget checks every [`SIGNAL_POLL`]
/// (`paritysim_spec::watch::run_inline`), no worker thread to spawn and join.
pub(crate) fn interruptible_here<T>(
    py: Python<'_>,
    cancel: &CancelFlag,
    work: impl FnOnce() -> Result<T> + Send,
) -> PyResult<T>
where
    T: Send,
{
    let signals = || Python::attach(|py| py.check_signals());
    py.detach(|| run_inline(cancel, SIGNAL_POLL, signals, work))?
        .py_err()
}

/// Runs a long core call like [`interruptible`], with a fresh cancel flag installed as the
/// call's budget (`budget::cancellable`): Ctrl-C reaches every integration it makes, on any
/// thread, and raises `KeyboardInterrupt`.
pub(crate) fn cancellable<T: Send>(
    py: Python<'_>,
    work: impl FnOnce() -> Result<T> + Send,
) -> PyResult<T> {
    cancellable_on(py, false, work)
}

/// [`cancellable`], on this thread with `here` ([`interruptible_here`]: no worker thread to
/// spawn and join; Python's signals polled from this thread's budget checks only).
pub(crate) fn cancellable_on<T: Send>(
    py: Python<'_>,
    here: bool,
    work: impl FnOnce() -> Result<T> + Send,
) -> PyResult<T> {
    let cancel = CancelFlag::new();
    let flag = cancel.clone();
    let work = move || budget::cancellable(&flag, work);
    if here {
        interruptible_here(py, &cancel, work)
    } else {
        interruptible(py, &cancel, work)
    }
}

/// Runs `work` with a wall-clock budget of `max_wall_ms` (None: none of its own) installed on
/// this thread (`budget::Budget`; the call's cancel flag and any outer deadline still apply):
/// every integration and `budget::check` it makes stops once the budget is spent, and the call
/// then fails with an `IntegrationError` naming `max_wall_ms` (a whole continuation, a long
/// list of Hill solutions: issue 34).
///
/// # Errors
/// `max_wall_ms` outside (0, 1e9] ms; the spent budget; those of `work`.
pub(crate) fn within<T>(max_wall_ms: Option<f64>, work: impl FnOnce() -> Result<T>) -> Result<T> {
    let Some(ms) = max_wall_ms else {
        return work();
    };
    if !(ms.is_finite() && ms > 0.0 && ms <= 1e9) {
        return Err(paritysim_error::Error::invalid(
            "max_wall_ms",
            ms.to_string(),
            "a wall-time budget in (0, 1e9] ms",
        ));
    }
    let start = std::time::Instant::now();
    let out = {
        let _guard = budget::Budget::new(Some(ms), None).enter();
        work()
    };
    match out {
        Err(paritysim_error::Error::Cancelled) => Err(paritysim_error::Error::Cancelled),
        out if start.elapsed().as_secs_f64() * 1e3 >= ms => {
            Err(paritysim_error::Error::Integration {
                time: f64::NAN,
                state: Vec::new(),
                reason: format!(
                    "exceeded the wall-time budget `max_wall_ms` = {ms} ms{}",
                    out.err()
                        .filter(|e| !e.to_string().contains("wall-time budget"))
                        .map_or(String::new(), |e| format!(" (stopped: {e})"))
                ),
            }
            .attributed("max_wall_ms", ms, "a larger budget (ms), or less work"))
        }
        out => out,
    }
}

/// Simulates a JSON spec on a worker thread (GIL released); Ctrl-C stops it within a few
/// tens of milliseconds and raises `KeyboardInterrupt`.
/// `columns` / `metrics` select what is built (`None`: everything).
#[pyfunction]
#[pyo3(signature = (json, columns=None, metrics=None))]
fn simulate(
    py: Python<'_>,
    json: &str,
    columns: Option<Vec<String>>,
    metrics: Option<Vec<String>>,
) -> PyResult<SimulationOutput> {
    let spec = parse(json).py_err()?;
    let (device, options) = spec.model().py_err()?;
    let mut options = spec
        .with_outputs(&device, &options, columns.as_deref(), metrics.as_deref())
        .py_err()?;
    let cancel = CancelFlag::new();
    options.cancel = Some(cancel.clone());
    let r = interruptible_here(py, &cancel, || {
        // A spec with a moving body flies (paritysim-flight); otherwise the fixed-body engine.
        spec.run(&device, &options).map_err(|e| spec.attribute(e))
    })?;
    output(py, Simulation::asked_metrics(&options, r))
}

/// `simulate` of a flying spec with a Python controller called every `1 / rate_hz` with
/// `(t_ms, [(body column, value)])` and returning `[(input name, value)]` (names as in
/// `[[body.set_points]]`; unknown names and non-finite values raise `InvalidParameterError`).
/// Its exception is raised as is.
#[pyfunction]
#[pyo3(signature = (json, controller, rate_hz, columns=None, metrics=None))]
fn simulate_controlled(
    py: Python<'_>,
    json: &str,
    controller: Py<PyAny>,
    rate_hz: f64,
    columns: Option<Vec<String>>,
    metrics: Option<Vec<String>>,
) -> PyResult<SimulationOutput> {
    let spec = parse(json).py_err()?;
    let (device, options) = spec.model().py_err()?;
    let mut options = spec
        .with_outputs(&device, &options, columns.as_deref(), metrics.as_deref())
        .py_err()?;
    // Ctrl-C is polled from the integrator's budget checks as in `simulate` (the controller's
    // own Python calls did not see it: issue 34).
    let cancel = CancelFlag::new();
    options.cancel = Some(cancel.clone());
    let mut raised: Option<PyErr> = None;
    let mut call = |t: f64, s: &paritysim_flight::FlightSample| {
        Python::attach(|py| {
            let values = paritysim_flight::body_values(s);
            let out = controller.bind(py).call1((t, values))?;
            out.extract::<Vec<(String, f64)>>()
        })
        .and_then(|pairs| {
            paritysim_flight::ControlInput::inputs_from_named(&pairs)
                .map_err(crate::errors::to_pyerr)
        })
        .map_err(|e| {
            raised = Some(e);
            paritysim_error::Error::Cancelled
        })
    };
    let r = interruptible_here(py, &cancel, || {
        spec.run_controlled(&device, &options, rate_hz, &mut call)
            .map_err(|e| spec.attribute(e))
    });
    match (raised, r) {
        (Some(e), _) => Err(e),
        (None, r) => output(py, Simulation::asked_metrics(&options, r?)),
    }
}

fn output(py: Python<'_>, r: paritysim_dynamics::SimulationResult) -> PyResult<SimulationOutput> {
    let columns = PyDict::new(py);
    for (name, values) in r.trajectory.columns {
        columns.set_item(name, PyArray1::from_vec(py, values))?;
    }
    Ok(SimulationOutput {
        time_ms: PyArray1::from_vec(py, r.trajectory.time).unbind(),
        columns: columns.unbind(),
        metrics: r.metrics,
        cycles_run: r.cycles_run,
        converged: r.converged,
        period_ms: r.period_ms,
        residual: r.residual,
        multipliers: r.multipliers.iter().map(|m| (m.re, m.im)).collect(),
        orbit_cycles: r.orbit_cycles,
    })
}
