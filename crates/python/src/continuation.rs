//! Bindings of the continuation of periodic orbits (`paritysim_spec::continuation`): the run
//! and its records live in the core, results are `BranchRecord` / `CurveRecord` dicts.

use paritysim_spec::continuation::{ContinuationRun, ContinuationSettings};
use pyo3::prelude::*;

use crate::convert::{bindings, from_json, to_py};
use crate::spec::{cancellable, parse, within};

/// A continued branch, kept so that its bifurcations can be followed.
#[pyclass(module = "paritysim._core", frozen)]
pub struct ContinuationOutput {
    run: ContinuationRun,
}

#[pymethods]
impl ContinuationOutput {
    /// The branch (`BranchRecord`): columns per point plus the bifurcations.
    #[getter]
    fn record<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, &self.run.record())
    }

    /// Follows bifurcation `index` in `second_path` (`CurveRecord`; GIL released).
    #[pyo3(signature = (index, second_path, second_start, stop, max_step=None))]
    fn follow<'py>(
        &self,
        py: Python<'py>,
        index: usize,
        second_path: &str,
        second_start: f64,
        stop: f64,
        max_step: Option<f64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let run = &self.run;
        let curve = cancellable(py, || {
            run.follow(index, second_path, second_start, stop, max_step)
        })?;
        to_py(py, &curve)
    }
}

bindings! {
    run cancellable;
    class ContinuationOutput;

    /// Continues the periodic orbit of a JSON spec in `path` from `start` to `stop`, within
    /// `max_wall_ms` for the whole branch (None: only each orbit's `options.max_wall_ms`).
    #[pyo3(signature = (json, path, start, stop, settings_json, max_wall_ms = None))]
    fn continuation(
        json: &str,
        path: &str,
        start: f64,
        stop: f64,
        settings_json: &str,
        max_wall_ms: Option<f64>,
    ) -> ContinuationOutput {
        let settings: ContinuationSettings = from_json("settings", settings_json)?;
        let run = within(max_wall_ms, || {
            ContinuationRun::new(parse(json)?, path, start, stop, settings)
        })?;
        Ok(ContinuationOutput { run })
    }
}
