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
    // Its errors name their spec paths already (`apply` resolves `path`).
    let first = build(&[start])?;
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

/// A multiplier as `[re, im]`.
fn pair(m: &nalgebra::Complex<f64>) -> [f64; 2] {
    [m.re, m.im]
}

/// A continued branch as plain columns (one entry per point), what crosses a language boundary.
#[derive(Clone, Debug, Serialize)]
pub struct BranchRecord {
    /// The continued parameter.
    pub parameter: Vec<f64>,
    /// The orbit's integrated state (coordinates, then rates) at phase 0.
    pub states: Vec<Vec<f64>>,
    /// Non-trivial Floquet multipliers `[re, im]`, largest modulus first.
    pub multipliers: Vec<Vec<[f64; 2]>>,
    /// `stable`, `unstable` or `marginal`.
    pub stability: Vec<&'static str>,
    /// Newton iterations.
    pub iterations: Vec<usize>,
    /// Newton residual.
    pub residual: Vec<f64>,
    /// Scaled arclength.
    pub arclength: Vec<f64>,
    /// Cyclic drift.
    pub drift: Vec<f64>,
    /// Orbit metrics `(name, value)` (empty lists when not computed).
    pub metrics: Vec<Vec<(String, f64)>>,
    /// The bifurcations, in branch order.
    pub bifurcations: Vec<BifurcationRecord>,
    /// Why the branch ended.
    pub stop_reason: String,
    /// Period-map evaluations with the monodromy (the cost).
    pub map_evaluations: usize,
    /// Deprecation notes of the path.
    pub notes: Vec<String>,
}

/// One bifurcation of a [`BranchRecord`].
#[derive(Clone, Debug, Serialize)]
pub struct BifurcationRecord {
    /// `fold`, `period_doubling`, ...
    pub kind: &'static str,
    /// The parameter at the bifurcation.
    pub parameter: f64,
    /// Index of the branch point before it.
    pub after: usize,
    /// Whether it was located (not only bracketed).
    pub located: bool,
    /// Its multipliers `[re, im]`.
    pub multipliers: Vec<[f64; 2]>,
}

/// A two-parameter bifurcation curve as columns.
#[derive(Clone, Debug, Serialize)]
pub struct CurveRecord {
    /// The branch's parameter at each curve point.
    pub first: Vec<f64>,
    /// The second parameter.
    pub second: Vec<f64>,
    /// Multipliers `[re, im]` per point.
    pub multipliers: Vec<Vec<[f64; 2]>>,
    /// Why the curve ended.
    pub stop_reason: String,
}

/// A continuation that ran: what it continued and its outcome, so a bifurcation can be
/// followed further.
#[derive(Clone, Debug)]
pub struct ContinuationRun {
    spec: Simulation,
    path: String,
    settings: ContinuationSettings,
    outcome: ContinuationOutcome,
}

impl ContinuationRun {
    /// [`continue_path`], kept with its inputs.
    ///
    /// # Errors
    /// As [`continue_path`].
    pub fn new(
        spec: Simulation,
        path: &str,
        start: f64,
        stop: f64,
        settings: ContinuationSettings,
    ) -> Result<Self> {
        let outcome = continue_path(&spec, path, start, stop, &settings)?;
        Ok(Self {
            spec,
            path: path.to_string(),
            settings,
            outcome,
        })
    }

    /// The outcome.
    pub fn outcome(&self) -> &ContinuationOutcome {
        &self.outcome
    }

    /// The branch as columns.
    pub fn record(&self) -> BranchRecord {
        let b = &self.outcome.branch;
        let column = |f: fn(&paritysim_continuation::BranchPoint) -> f64| -> Vec<f64> {
            b.points.iter().map(f).collect()
        };
        BranchRecord {
            parameter: column(|p| p.parameter),
            states: b
                .points
                .iter()
                .map(|p| p.state.as_slice().to_vec())
                .collect(),
            multipliers: b
                .points
                .iter()
                .map(|p| p.multipliers.iter().map(pair).collect())
                .collect(),
            stability: b.points.iter().map(|p| p.stability.name()).collect(),
            iterations: b.points.iter().map(|p| p.iterations).collect(),
            residual: column(|p| p.residual),
            arclength: column(|p| p.arclength),
            drift: column(|p| p.drift),
            metrics: self.outcome.metrics.clone(),
            bifurcations: b
                .bifurcations
                .iter()
                .map(|x| BifurcationRecord {
                    kind: x.kind.name(),
                    parameter: x.point.parameter,
                    after: x.after,
                    located: x.located,
                    multipliers: x.point.multipliers.iter().map(pair).collect(),
                })
                .collect(),
            stop_reason: format!("{:?}", b.stop_reason),
            map_evaluations: b.map_evaluations,
            notes: self.outcome.notes.clone(),
        }
    }

    /// Follows bifurcation `index` (a fold or period doubling) in `second_path` from
    /// `second_start` to `stop`; `max_step` (scaled arclength, the first step a quarter of
    /// it) defaults to the branch's.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for an index past the bifurcations or `max_step` below
    /// `min_step`; as [`continue_bifurcation_path`].
    pub fn follow(
        &self,
        index: usize,
        second_path: &str,
        second_start: f64,
        stop: f64,
        max_step: Option<f64>,
    ) -> Result<CurveRecord> {
        let mut settings = self.settings.clone();
        if let Some(step) = max_step {
            if !(step.is_finite() && step >= settings.min_step) {
                let allowed = format!(">= min_step = {}", settings.min_step);
                return Err(Error::invalid("max_step", step, allowed));
            }
            settings.max_step = step;
            settings.initial_step = (0.25 * step).max(settings.min_step);
        }
        let bifurcations = &self.outcome.branch.bifurcations;
        let n = bifurcations.len();
        let bif = bifurcations
            .get(index)
            .ok_or_else(|| Error::invalid("index", index, format!("a bifurcation index < {n}")))?;
        let curve = continue_bifurcation_path(
            &self.spec,
            &self.path,
            bif,
            self.outcome.parameter_scale,
            second_path,
            second_start,
            stop,
            &settings,
        )?;
        Ok(CurveRecord {
            first: curve.points.iter().map(|p| p.parameters.0).collect(),
            second: curve.points.iter().map(|p| p.parameters.1).collect(),
            multipliers: curve
                .points
                .iter()
                .map(|p| p.multipliers.iter().map(pair).collect())
                .collect(),
            stop_reason: format!("{:?}", curve.stop_reason),
        })
    }
}
