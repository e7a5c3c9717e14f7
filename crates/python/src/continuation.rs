//! Bindings of the continuation of periodic orbits (`paritysim-spec::continuation`).

use paritysim_continuation::{BranchPoint, Curve};
use paritysim_error::Error;
use paritysim_spec::Simulation;
use paritysim_spec::continuation::{
    ContinuationOutcome, ContinuationSettings, continue_bifurcation_path, continue_path,
};
use pyo3::prelude::*;

use crate::errors::IntoPyResult;
use crate::spec::{cancellable, parse};

type Complexes = Vec<(f64, f64)>;
/// `(first parameter, second parameter, multipliers)` of each curve point.
type CurveRows = Vec<(f64, f64, Complexes)>;

fn settings(json: &str) -> Result<ContinuationSettings, Error> {
    serde_json::from_str(json).map_err(|e| {
        Error::invalid(
            "settings",
            json,
            format!("known continuation settings ({e})"),
        )
    })
}

fn multipliers(p: &BranchPoint) -> Complexes {
    p.multipliers.iter().map(|m| (m.re, m.im)).collect()
}

/// A continued branch: one entry per point in the getters, plus the located bifurcations.
#[pyclass(module = "paritysim._core", frozen)]
pub struct ContinuationOutput {
    spec: Simulation,
    path: String,
    settings: ContinuationSettings,
    outcome: ContinuationOutcome,
}

#[pymethods]
impl ContinuationOutput {
    /// The continued parameter at each point.
    #[getter]
    fn parameter(&self) -> Vec<f64> {
        self.outcome
            .branch
            .points
            .iter()
            .map(|p| p.parameter)
            .collect()
    }
    /// The orbit's integrated state (coordinates, then rates) at phase 0, per point.
    #[getter]
    fn states(&self) -> Vec<Vec<f64>> {
        self.outcome
            .branch
            .points
            .iter()
            .map(|p| p.state.as_slice().to_vec())
            .collect()
    }
    /// Non-trivial Floquet multipliers `(re, im)`, largest modulus first, per point.
    #[getter]
    fn multipliers(&self) -> Vec<Complexes> {
        self.outcome.branch.points.iter().map(multipliers).collect()
    }
    /// `stable`, `unstable` or `marginal`, per point.
    #[getter]
    fn stability(&self) -> Vec<&'static str> {
        self.outcome
            .branch
            .points
            .iter()
            .map(|p| p.stability.name())
            .collect()
    }
    /// Newton iterations, residual, scaled arclength and cyclic drift, per point.
    #[getter]
    fn diagnostics(&self) -> Vec<(usize, f64, f64, f64)> {
        let b = &self.outcome.branch;
        b.points
            .iter()
            .map(|p| (p.iterations, p.residual, p.arclength, p.drift))
            .collect()
    }
    /// The orbit metrics of each point (empty lists when not computed).
    #[getter]
    fn metrics(&self) -> Vec<Vec<(String, f64)>> {
        self.outcome.metrics.clone()
    }
    /// `(kind, parameter, after, located, multipliers)` of each bifurcation, in branch order.
    #[getter]
    fn bifurcations(&self) -> Vec<(&'static str, f64, usize, bool, Complexes)> {
        let b = &self.outcome.branch;
        b.bifurcations
            .iter()
            .map(|x| {
                (
                    x.kind.name(),
                    x.point.parameter,
                    x.after,
                    x.located,
                    multipliers(&x.point),
                )
            })
            .collect()
    }
    /// Why the branch ended.
    #[getter]
    fn stop_reason(&self) -> String {
        format!("{:?}", self.outcome.branch.stop_reason)
    }
    /// Period-map evaluations with the monodromy (the cost).
    #[getter]
    fn map_evaluations(&self) -> usize {
        self.outcome.branch.map_evaluations
    }
    /// Deprecation notes of the path.
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.outcome.notes.clone()
    }

    /// Follows bifurcation `index` (a fold or period doubling) in `second_path` from
    /// `second_start` to `stop` (`max_step`: the curve's largest step, default the branch's):
    /// `[(first, second, multipliers)]` and the stop reason.
    #[pyo3(signature = (index, second_path, second_start, stop, max_step=None))]
    fn follow(
        &self,
        py: Python<'_>,
        index: usize,
        second_path: &str,
        second_start: f64,
        stop: f64,
        max_step: Option<f64>,
    ) -> PyResult<(CurveRows, String)> {
        let mut settings = self.settings.clone();
        if let Some(step) = max_step {
            if !(step.is_finite() && step >= settings.min_step) {
                return Err(Error::invalid(
                    "max_step",
                    step,
                    format!(">= min_step = {}", settings.min_step),
                ))
                .py_err();
            }
            settings.max_step = step;
            settings.initial_step = (0.25 * step).max(settings.min_step);
        }
        let n = self.outcome.branch.bifurcations.len();
        let bif = self
            .outcome
            .branch
            .bifurcations
            .get(index)
            .ok_or_else(|| Error::invalid("index", index, format!("a bifurcation index < {n}")))
            .py_err()?;
        let curve: Curve = cancellable(py, || {
            continue_bifurcation_path(
                &self.spec,
                &self.path,
                bif,
                self.outcome.parameter_scale,
                second_path,
                second_start,
                stop,
                &settings,
            )
        })?;
        let points = curve
            .points
            .iter()
            .map(|p| {
                (
                    p.parameters.0,
                    p.parameters.1,
                    p.multipliers.iter().map(|m| (m.re, m.im)).collect(),
                )
            })
            .collect();
        Ok((points, format!("{:?}", curve.stop_reason)))
    }
}

/// Continues the periodic orbit of a JSON spec in `path` from `start` to `stop` (GIL released).
#[pyfunction]
fn continuation(
    py: Python<'_>,
    json: &str,
    path: &str,
    start: f64,
    stop: f64,
    settings_json: &str,
) -> PyResult<ContinuationOutput> {
    let spec = parse(json).py_err()?;
    let settings = settings(settings_json).py_err()?;
    let outcome = cancellable(py, || continue_path(&spec, path, start, stop, &settings))?;
    Ok(ContinuationOutput {
        spec,
        path: path.to_string(),
        settings,
        outcome,
    })
}

/// Adds the continuation functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<ContinuationOutput>()?;
    m.add_function(wrap_pyfunction!(continuation, m)?)?;
    Ok(())
}
