//! Continuation of a spec's periodic orbit in one parameter path (issue 18): the path language
//! of [`crate::paths`] chooses the parameter, [`paritysim_continuation`] follows the orbit, and
//! every point gets the orbit's metrics.

use paritysim_continuation::{
    Bifurcation, Branch, ContinuationOptions, Curve, CurveOptions, Method, continue_fold_curve,
    continue_orbits,
};
use paritysim_dynamics::continuation::DevicePeriodMap;
use paritysim_dynamics::integrate::budget;
use paritysim_dynamics::simulate::orbit_metrics;
use paritysim_dynamics::stability::{ShootingOptions, compact_state, expand_state, periodic_orbit};
use paritysim_dynamics::{Device, SimulationOptions};
use paritysim_error::{Error, Result};
use rayon::prelude::*;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::paths::{Parameter, apply, resolve};
use crate::spec::Simulation;

/// Settings of a continuation (what `ps.continuation` accepts as keywords).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct ContinuationSettings {
    /// `"arclength"` (turns around folds) or `"natural"` (steps the parameter).
    pub method: String,
    /// First step, in scaled arclength (parameter / `parameter_scale` for natural).
    pub initial_step: f64,
    /// Smallest step before giving up.
    pub min_step: f64,
    /// Largest step.
    pub max_step: f64,
    /// Most points.
    pub max_points: usize,
    /// Newton tolerance on `|P(x) − x|∞`.
    pub tolerance: f64,
    /// Parameter units per state unit in the arclength (None: |start − stop| / 10).
    pub parameter_scale: Option<f64>,
    /// `|μ| − 1` within this is marginal.
    pub multiplier_tolerance: f64,
    /// Index of a cyclic integrated coordinate (e.g. 1 for q2 of a K2 = 0 linear whippletree).
    pub cyclic: Option<usize>,
    /// Locate bifurcations by bisection.
    pub locate: bool,
    /// Compute each point's orbit metrics (one recorded period per point).
    pub metrics: bool,
}

impl Default for ContinuationSettings {
    fn default() -> Self {
        let o = ContinuationOptions::new(0, 1.0);
        ContinuationSettings {
            method: "arclength".into(),
            initial_step: 0.05,
            min_step: 1e-6,
            max_step: 0.5,
            max_points: 400,
            tolerance: 1e-9,
            parameter_scale: None,
            multiplier_tolerance: o.multiplier_tolerance,
            cyclic: None,
            locate: true,
            metrics: true,
        }
    }
}

/// A continued branch with the metrics of each point.
#[derive(Clone, Debug)]
pub struct ContinuationOutcome {
    /// The branch.
    pub branch: Branch,
    /// Metrics of each branch point (empty without `metrics`; a point whose recording fails
    /// gets none).
    pub metrics: Vec<Vec<(String, f64)>>,
    /// Deprecation notes of the path.
    pub notes: Vec<String>,
    /// Parameter units per state unit used in the arclength.
    pub parameter_scale: f64,
}

fn shooting(options: &SimulationOptions) -> ShootingOptions {
    ShootingOptions {
        method: options.method,
        rtol: options.rtol.min(1e-10),
        atol: options.atol.min(1e-12),
        max_steps: options.max_steps,
        ..ShootingOptions::default()
    }
}

fn builder<'a>(
    spec: &'a Simulation,
    params: &'a [Parameter],
) -> impl Fn(&[f64]) -> Result<Device> + Sync + 'a {
    move |values: &[f64]| {
        let values: Vec<Value> = values.iter().map(|&v| Value::from(v)).collect();
        let pairs: Vec<(&Parameter, &Value)> = params.iter().zip(values.iter()).collect();
        apply(spec, &pairs)?.device()
    }
}

/// Follows the periodic orbit of `spec` as `path` goes from `start` to `stop`.
///
/// # Errors
/// [`Error::InvalidParameter`] for an unknown path or bad settings; the errors of finding the
/// first orbit (Newton shooting at `start`).
pub fn continue_path(
    spec: &Simulation,
    path: &str,
    start: f64,
    stop: f64,
    settings: &ContinuationSettings,
) -> Result<ContinuationOutcome> {
    let param = resolve(spec, path)?;
    let notes = param.notes.clone();
    let params = [param];
    let build = builder(spec, &params);
    let (_, sim_options) = spec.model()?;
    let shoot = shooting(&sim_options);
    let first = build(&[start]).map_err(|e| e.in_field(path))?;
    let orbit = periodic_orbit(&first, &shoot)?;
    let map = DevicePeriodMap::new(&build, &[start], &shoot)?;
    let mut options = ContinuationOptions::new(0, stop);
    options.method = match settings.method.as_str() {
        "arclength" => Method::PseudoArclength,
        "natural" => Method::Natural,
        other => {
            return Err(Error::invalid(
                "method",
                other,
                "\"arclength\" or \"natural\"",
            ));
        }
    };
    options.initial_step = settings.initial_step;
    options.min_step = settings.min_step;
    options.max_step = settings.max_step;
    options.max_points = settings.max_points;
    options.tolerance = settings.tolerance;
    options.parameter_scale = settings
        .parameter_scale
        .unwrap_or_else(|| ((stop - start).abs() / 10.0).max(f64::MIN_POSITIVE));
    options.multiplier_tolerance = settings.multiplier_tolerance;
    options.cyclic = settings.cyclic;
    options.locate = settings.locate;
    let x0 = compact_state(first.n_dof(), &orbit.state);
    let branch = continue_orbits(&map, &x0, &[start], &options)?;
    let metrics = if settings.metrics {
        let run_budget = budget::current();
        branch
            .points
            .par_iter()
            .map(|p| {
                let _budget = run_budget.clone().map(budget::Budget::enter);
                build(&[p.parameter])
                    .and_then(|d| {
                        orbit_metrics(&d, &expand_state(d.n_dof(), &p.state), &sim_options)
                    })
                    .unwrap_or_default()
            })
            .collect()
    } else {
        Vec::new()
    };
    Ok(ContinuationOutcome {
        parameter_scale: options.parameter_scale,
        branch,
        metrics,
        notes,
    })
}

/// Smallest Newton tolerance of a bifurcation curve: its test function is a derivative of the
/// computed (adaptive-step) map, so its noise floor lies far above the branch's.
pub const CURVE_TOLERANCE_FLOOR: f64 = 1e-7;

/// Follows a located fold or period doubling of a branch of `path` (continued with
/// `parameter_scale`) in a second path.
///
/// # Errors
/// As [`continue_fold_curve`], and for unknown paths.
#[allow(clippy::too_many_arguments)]
pub fn continue_bifurcation_path(
    spec: &Simulation,
    path: &str,
    bifurcation: &Bifurcation,
    parameter_scale: f64,
    second_path: &str,
    second_start: f64,
    stop: f64,
    settings: &ContinuationSettings,
) -> Result<Curve> {
    let params = [resolve(spec, path)?, resolve(spec, second_path)?];
    let build = builder(spec, &params);
    let (_, sim_options) = spec.model()?;
    let shoot = shooting(&sim_options);
    let start = [bifurcation.point.parameter, second_start];
    let map = DevicePeriodMap::new(&build, &start, &shoot)?;
    let mut options = CurveOptions::new(1, stop);
    options.initial_step = settings.initial_step;
    options.min_step = settings.min_step;
    options.max_step = settings.max_step;
    options.max_points = settings.max_points;
    options.tolerance = settings.tolerance.max(CURVE_TOLERANCE_FLOOR);
    options.parameter_scales = (
        parameter_scale,
        ((stop - second_start).abs() / 10.0).max(f64::MIN_POSITIVE),
    );
    continue_fold_curve(&map, bifurcation, &start, 0, &options)
}
