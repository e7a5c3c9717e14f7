//! Bindings of the sweep handle of paritysim-spec (`SweepRun`) and its outcome.
//!
//! The handle, its background thread, progress counter and cancel flag live in the core
//! ([`paritysim_spec::sweep::SweepJob`]); this is the mechanical translation: blocking calls
//! release the GIL, results are numpy arrays.

use std::time::Duration;

use numpy::PyArray1;
use paritysim_dynamics::sweep::{THREADS_ENV, resolve_threads};
use paritysim_error::Error;
use paritysim_spec::sweep::{KeptCycles, SweepJob, SweepOutcome, SweepPlan};
use pyo3::prelude::*;

use crate::convert::shaped;
use crate::errors::IntoPyResult;
use crate::spec::parse;

/// A batch of sweep points running on a background thread.
#[pyclass(module = "paritysim._core", frozen)]
pub struct SweepRun {
    job: SweepJob,
}

#[pymethods]
impl SweepRun {
    /// `spec`: the base spec (JSON); `names`: parameter paths; `rows`: JSON list of rows
    /// (`null` keeps the base value). Unknown paths and metrics raise here.
    #[new]
    #[pyo3(signature = (spec, names, rows, metrics=None, keep_cycle=false, threads=None))]
    fn new(
        spec: &str,
        names: Vec<String>,
        rows: &str,
        metrics: Option<Vec<String>>,
        keep_cycle: bool,
        threads: Option<usize>,
    ) -> PyResult<Self> {
        let base = parse(spec).py_err()?;
        let rows: Vec<Vec<serde_json::Value>> = serde_json::from_str(rows)
            .map_err(|e| Error::invalid("rows", e.to_string(), "a JSON list of rows"))
            .py_err()?;
        let plan =
            SweepPlan::new(base, &names, rows, metrics.as_deref(), keep_cycle, threads).py_err()?;
        Ok(Self {
            job: SweepJob::new(plan),
        })
    }

    /// Starts the run on a background thread.
    fn start(&self) -> PyResult<()> {
        self.job.start().py_err()
    }

    /// Stops scheduling new points; running points stop within milliseconds and are reported
    /// as not run.
    fn cancel(&self) {
        self.job.cancel();
    }

    /// Waits up to `timeout` seconds (None: until done), GIL released; True when done.
    #[pyo3(signature = (timeout=None))]
    fn wait(&self, py: Python<'_>, timeout: Option<f64>) -> PyResult<bool> {
        let timeout = match timeout {
            None => None,
            Some(t) if t.is_finite() && t >= 0.0 => Some(Duration::from_secs_f64(t)),
            Some(t) => {
                return Err(Error::invalid("timeout", t, "None or finite and >= 0 (s)")).py_err();
            }
        };
        py.detach(|| self.job.wait(timeout)).py_err()
    }

    /// Number of points.
    #[getter]
    fn total(&self) -> usize {
        self.job.plan().len()
    }

    /// Points finished so far.
    #[getter]
    fn finished(&self) -> usize {
        self.job.finished()
    }

    /// Whether the run was cancelled.
    #[getter]
    fn cancelled(&self) -> bool {
        self.job.is_cancelled()
    }

    /// Threads of the local pool.
    #[getter]
    fn threads(&self) -> usize {
        self.job.plan().threads()
    }

    /// Reported metric names.
    #[getter]
    fn metric_names(&self) -> Vec<String> {
        self.job.plan().metrics().to_vec()
    }

    /// Deprecation notes of the parameter names.
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.job.plan().notes()
    }

    /// Waits for the run (starting it if needed), GIL released.
    fn result(&self, py: Python<'_>) -> PyResult<SweepResult> {
        let outcome = py.detach(|| self.job.outcome()).py_err()?;
        Ok(SweepResult {
            n_metrics: self.job.plan().metrics().len(),
            outcome,
        })
    }
}

/// The outcome of a `SweepRun`, one entry per point in input order.
#[pyclass(module = "paritysim._core", frozen)]
pub struct SweepResult {
    n_metrics: usize,
    outcome: SweepOutcome,
}

#[pymethods]
impl SweepResult {
    /// Whether each point ran.
    #[getter]
    fn finished<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        PyArray1::from_slice(py, &self.outcome.finished)
    }

    /// Whether each point succeeded.
    #[getter]
    fn ok<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        PyArray1::from_slice(py, &self.outcome.ok)
    }

    /// Metrics `(points, metrics)`, NaN where not ok.
    #[getter]
    fn metrics<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let n = self.outcome.finished.len();
        shaped(py, self.outcome.metrics.clone(), &[n, self.n_metrics])
    }

    /// Steady state reached.
    #[getter]
    fn converged<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        PyArray1::from_slice(py, &self.outcome.converged)
    }

    /// Cycles before recording (-1 where not ok).
    #[getter]
    fn cycles_run<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        PyArray1::from_slice(py, &self.outcome.cycles_run)
    }

    /// Error messages (None where ok or not run).
    #[getter]
    fn error(&self) -> Vec<Option<String>> {
        self.outcome.error.clone()
    }

    /// Error kinds (None where ok or not run).
    #[getter]
    fn error_kind(&self) -> Vec<Option<String>> {
        self.outcome.error_kind.clone()
    }

    /// With `keep_cycle`: column -> per point the last cycle (None where not ok).
    #[getter]
    fn cycle(&self) -> Option<KeptCycles> {
        self.outcome.cycle.clone()
    }
}

/// Metric names `simulate` reports for a JSON spec, in order.
#[pyfunction]
fn sweep_metric_names(spec: &str) -> PyResult<Vec<String>> {
    let spec = parse(spec).py_err()?;
    spec.device().and_then(|d| spec.metric_names(&d)).py_err()
}

/// Trajectory column names (without `time_ms`) recorded for a JSON spec, in order.
#[pyfunction]
fn sweep_trajectory_columns(spec: &str) -> PyResult<Vec<String>> {
    let spec = parse(spec).py_err()?;
    spec.device().and_then(|d| spec.column_names(&d)).py_err()
}

/// The thread count a sweep would use: `threads`, else `$PARITYSIM_THREADS`, else all cores.
#[pyfunction]
#[pyo3(signature = (threads=None))]
fn sweep_resolve_threads(threads: Option<usize>) -> PyResult<usize> {
    resolve_threads(threads).py_err()
}

/// Adds the sweep classes and functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<SweepRun>()?;
    m.add_class::<SweepResult>()?;
    m.add("SWEEP_THREADS_ENV", THREADS_ENV)?;
    m.add_function(wrap_pyfunction!(sweep_metric_names, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_trajectory_columns, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_resolve_threads, m)?)?;
    Ok(())
}
