//! Bindings of the sweep handle of paritysim-spec (`SweepRun`) and its outcome.
//!
//! The handle, its background thread, progress counter and cancel flag live in the core
//! ([`paritysim_spec::sweep::SweepJob`]); this is the mechanical translation: blocking calls
//! release the GIL, results are numpy arrays.

use numpy::PyArray1;
use paritysim_dynamics::sweep::{THREADS_ENV, resolve_threads};
use paritysim_spec::sweep::{
    KeptCycles, SweepJob, SweepPlan, rows_from_json, timeout_from_seconds,
};
use pyo3::prelude::*;

use crate::convert::{bindings, shaped};
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
        let (base, rows) = (parse(spec).py_err()?, rows_from_json(rows).py_err()?);
        let plan = SweepPlan::new(base, &names, rows, metrics.as_deref(), keep_cycle, threads);
        Ok(Self {
            job: SweepJob::new(plan.py_err()?),
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
        let timeout = timeout_from_seconds(timeout).py_err()?;
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
        let o = py.detach(|| self.job.outcome()).py_err()?;
        let shape = [o.finished.len(), self.job.plan().metrics().len()];
        Ok(SweepResult {
            finished: PyArray1::from_vec(py, o.finished).unbind(),
            ok: PyArray1::from_vec(py, o.ok).unbind(),
            metrics: shaped(py, o.metrics, &shape)?.unbind(),
            converged: PyArray1::from_vec(py, o.converged).unbind(),
            cycles_run: PyArray1::from_vec(py, o.cycles_run).unbind(),
            orbit_cycles: PyArray1::from_vec(py, o.orbit_cycles).unbind(),
            error: o.error,
            error_kind: o.error_kind,
            cycle: o.cycle,
        })
    }
}

/// The outcome of a `SweepRun` (`paritysim_spec::sweep::SweepOutcome`), one entry per point
/// in input order; `metrics` is `(points, metrics)`.
#[pyclass(module = "paritysim._core", frozen, get_all)]
pub struct SweepResult {
    finished: Py<PyArray1<bool>>,
    ok: Py<PyArray1<bool>>,
    metrics: Py<PyAny>,
    converged: Py<PyArray1<bool>>,
    cycles_run: Py<PyArray1<i64>>,
    orbit_cycles: Py<PyArray1<i64>>,
    error: Vec<Option<String>>,
    error_kind: Vec<Option<String>>,
    cycle: Option<KeptCycles>,
}

bindings! {
    class SweepRun;
    class SweepResult;
    const "SWEEP_THREADS_ENV" = THREADS_ENV;

    /// Metric names `simulate` reports for a JSON spec, in order.
    fn sweep_metric_names(spec: &str) -> Vec<String> {
        let spec = parse(spec)?;
        spec.metric_names(&spec.device()?)
    }

    /// Trajectory column names (without `time_ms`) recorded for a JSON spec, in order.
    fn sweep_trajectory_columns(spec: &str) -> Vec<String> {
        let spec = parse(spec)?;
        spec.column_names(&spec.device()?)
    }

    /// The trajectory columns of a JSON spec (without `time_ms`) with their units, in order.
    fn trajectory_column_units(spec: &str) -> Vec<(String, &'static str)> {
        let spec = parse(spec)?;
        spec.column_units(&spec.device()?)
    }

    /// The thread count a sweep would use: `threads`, else `$PARITYSIM_THREADS`, else all cores.
    #[pyo3(signature = (threads=None))]
    fn sweep_resolve_threads(threads: Option<usize>) -> usize {
        resolve_threads(threads)
    }
}
