//! Bindings of paritysim-dynamics: a device spec arrives as a plain dict (built by the Python
//! dataclasses in `paritysim.spec`), is validated here with dotted field paths, and runs with
//! the GIL released.

use nalgebra::Matrix3;
use numpy::PyArray1;
use paritysim_constraints::{Constraints, Vec6};
use paritysim_dynamics::device::{Device, DeviceSpec, Formulation, Transmission};
use paritysim_dynamics::integrate::Method;
use paritysim_dynamics::simulate::PerturbTarget;
use paritysim_dynamics::{
    Actuator, DcOffset, JointSpring, Perturbation, SimulationOptions, SimulationResult,
    SteadyState, Waveform, Wing, WingAero,
};
use paritysim_error::{Error, Result};

use paritysim_kinematics::drivetrain::{HmfFourBar, LinearDifferential, LinkageDifferential};
use paritysim_kinematics::{Drivetrain, RodCrank, SphericalShoulder};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::errors::IntoPyResult;

/// A borrowed dict with its dotted path, for error messages.
struct Node<'a, 'py> {
    dict: &'a Bound<'py, PyDict>,
    path: String,
}

fn invalid(path: &str, value: impl std::fmt::Display, allowed: &str) -> Error {
    Error::invalid(path.to_string(), value, allowed)
}

impl<'py> Node<'_, 'py> {
    fn field(&self, key: &str) -> String {
        if self.path.is_empty() {
            key.to_string()
        } else {
            format!("{}.{key}", self.path)
        }
    }

    fn get(&self, key: &str) -> Option<Bound<'py, PyAny>> {
        self.dict
            .get_item(key)
            .ok()
            .flatten()
            .filter(|v| !v.is_none())
    }

    fn f64_or(&self, key: &str, default: f64) -> Result<f64> {
        match self.get(key) {
            None => Ok(default),
            Some(v) => {
                let x: f64 = v.extract().map_err(|_| {
                    invalid(
                        &self.field(key),
                        v.repr().map(|r| r.to_string()).unwrap_or_default(),
                        "a number",
                    )
                })?;
                if !x.is_finite() {
                    return Err(invalid(&self.field(key), x, "a finite number"));
                }
                Ok(x)
            }
        }
    }

    fn f64(&self, key: &str) -> Result<f64> {
        if self.get(key).is_none() {
            return Err(invalid(&self.field(key), "missing", "a number"));
        }
        self.f64_or(key, 0.0)
    }

    fn usize_or(&self, key: &str, default: usize) -> Result<usize> {
        match self.get(key) {
            None => Ok(default),
            Some(v) => v
                .extract()
                .map_err(|_| invalid(&self.field(key), v, "a non-negative integer")),
        }
    }

    fn str_or(&self, key: &str, default: &str) -> Result<String> {
        match self.get(key) {
            None => Ok(default.to_string()),
            Some(v) => v
                .extract()
                .map_err(|_| invalid(&self.field(key), v, "a string")),
        }
    }

    fn vec(&self, key: &str) -> Result<Option<Vec<f64>>> {
        match self.get(key) {
            None => Ok(None),
            Some(v) => {
                let x: Vec<f64> = v
                    .extract()
                    .map_err(|_| invalid(&self.field(key), v, "a list of numbers"))?;
                for (i, e) in x.iter().enumerate() {
                    if !e.is_finite() {
                        return Err(invalid(
                            &format!("{}[{i}]", self.field(key)),
                            e,
                            "a finite number",
                        ));
                    }
                }
                Ok(Some(x))
            }
        }
    }
}

fn child<'a, 'py>(
    parent: &Node<'_, 'py>,
    key: &str,
    holder: &'a mut Option<Bound<'py, PyDict>>,
) -> Result<Option<Node<'a, 'py>>> {
    match parent.get(key) {
        None => Ok(None),
        Some(v) => {
            let d = v
                .cast_into::<PyDict>()
                .map_err(|_| invalid(&parent.field(key), "not a dict", "a table / dict"))?;
            *holder = Some(d);
            Ok(Some(Node {
                dict: holder.as_ref().unwrap(),
                path: parent.field(key),
            }))
        }
    }
}

fn parse_wing(node: &Node<'_, '_>) -> Result<Wing> {
    let mut h = None;
    let shoulder = match child(node, "shoulder", &mut h)? {
        Some(s) => SphericalShoulder::new(
            s.f64_or("alpha2", std::f64::consts::FRAC_PI_2)?,
            s.f64_or("alpha3", 0.0)?,
        ),
        None => SphericalShoulder::new(std::f64::consts::FRAC_PI_2, 0.0),
    }
    .map_err(|e| e.in_field(&node.field("shoulder")))?;
    let inertia_path = node.field("inertia");
    let rows: Vec<Vec<f64>> = match node.get("inertia") {
        None => return Err(invalid(&inertia_path, "missing", "a 3x3 tensor (mg mm^2)")),
        Some(v) => v
            .extract()
            .map_err(|_| invalid(&inertia_path, v, "a 3x3 list of numbers (mg mm^2)"))?,
    };
    if rows.len() != 3 || rows.iter().any(|r| r.len() != 3) {
        return Err(invalid(
            &inertia_path,
            format!("{rows:?}"),
            "a 3x3 tensor (mg mm^2)",
        ));
    }
    let inertia = Matrix3::from_fn(|i, j| rows[i][j]);
    let mut springs = [JointSpring::default(); 6];
    if let Some(list) = node.get("springs") {
        let list = list.cast_into::<PyList>().map_err(|_| {
            invalid(
                &node.field("springs"),
                "not a list",
                "a list of 6 spring tables",
            )
        })?;
        if list.len() != 6 {
            return Err(invalid(
                &node.field("springs"),
                list.len(),
                "exactly 6 springs (joints 1..6)",
            ));
        }
        for (j, item) in list.iter().enumerate() {
            let d = item.cast_into::<PyDict>().map_err(|_| {
                invalid(
                    &format!("{}[{j}]", node.field("springs")),
                    "not a dict",
                    "a spring table",
                )
            })?;
            let n = Node {
                dict: &d,
                path: format!("{}[{j}]", node.field("springs")),
            };
            springs[j] = JointSpring::nonlinear(
                n.f64_or("stiffness", 0.0)?,
                n.f64_or("cubic", 0.0)?,
                n.f64_or("rest_angle", 0.0)?,
            )
            .map_err(|e| e.in_field(&n.path))?;
        }
    }
    let mut h2 = None;
    let aero = match child(node, "aero", &mut h2)? {
        None => WingAero::None,
        Some(a) => match a.str_or("kind", "stroke_drag")?.as_str() {
            "none" => WingAero::None,
            "stroke_drag" => WingAero::stroke_drag(a.f64("omega1")?, a.f64_or("coefficient", 1.0)?)
                .map_err(|e| e.in_field(&a.path))?,
            "blade_element" => {
                use paritysim_aero::{BladeElementModel, CoefficientSet, NormalForceLaw, Omegas};
                let wrap = |e: Error| e.in_field(&a.path);
                let omegas = Omegas::new(
                    a.f64("omega1")?,
                    a.f64_or("omega2", 0.0)?,
                    a.f64_or("omega3", 0.0)?,
                    a.f64_or("omega4", 0.0)?,
                )
                .map_err(wrap)?;
                let coefficients = CoefficientSet::from_name(&a.str_or("model", "dickinson1999")?)
                    .map_err(wrap)?;
                let law = match a.str_or("normal_force_law", "coefficient")?.as_str() {
                    "coefficient" => NormalForceLaw::Coefficient,
                    "unit" => NormalForceLaw::Unit,
                    other => {
                        return Err(invalid(
                            &a.field("normal_force_law"),
                            other,
                            "coefficient or unit",
                        ));
                    }
                };
                let c_rd = a.f64_or(
                    "rotational_damping",
                    paritysim_aero::DEFAULT_ROTATIONAL_DAMPING,
                )?;
                let model = BladeElementModel::new(omegas, coefficients)
                    .and_then(|m| m.with_rotational_damping(c_rd))
                    .map_err(wrap)?
                    .with_normal_force_law(law);
                WingAero::BladeElement(model)
            }
            other => {
                return Err(invalid(
                    &a.field("kind"),
                    other,
                    "one of none, stroke_drag, blade_element",
                ));
            }
        },
    };
    let wing = Wing::new(shoulder, inertia, springs, aero).map_err(|e| e.in_field(&node.path))?;
    let mut h3 = None;
    Ok(match child(node, "tunable_hinge", &mut h3)? {
        None => wing,
        Some(t) => wing.with_tunable_hinge(
            paritysim_dynamics::TunableHinge::new(
                t.f64("k0")?,
                t.f64_or("k1", 0.0)?,
                t.f64_or("k2", 0.0)?,
            )
            .map_err(|e| e.in_field(&t.path))?,
        ),
    })
}

fn parse_drivetrain(node: &Node<'_, '_>) -> Result<Drivetrain> {
    let kind = node.str_or("kind", "linkage_differential")?;
    let wrap = |e: Error| e.in_field(&node.path);
    Ok(match kind.as_str() {
        "hmf_four_bar" => Drivetrain::HmfFourBar(HmfFourBar::new(
            RodCrank::new(node.f64_or("crank_mm", 0.4)?, node.f64_or("rod_mm", 0.8)?)
                .map_err(wrap)?,
        )),
        "linear_differential" => Drivetrain::LinearDifferential(
            LinearDifferential::new(
                node.f64_or("transmission_ratio", 2.5)?,
                node.f64_or("arm_length_mm", 2.5)?,
                node.f64_or("arm_ratio", 1.0)?,
            )
            .map_err(wrap)?,
        ),
        "linkage_differential" => Drivetrain::LinkageDifferential(
            LinkageDifferential::new(
                RodCrank::new(node.f64_or("crank_mm", 0.4)?, node.f64_or("rod_mm", 0.8)?)
                    .map_err(wrap)?,
                node.f64_or("whippletree_length_mm", 5.0)?,
                node.f64_or("arm_ratio", 1.0)?,
            )
            .map_err(wrap)?,
        ),
        other => {
            return Err(invalid(
                &node.field("kind"),
                other,
                "one of hmf_four_bar, linear_differential, linkage_differential",
            ));
        }
    })
}

fn parse_waveform(node: &Node<'_, '_>) -> Result<Waveform> {
    let wrap = |e: Error| e.in_field(&node.path);
    match node.str_or("kind", "sine")?.as_str() {
        "sine" => Waveform::sine(
            node.f64("amplitude_v")?,
            node.f64("frequency_hz")?,
            node.f64_or("offset_v", 0.0)?,
            node.f64_or("phase", 0.0)?,
        )
        .map_err(wrap),
        "sampled" => Waveform::sampled(
            node.vec("times_ms")?.unwrap_or_default(),
            node.vec("voltages_v")?.unwrap_or_default(),
            node.f64("period_ms")?,
        )
        .map_err(wrap),
        other => Err(invalid(&node.field("kind"), other, "one of sine, sampled")),
    }
}

/// Builds and validates a device from its dict spec.
pub(crate) fn parse_device(spec: &Bound<'_, PyDict>) -> Result<Device> {
    let root = Node {
        dict: spec,
        path: String::new(),
    };
    let wings_any = root
        .get("wings")
        .ok_or_else(|| invalid("wings", "missing", "a list of 1 or 2 wings"))?;
    let wings_list = wings_any
        .cast_into::<PyList>()
        .map_err(|_| invalid("wings", "not a list", "a list of 1 or 2 wings"))?;
    if !(1..=2).contains(&wings_list.len()) {
        return Err(invalid(
            "wings",
            wings_list.len(),
            "1 or 2 wings (left first)",
        ));
    }
    let mut wings = Vec::new();
    for (i, w) in wings_list.iter().enumerate() {
        let d = w
            .cast_into::<PyDict>()
            .map_err(|_| invalid(&format!("wings[{i}]"), "not a dict", "a wing table"))?;
        wings.push(parse_wing(&Node {
            dict: &d,
            path: format!("wings[{i}]"),
        })?);
    }
    let n_coords = 3 * wings.len();
    let constraints = match root.get("configuration") {
        None => Constraints::none(n_coords)?,
        Some(v) => {
            if let Ok(name) = v.extract::<String>() {
                Constraints::configuration(&name)?
            } else {
                let d = v
                    .cast_into::<PyDict>()
                    .map_err(|_| invalid("configuration", "?", "a Table 3.1 name or {rows, c0}"))?;
                let n = Node {
                    dict: &d,
                    path: "configuration".into(),
                };
                let rows: Vec<Vec<f64>> = match n.get("rows") {
                    None => Vec::new(),
                    Some(r) => r.extract().map_err(|_| {
                        invalid("configuration.rows", r, "a list of rows (lists of numbers)")
                    })?,
                };
                let c0 = n.vec("c0")?.unwrap_or_else(|| vec![0.0; rows.len()]);
                Constraints::new(n_coords, &rows, &c0)?
            }
        }
    };
    let mut h = None;
    let transmission = match child(&root, "drivetrain", &mut h)? {
        None => None,
        Some(d) => Some(
            Transmission::new(parse_drivetrain(&d)?, d.f64_or("balance_stiffness", 0.0)?)
                .map_err(|e| e.in_field("drivetrain"))?,
        ),
    };
    let mut h2 = None;
    let actuator = match child(&root, "actuator", &mut h2)? {
        None => None,
        Some(a) => {
            let mut h3 = None;
            let waveform = match child(&a, "waveform", &mut h3)? {
                Some(w) => parse_waveform(&w)?,
                None => return Err(invalid("actuator.waveform", "missing", "a waveform table")),
            };
            let dc = match a.str_or("dc_offset", "as_force")?.as_str() {
                "as_force" => DcOffset::AsForce,
                "ignore" => DcOffset::Ignore,
                other => return Err(invalid("actuator.dc_offset", other, "as_force or ignore")),
            };
            Some(
                Actuator::new(
                    a.f64_or("force_per_volt", 1.2)?,
                    a.f64_or("stiffness", 467.0)?,
                    waveform,
                    dc,
                )
                .map_err(|e| e.in_field("actuator"))?,
            )
        }
    };
    let formulation = match root.str_or("formulation", "auto")?.as_str() {
        "auto" => Formulation::Auto,
        "null_space" => Formulation::NullSpace,
        "projection" => Formulation::Projection,
        "drivetrain_coordinates" => Formulation::DrivetrainCoordinates,
        other => {
            return Err(invalid(
                "formulation",
                other,
                "auto, null_space, projection or drivetrain_coordinates",
            ));
        }
    };
    Device::new(DeviceSpec {
        wings,
        constraints,
        transmission,
        actuator,
        formulation,
    })
}

pub(crate) fn parse_options(
    options: &Bound<'_, PyDict>,
    n_coords: usize,
) -> Result<SimulationOptions> {
    let n = Node {
        dict: options,
        path: "options".into(),
    };
    let d = SimulationOptions::default();
    let method = match n.str_or("method", "dop853")?.as_str() {
        "dop853" => Method::Dop853,
        "dopri5" => Method::Dopri5,
        other => return Err(invalid("options.method", other, "dop853 or dopri5")),
    };
    let vec6 = |key: &str| -> Result<Option<Vec6>> {
        match n.vec(key)? {
            None => Ok(None),
            Some(v) if v.len() == n_coords => {
                let mut out = Vec6::zeros();
                for (i, x) in v.iter().enumerate() {
                    out[i] = *x;
                }
                Ok(Some(out))
            }
            Some(v) => Err(invalid(
                &n.field(key),
                v.len(),
                &format!("{n_coords} values (3 per wing)"),
            )),
        }
    };
    let initial = match (vec6("initial_p")?, vec6("initial_p_dot")?) {
        (None, None) => None,
        (p, v) => Some((p.unwrap_or_else(Vec6::zeros), v.unwrap_or_else(Vec6::zeros))),
    };
    let mut h = None;
    let perturbation = match child(&n, "perturbation", &mut h)? {
        None => None,
        Some(p) => {
            let target = match p.get("target") {
                None => PerturbTarget::WhippletreeRate,
                Some(t) => match t.extract::<String>() {
                    Ok(s) if s == "q2" => PerturbTarget::WhippletreeRate,
                    _ => PerturbTarget::Coordinate(t.extract().map_err(|_| {
                        invalid(
                            "options.perturbation.target",
                            t,
                            "\"q2\" or a coordinate index",
                        )
                    })?),
                },
            };
            Some(Perturbation {
                target,
                delta: p.f64("delta")?,
                phase: p.f64_or("phase", 0.0)?,
            })
        }
    };
    Ok(SimulationOptions {
        method,
        rtol: n.f64_or("rtol", d.rtol)?,
        atol: n.f64_or("atol", d.atol)?,
        max_steps: n.usize_or("max_steps", d.max_steps)?,
        initial,
        min_cycles: n.usize_or("min_cycles", d.min_cycles)?,
        max_cycles: n.usize_or("max_cycles", d.max_cycles)?,
        steady_tol: n.f64_or("steady_tol", d.steady_tol)?,
        samples_per_cycle: n.usize_or("samples_per_cycle", d.samples_per_cycle)?,
        record_cycles: n.usize_or("record_cycles", d.record_cycles)?,
        perturbation,
        duration_ms: match n.get("duration_ms") {
            None => None,
            Some(_) => Some(n.f64("duration_ms")?),
        },
        steady_state: match n.str_or("steady_state", "transient")?.as_str() {
            "transient" => SteadyState::Transient,
            "shooting" => SteadyState::Shooting,
            other => {
                return Err(invalid(
                    "options.steady_state",
                    other,
                    "transient or shooting",
                ));
            }
        },
        ..d
    })
}

/// Validates a device spec dict; returns `(n_wings, n_dof)`.
#[pyfunction]
fn validate_device(spec: &Bound<'_, PyDict>) -> PyResult<(usize, usize)> {
    let d = parse_device(spec).py_err()?;
    Ok((d.n_wings(), d.n_dof()))
}

fn result_to_dict<'py>(py: Python<'py>, r: SimulationResult) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("time_ms", PyArray1::from_vec(py, r.trajectory.time))?;
    let cols = PyDict::new(py);
    for (name, values) in r.trajectory.columns {
        cols.set_item(name, PyArray1::from_vec(py, values))?;
    }
    out.set_item("columns", cols)?;
    let metrics = PyDict::new(py);
    for (name, v) in r.metrics {
        metrics.set_item(name, v)?;
    }
    out.set_item("metrics", metrics)?;
    out.set_item("cycles_run", r.cycles_run)?;
    out.set_item("converged", r.converged)?;
    out.set_item("period_ms", r.period_ms)?;
    out.set_item("residual", r.residual)?;
    Ok(out)
}

/// Simulates a device spec dict with an options dict (GIL released while integrating).
///
/// Returns `time_ms`, `columns` (name -> array), `metrics` (name -> float), `cycles_run`,
/// `converged`, `period_ms`.
#[pyfunction]
fn simulate<'py>(
    py: Python<'py>,
    spec: &Bound<'py, PyDict>,
    options: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyDict>> {
    let device = parse_device(spec).py_err()?;
    let opts = parse_options(options, device.n_coords()).py_err()?;
    let result = py
        .detach(|| paritysim_dynamics::simulate(&device, &opts))
        .py_err()?;
    result_to_dict(py, result)
}

/// Adds the dynamics functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(validate_device, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    Ok(())
}
