//! Steady-state sensitivities with the parameters named by spec paths (`ps.sensitivity`):
//! the paths resolved and checked once here, the derivatives from
//! [`paritysim_dynamics::sensitivity`].

use paritysim_dynamics::SimulationOptions;
use paritysim_dynamics::sensitivity::{
    Orbit, SteadySensitivity, orbit_options, steady_sensitivity, steady_sensitivity_at, unconverged,
};
use paritysim_error::{Error, Result};
use serde_json::Value;

use crate::paths::{
    Parameter, apply_in_place, apply_to, field_paths, get, resolve_all_in, resolve_in, spec_paths,
};
use crate::spec::Simulation;

/// What [`sensitivity`] returns: the resolved parameters with their units and base values,
/// and the derivatives.
#[derive(Clone, Debug)]
pub struct Sensitivity {
    /// The parameters as resolved (canonical targets), in the caller's order.
    pub parameters: Vec<Parameter>,
    /// Each parameter's unit (`1` for dimensionless).
    pub units: Vec<String>,
    /// Each parameter's value in the spec.
    pub values: Vec<f64>,
    /// The derivatives (metric × parameter) and the orbit's multipliers.
    pub result: SteadySensitivity,
}

/// Derivatives of `spec`'s steady-state metrics (`metrics`, or all) with respect to the
/// continuous fields `params` (any spelling `ps.spec_paths` lists, `wings[*].…` included).
///
/// # Errors
/// [`Error::InvalidParameter`] naming a path that is unknown (with the nearest ones), not a
/// continuous number (a name, a kind, a count, a flag), whose `wings[*]` targets differ, or
/// whose field an earlier parameter names; a flying spec (`body.mode` other than fixed); those
/// of [`steady_sensitivity`].
pub fn sensitivity(
    spec: &Simulation,
    params: &[String],
    metrics: Option<&[String]>,
) -> Result<Sensitivity> {
    let value = serde_json::to_value(spec).expect("a spec serialises");
    let (parameters, units, _) = parameters_in(spec, &value, params)?;
    let (device, options) = prepared(spec, metrics)?;
    differentiate((spec, &value), parameters, units, &device, &options, None)
}

/// The device of a sensitivity at `spec` (a fixed body) and its options ([`orbit_options`]:
/// one recorded cycle, no columns, shooting; the asked metrics).
fn prepared(
    spec: &Simulation,
    metrics: Option<&[String]>,
) -> Result<(paritysim_dynamics::Device, SimulationOptions)> {
    let (device, options) = spec.model()?;
    if spec.flight(&device)?.is_some() {
        return Err(Error::invalid(
            "body.mode",
            "a moving body",
            "a fixed body: sensitivities are of the fixed-body steady state",
        ));
    }
    let options = spec.with_outputs(&device, &options, Some(&[]), metrics)?;
    Ok((device, orbit_options(&options)))
}

/// The derivatives at `spec`, serialised as `value` (its `device` and `options`, see
/// [`prepared`]) by the `parameters` (resolved on it or on a sweep's base spec: the paths are
/// the same; their values are read from `value`, the perturbed specs are `value` with them
/// set), at `orbit` when it is known (a sweep's converged point), else at the orbit a run from
/// the spec's own start reaches.
fn differentiate(
    (spec, value): (&Simulation, &Value),
    parameters: Vec<Parameter>,
    units: Vec<String>,
    device: &paritysim_dynamics::Device,
    options: &SimulationOptions,
    orbit: Option<&Orbit>,
) -> Result<Sensitivity> {
    let values = parameters
        .iter()
        .map(|p| value_of(value, p))
        .collect::<Result<Vec<_>>>()?;
    // A copy of the value per thread building devices, perturbed in place for each.
    let copies = std::sync::Mutex::new(Vec::new());
    let device_at = |p: &[f64]| -> Result<paritysim_dynamics::Device> {
        // Only the parameters that moved are set: the others are in the value already.
        let moved: Vec<(&Parameter, Value)> = parameters
            .iter()
            .zip(p.iter().zip(&values))
            .filter(|(_, (x, base))| x.to_bits() != base.to_bits())
            .map(|(param, (&x, _))| (param, Value::from(x)))
            .collect();
        let pairs: Vec<(&Parameter, &Value)> = moved.iter().map(|(p, v)| (*p, v)).collect();
        let lock = || {
            copies
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
        };
        let mut copy = lock().pop().unwrap_or_else(|| value.clone());
        let perturbed = apply_in_place(spec, &mut copy, &pairs);
        lock().push(copy);
        perturbed?.device()
    };
    let result = match orbit {
        Some(orbit) => steady_sensitivity_at(&device_at, device, &values, None, options, orbit)?,
        None => steady_sensitivity(&device_at, device, &values, None, options)?,
    };
    Ok(Sensitivity {
        parameters,
        units,
        values,
        result,
    })
}

/// The value of parameter `param` in the serialised spec `value`: one number on all its
/// targets (a `wings[*]` path), divided by the target's scale (`omega_ratio`).
fn value_of(value: &Value, param: &Parameter) -> Result<f64> {
    let mut base = None;
    for (path, scale) in &param.targets {
        let field = get(value, path).unwrap_or(&Value::Null);
        let Some(x) = field.as_f64().filter(|_| continuous(field)) else {
            return Err(Error::invalid(
                param.name.clone(),
                field.to_string(),
                format!(
                    "a continuous number to differentiate by ({path} is discrete or not a number)"
                ),
            ));
        };
        let x = scale.map_or(x, |s| x / s);
        match base {
            None => base = Some(x),
            Some(b) if b != x => {
                return Err(Error::invalid(
                    param.name.clone(),
                    format!("{b} and {x}"),
                    "one value on every wing: name each wing's path to differentiate by it",
                ));
            }
            Some(_) => {}
        }
    }
    base.ok_or_else(|| Error::invalid(param.name.clone(), "<no target>", "a spec path"))
}

/// The sensitivities at the points `rows` of `spec` (each a JSON object of spec paths and
/// values, as a sweep's rows apply them), one row per point, on `threads` of the sweep engine
/// (None: `PARITYSIM_THREADS`, else every core): `ps.sweep(..., gradients=...)`. A point that
/// fails is its row's error.
///
/// # Errors
/// [`Error::Cancelled`] when the caller's budget is cancelled; [`Error::InvalidParameter`] for
/// a bad thread count; the rest are per row.
pub fn sensitivities(
    spec: &Simulation,
    rows: &[String],
    params: &[String],
    metrics: Option<&[String]>,
    threads: Option<usize>,
) -> Result<SensitivityRows> {
    // The paths are resolved once on the base spec (as the sweep resolves its columns), the
    // gradients' and each row's: per point only the values change.
    let base = serde_json::to_value(spec).expect("a spec serialises");
    let (parameters, units, _) = parameters_in(spec, &base, params)?;
    let listed = field_paths(spec);
    let mut columns: Vec<(String, Parameter)> = Vec::new();
    let points: Vec<Result<Vec<(usize, Value)>>> = rows
        .iter()
        .map(|row| {
            let values: serde_json::Map<String, Value> =
                serde_json::from_str(row).map_err(|e| {
                    Error::invalid("values", e.to_string(), "a JSON object of path: value")
                })?;
            values
                .into_iter()
                .map(|(key, v)| {
                    let k = match columns.iter().position(|(name, _)| *name == key) {
                        Some(k) => k,
                        None => {
                            columns.push((key.clone(), resolve_in(spec, &listed, &key)?));
                            columns.len() - 1
                        }
                    };
                    Ok((k, v))
                })
                .collect()
        })
        .collect();
    // Each row's spec (serialised), device and options, on the sweep's threads.
    let rows_prepared =
        paritysim_dynamics::stability::rows::run_rows(rows.len(), threads, None, |i| {
            let point = points[i].as_ref().map_err(Clone::clone)?;
            let pairs: Vec<(&Parameter, &Value)> =
                point.iter().map(|(k, v)| (&columns[*k].1, v)).collect();
            let spec = apply_to(base.clone(), &pairs)?;
            let value = serde_json::to_value(&spec).expect("a spec serialises");
            let input = prepared(&spec, metrics)?;
            Ok(((spec, value), input))
        })?;
    let (values, inputs): (Vec<_>, Vec<_>) = rows_prepared
        .into_iter()
        .map(|r: Result<_>| match r {
            Ok((value, input)) => (Some(value), Ok(input)),
            Err(e) => (None, Err(e)),
        })
        .unzip();
    // The orbits as the sweep finds them (chained neighbours, SIMD lanes: a tenth of a cold
    // run each, docs/findings.md §30), then the derivatives at each.
    let names = metrics.map(<[String]>::to_vec).unwrap_or_default();
    // A cancel of the call (Ctrl-C) stops the sweep too.
    let control = paritysim_dynamics::sweep::SweepControl::of_current_budget();
    let orbits = paritysim_dynamics::sweep::run_points(&inputs, &names, false, threads, &control)?;
    let runs = paritysim_dynamics::stability::rows::run_rows(rows.len(), threads, None, |i| {
        let (device, options) = inputs[i].as_ref().map_err(Clone::clone)?;
        let found = orbits[i].as_ref().ok_or(Error::Cancelled)?;
        let found = found.as_ref().map_err(Clone::clone)?;
        if !found.converged {
            let time = found.cycles_run as f64 * device.period().unwrap_or(f64::NAN);
            return Err(unconverged(time, Vec::new(), found.residual));
        }
        let Some((p, p_dot)) = found.steady_state else {
            return Err(unconverged(f64::NAN, Vec::new(), found.residual));
        };
        let orbit = Orbit {
            state: device.state_from(&p, &p_dot)?,
            grid: found.step_grid.clone(),
            cycles: found.orbit_cycles,
            samples: None,
        };
        let (spec, value) = values[i].as_ref().expect("a prepared row has its spec");
        differentiate(
            (spec, value),
            parameters.clone(),
            units.clone(),
            device,
            options,
            Some(&orbit),
        )
        .map(|s| s.record())
    })?;
    Ok(SensitivityRows {
        error: runs
            .iter()
            .map(|r| r.as_ref().err().map(ToString::to_string))
            .collect(),
        error_kind: runs
            .iter()
            .map(|r| r.as_ref().err().map(|e| e.kind()))
            .collect(),
        rows: runs.into_iter().map(Result::ok).collect(),
    })
}

/// [`sensitivities`] for the bindings: per point its record, or its error and the error's kind.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SensitivityRows {
    /// Each point's derivatives (None where it failed).
    pub rows: Vec<Option<SensitivityRecord>>,
    /// Each failed point's error message.
    pub error: Vec<Option<String>>,
    /// Each failed point's error kind (`Integration`, `InvalidParameter`, ...).
    pub error_kind: Vec<Option<&'static str>>,
}

/// The parameters `params` of `spec` resolved, with their units and values: what
/// [`sensitivity`] differentiates by (a sweep checks its `gradients` with it before running).
///
/// # Errors
/// As [`sensitivity`] for the paths.
pub fn parameters(
    spec: &Simulation,
    params: &[String],
) -> Result<(Vec<Parameter>, Vec<String>, Vec<f64>)> {
    parameters_in(
        spec,
        &serde_json::to_value(spec).expect("a spec serialises"),
        params,
    )
}

/// [`parameters`] with the spec also given serialised as `value`.
fn parameters_in(
    spec: &Simulation,
    value: &Value,
    params: &[String],
) -> Result<(Vec<Parameter>, Vec<String>, Vec<f64>)> {
    if params.is_empty() {
        return Err(Error::invalid(
            "params",
            "[]",
            "at least one continuous spec path (see ps.spec_paths)",
        ));
    }
    let (resolved, listed) = resolve_all_in(spec, value, params)?;
    // A field named twice (the same path, or two spellings of it) would be two columns of one
    // derivative, and two design variables writing one field in `ps.optimize`.
    for (i, param) in resolved.iter().enumerate() {
        if let Some(first) = resolved[..i].iter().find(|p| p.targets == param.targets) {
            return Err(Error::invalid(
                param.name.clone(),
                format!("the field of `{}`", first.name),
                "each spec field once among the parameters",
            ));
        }
    }
    let mut parameters = Vec::new();
    let mut units = Vec::new();
    let mut values = Vec::new();
    for (name, param) in params.iter().zip(resolved) {
        let mut base = None;
        for (path, scale) in &param.targets {
            let info = listed
                .iter()
                .find(|i| &i.path == path)
                .expect("a resolved path is listed");
            let Some(x) = info.value.as_f64().filter(|_| continuous(&info.value)) else {
                let allowed = spec_paths(spec)
                    .into_iter()
                    .find(|i| &i.path == path)
                    .map(|i| i.allowed)
                    .unwrap_or_default();
                return Err(Error::invalid(
                    name.clone(),
                    info.value.to_string(),
                    format!(
                        "a continuous number to differentiate by ({path}: {allowed} is discrete or not a number)"
                    ),
                ));
            };
            let x = scale.map_or(x, |s| x / s);
            match base {
                None => {
                    base = Some(x);
                    // An `omega_ratio` scales the target (Ω1): a multiplier, dimensionless.
                    units.push(if scale.is_some() {
                        "1".to_string()
                    } else {
                        info.unit.clone()
                    });
                }
                Some(b) if b != x => {
                    return Err(Error::invalid(
                        name.clone(),
                        format!("{b} and {x}"),
                        "one value on every wing: name each wing's path to differentiate by it",
                    ));
                }
                Some(_) => {}
            }
        }
        values.push(base.expect("a resolved parameter has a target"));
        parameters.push(param);
    }
    Ok((parameters, units, values))
}

/// [`Sensitivity`] as plain columns for the bindings (`ps.sensitivity`'s table).
#[derive(Clone, Debug, serde::Serialize)]
pub struct SensitivityRecord {
    /// Metric names, in the window's order.
    pub metric: Vec<String>,
    /// The metrics at the spec's point.
    pub value: Vec<f64>,
    /// Per metric: why its derivatives are not to be trusted (empty: differentiable).
    pub not_differentiable: Vec<String>,
    /// Parameter names as the caller gave them.
    pub parameter: Vec<String>,
    /// Their units.
    pub unit: Vec<String>,
    /// Their values in the spec.
    pub parameter_value: Vec<f64>,
    /// Per parameter: why the orbit is not differentiable in it here (empty: it is; its
    /// `jacobian` and `state_jacobian` columns are then NaN).
    pub parameter_not_differentiable: Vec<String>,
    /// `∂metric/∂parameter`: one column (over the metrics) per parameter.
    pub jacobian: Vec<Vec<f64>>,
    /// `dx*/dp`: the orbit's start state (coordinates, then rates), one column per parameter.
    pub state_jacobian: Vec<Vec<f64>>,
    /// Floquet multipliers of the exact monodromy, largest modulus first, as `[re, im]`.
    pub multipliers: Vec<[f64; 2]>,
    /// Neutral directions (multiplier 1) left out of the orbit's derivative.
    pub neutral_directions: usize,
    /// The orbit's period-map residual on its grid.
    pub residual: f64,
    /// Deprecation notes of the parameter names (an old spelling such as `drivetrain.k2`).
    pub notes: Vec<String>,
}

impl Sensitivity {
    /// The plain-column form.
    pub fn record(&self) -> SensitivityRecord {
        let r = &self.result;
        let columns = |m: &nalgebra::DMatrix<f64>| {
            m.column_iter()
                .map(|c| c.iter().copied().collect())
                .collect()
        };
        SensitivityRecord {
            metric: r.metrics.iter().map(|(m, _)| m.clone()).collect(),
            value: r.metrics.iter().map(|(_, v)| *v).collect(),
            not_differentiable: r
                .not_differentiable
                .iter()
                .map(|f| f.clone().unwrap_or_default())
                .collect(),
            parameter: self.parameters.iter().map(|p| p.name.clone()).collect(),
            unit: self.units.clone(),
            parameter_value: self.values.clone(),
            parameter_not_differentiable: r
                .parameter_not_differentiable
                .iter()
                .map(|f| f.clone().unwrap_or_default())
                .collect(),
            jacobian: columns(&r.jacobian),
            state_jacobian: columns(&r.state_jacobian),
            multipliers: r.multipliers.iter().map(|z| [z.re, z.im]).collect(),
            neutral_directions: r.neutral_directions,
            residual: r.residual,
            notes: self
                .parameters
                .iter()
                .flat_map(|p| p.notes.iter().cloned())
                .collect(),
        }
    }
}

/// A JSON number that is a float field (integers are counts and indices: discrete).
fn continuous(value: &Value) -> bool {
    value.is_f64()
}
