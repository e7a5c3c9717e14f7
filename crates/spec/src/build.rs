//! From a spec to the dynamics model ([`Device`]) and its [`SimulationOptions`].

use nalgebra::Matrix3;
use paritysim_aero::{
    BladeElementModel, CoefficientSet, Omegas, QuasiSteadyOmegas, QuasiSteadyTerms,
    WhitneyWoodModel,
};
use paritysim_constraints::{Constraints, Vec6};
use paritysim_dynamics::device::{
    DeviceSpec, Formulation as EngineFormulation, Transmission, ties_strokes,
};
use paritysim_dynamics::simulate::PerturbTarget as EngineTarget;
use paritysim_dynamics::{
    Actuator as EngineActuator, DcOffset as EngineDc, Device, JointSpring,
    Perturbation as EngineKick, SimulationOptions, TunableHinge as EngineHinge,
    Waveform as EngineWaveform, Wing as EngineWing, WingAero,
};
use paritysim_error::{Error, Result};
use paritysim_kinematics::SphericalShoulder;

use crate::actuator::{Actuator, DcOffset, Waveform};
use crate::options::{Options, PerturbTarget};
use crate::spec::{Configuration, Formulation, Simulation};
use crate::wing::{Aero, CoefficientModel, NormalForceLaw, SPRING_NAMES, Wing};

impl Simulation {
    /// The validated model and options.
    ///
    /// # Errors
    /// Whatever the engine's constructors reject (cross-field conditions such as a 1-DOF
    /// drivetrain driving untied wings), with the dotted field path.
    pub fn model(&self) -> Result<(Device, SimulationOptions)> {
        let device = self.device()?;
        // A flying spec's body is checked here too (its errors name `body.` fields).
        self.flight(&device)?;
        let mut options = options(&self.options, device.n_coords())?;
        options.weight_mn = self.weight_mn();
        Ok((device, options))
    }

    /// The weight of body and wings (mN) when the spec has a `body` section (any mode, the
    /// torque stand's `fixed` included): what `lift_to_weight` divides by.
    pub fn weight_mn(&self) -> Option<f64> {
        self.body.as_ref().map(|b| {
            let g = b.gravity_mm_per_ms2;
            let mass = b.mass_mg + b.wing_mass_mg.iter().sum::<f64>();
            mass * (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt()
        })
    }

    /// The radius (mm) that gives blade-element wings their force parameter `Ω1 / r`:
    /// `body.force_radius_mm`, or its default without a `body` section (the torque stand's
    /// force metrics and free flight use the same).
    pub fn force_radius_mm(&self) -> f64 {
        self.body
            .as_ref()
            .map_or(crate::body::Body::default().force_radius_mm, |b| {
                b.force_radius_mm
            })
    }

    /// The validated dynamics model.
    ///
    /// # Errors
    /// See [`Simulation::model`].
    pub fn device(&self) -> Result<Device> {
        let force_radius = self.force_radius_mm();
        let wings = self
            .wings
            .iter()
            .enumerate()
            .map(|(i, w)| wing(w, force_radius).map_err(|e| e.in_field(&format!("wings[{i}]"))))
            .collect::<Result<Vec<_>>>()?;
        let constraints = constraints(&self.configuration, 3 * wings.len())?;
        let transmission = match &self.drivetrain {
            None => None,
            Some(d) => Some(
                d.kinematics()
                    .and_then(|k| Transmission::new(k, d.balance_spring()))
                    .and_then(|t| t.with_preload(d.balance_preload()))
                    .and_then(|t| t.with_balance_losses(d.balance_damping(), d.balance_cubic()))
                    .map_err(|e| e.in_field("drivetrain"))?,
            ),
        };
        let actuator = self
            .actuator
            .as_ref()
            .map(actuator)
            .transpose()
            .map_err(|e| e.in_field("actuator"))?;
        // A 2-DOF drivetrain drives two wings.
        if let Some(t) = &transmission
            && t.kinematics().dof() == 2
            && wings.len() == 1
        {
            return Err(Error::invalid(
                "drivetrain.kind",
                t.kinematics().name(),
                "a 1-DOF drivetrain (single_linear, hmf_four_bar) for a device with one wing",
            ));
        }
        // Per-side drives need one drive per wing.
        if let (Some(a), Some(t), Some(spec)) = (&actuator, &transmission, &self.actuator) {
            let dual = t.kinematics().is_dual();
            if a.has_sides() && !dual {
                let (field, value) = if spec.side_gain != [1.0, 1.0] {
                    ("actuator.side_gain", format!("{:?}", spec.side_gain))
                } else {
                    (
                        "actuator.side_offset_v",
                        format!("{:?}", spec.side_offset_v),
                    )
                };
                return Err(Error::invalid(
                    field,
                    value,
                    format!(
                        "[1, 1] (gain) and [0, 0] (offset) unless drivetrain.kind is \"dual_four_bar\" or \"dual_linear\" (one drive per wing; this drivetrain is {})",
                        t.kinematics().name()
                    ),
                ));
            }
        }
        // A 1-DOF drivetrain on two wings whose strokes `C` leaves untied is the engine's
        // error; the field a user changes for it is the drivetrain (or the configuration).
        let untied_kind = match &transmission {
            Some(t)
                if wings.len() == 2
                    && constraints.n_coords() == 6
                    && t.kinematics().dof() == 1
                    && !ties_strokes(&constraints) =>
            {
                Some(t.kinematics().name().to_string())
            }
            _ => None,
        };
        Device::new(DeviceSpec {
            wings,
            constraints,
            transmission,
            actuator,
            formulation: match self.formulation {
                Formulation::Auto => EngineFormulation::Auto,
                Formulation::NullSpace => EngineFormulation::NullSpace,
                Formulation::Projection => EngineFormulation::Projection,
                Formulation::DrivetrainCoordinates => EngineFormulation::DrivetrainCoordinates,
            },
        })
        .map_err(|e| match untied_kind {
            Some(kind) => e.attributed(
                "drivetrain.kind",
                format!("{kind:?}"),
                format!(
                    "a drivetrain with a whippletree or a drive per wing for configuration {:?} \
                     (its strokes are not tied), or a configuration that ties them (e.g. hmf)",
                    self.configuration
                        .name
                        .as_deref()
                        .unwrap_or("explicit rows")
                ),
            ),
            None => e,
        })
    }
}

/// The §3.2.4 blade element of a spec aero (`omegas` Ω1..Ω4) with its force parameter, or
/// `Ω1 / force_radius` without one.
fn blade_element(
    omegas: [f64; 4],
    force_parameter: Option<f64>,
    model: CoefficientModel,
    rotational_damping: Option<f64>,
    normal_force_law: NormalForceLaw,
    force_radius: f64,
) -> Result<BladeElementModel<CoefficientSet>> {
    let [o1, o2, o3, o4] = omegas;
    let force = force_parameter.unwrap_or(o1 / force_radius);
    // The aero crate names its own fields (`omegas.omega2`, `force`); the spec's are `omega2`
    // and `force_parameter` (an error's field is a path `with_paths` takes).
    let omegas = Omegas::new(o1, o2, o3, o4)
        .and_then(|o| o.with_force(force))
        .map_err(|e| match e {
            paritysim_error::Error::InvalidParameter {
                field,
                value,
                allowed,
            } => paritysim_error::Error::InvalidParameter {
                field: match field.trim_start_matches("omegas.") {
                    "force" => "force_parameter".into(),
                    name => name.to_string().into(),
                },
                value,
                allowed,
            },
            other => other,
        })?;
    let coefficients = CoefficientSet::from_name(match model {
        CoefficientModel::Dickinson1999 => "dickinson1999",
        CoefficientModel::WhitneyWood2010 => "whitney_wood2010",
    })?;
    let damping = rotational_damping.unwrap_or(paritysim_aero::DEFAULT_ROTATIONAL_DAMPING);
    let law = match normal_force_law {
        NormalForceLaw::Coefficient => paritysim_aero::NormalForceLaw::Coefficient,
        NormalForceLaw::Unit => paritysim_aero::NormalForceLaw::Unit,
    };
    Ok(BladeElementModel::new(omegas, coefficients)?
        .with_rotational_damping(damping)?
        .with_normal_force_law(law))
}

/// The engine wing of a spec wing; a blade element gets its force parameter, or
/// `Ω1 / force_radius` (mg·mm) without one, so its lift and drag forces are defined on every
/// body mode.
fn wing(w: &Wing, force_radius: f64) -> Result<EngineWing> {
    let shoulder = SphericalShoulder::new(w.shoulder.alpha2, w.shoulder.alpha3)
        .map_err(|e| e.in_field("shoulder"))?;
    let inertia = Matrix3::from_fn(|i, j| w.inertia[i][j]);
    let mut springs = [JointSpring::default(); 6];
    for (k, s) in w.springs.in_joint_order().into_iter().enumerate() {
        springs[k] = JointSpring::nonlinear(s.stiffness, s.cubic, s.rest_angle)
            .map_err(|e| e.in_field(&format!("springs.{}", SPRING_NAMES[k])))?;
    }
    let aero = match &w.aero {
        None => WingAero::None,
        Some(Aero::StrokeDrag(a)) => {
            WingAero::stroke_drag(a.omega1, a.coefficient).map_err(|e| e.in_field("aero"))?
        }
        Some(Aero::BladeElement(a)) => WingAero::BladeElement(
            blade_element(
                [a.omega1, a.omega2, a.omega3, a.omega4],
                a.force_parameter,
                a.model,
                a.rotational_damping,
                a.normal_force_law,
                force_radius,
            )
            .map_err(|e| e.in_field("aero"))?,
        ),
        Some(Aero::WhitneyWood2010(a)) => {
            let blade = blade_element(
                [a.omega1, a.omega2, a.omega3, a.omega4],
                a.force_parameter,
                a.model,
                a.rotational_damping,
                a.normal_force_law,
                force_radius,
            );
            let omegas = QuasiSteadyOmegas {
                omega5: a.omega5,
                omega6: a.omega6,
                omega7: a.omega7,
                omega8: a.omega8,
            };
            let terms = QuasiSteadyTerms {
                rotational_lift: a.rotational_lift,
                translational_added_mass: a.translational_added_mass,
                rotational_added_mass: a.rotational_added_mass,
            };
            WingAero::WhitneyWood2010(
                blade
                    .and_then(|b| WhitneyWoodModel::new(b, omegas, terms))
                    .map_err(|e| e.in_field("aero"))?,
            )
        }
    };
    let built = EngineWing::new(shoulder, inertia, springs, aero)?
        .with_hinge_damping(w.springs.hinge_damping)
        .map_err(|e| rename_field(e, "damping", "hinge_damping").in_field("springs"))?;
    Ok(match &w.tunable_hinge {
        None => built,
        Some(h) => built.with_tunable_hinge(
            EngineHinge::new(
                h.stiffness_at_zero,
                h.stiffness_slope,
                h.stiffness_curvature,
            )
            .map_err(|e| rename_hinge(e).in_field("tunable_hinge"))?,
        ),
    })
}

/// Renames the field of an [`Error::InvalidParameter`] whose field is `from`.
fn rename_field(e: Error, from: &str, to: &'static str) -> Error {
    match e {
        Error::InvalidParameter {
            field,
            value,
            allowed,
        } if field == from => Error::invalid(to, value, allowed),
        other => other,
    }
}

/// The engine names the hinge coefficients `k0, k1, k2`; the spec names say what they are.
fn rename_hinge(e: Error) -> Error {
    match e {
        Error::InvalidParameter {
            field,
            value,
            allowed,
        } => {
            let name = match field.as_ref() {
                "k0" => "stiffness_at_zero",
                "k1" => "stiffness_slope",
                "k2" => "stiffness_curvature",
                other => return Error::invalid(other.to_string(), value, allowed),
            };
            let allowed = allowed
                .replace("k0", "stiffness_at_zero")
                .replace("k1", "stiffness_slope")
                .replace("k2", "stiffness_curvature");
            Error::invalid(name, value, allowed)
        }
        other => other,
    }
}

/// The named configurations of a one-wing device (`wings` of length 1): `single_wing` (the
/// deviation θ held at 0, the rotation ψ free) and `single_wing_fixed` (θ and ψ held: the wing
/// only strokes).
pub const SINGLE_WING_CONFIGURATIONS: [&str; 2] = ["single_wing", "single_wing_fixed"];

fn constraints(c: &Configuration, n_coords: usize) -> Result<Constraints> {
    match (&c.name, &c.rows) {
        (Some(_), Some(_)) => Err(Error::invalid(
            "configuration",
            "both name and rows",
            "a Table 3.1 name or explicit rows, not both",
        )),
        // One wing (issue 35): the stroke free, the deviation held, the rotation free or held.
        (Some(name), None) if SINGLE_WING_CONFIGURATIONS.contains(&name.as_str()) => {
            if n_coords != 3 {
                return Err(Error::invalid(
                    "configuration.name",
                    name,
                    "a Table 3.1 name for two wings (single_wing and single_wing_fixed need \
                     `wings` of length 1)",
                ));
            }
            let rows: &[Vec<f64>] = if name == "single_wing" {
                &[vec![0.0, 1.0, 0.0]]
            } else {
                &[vec![0.0, 1.0, 0.0], vec![0.0, 0.0, 1.0]]
            };
            Constraints::new(3, rows, &vec![0.0; rows.len()])
        }
        (Some(name), None) if n_coords == 3 => Err(Error::invalid(
            "configuration.name",
            name,
            "single_wing (theta held) or single_wing_fixed (theta and psi held) for one wing",
        )),
        (Some(name), None) => Constraints::configuration(name).map_err(|e| match e {
            Error::InvalidParameter { value, allowed, .. } => Error::invalid(
                "configuration.name",
                value,
                format!(
                    "{allowed}, or for one wing {}",
                    SINGLE_WING_CONFIGURATIONS.join(", ")
                ),
            ),
            other => other,
        }),
        (None, Some(rows)) => {
            let c0 = c.c0.clone().unwrap_or_else(|| vec![0.0; rows.len()]);
            Constraints::new(n_coords, rows, &c0)
        }
        (None, None) => match &c.c0 {
            Some(_) => Err(Error::invalid(
                "configuration.c0",
                "given without rows",
                "c0 only together with rows",
            )),
            None => Constraints::none(n_coords),
        },
    }
}

fn actuator(a: &Actuator) -> Result<EngineActuator> {
    let waveform = match &a.waveform {
        Waveform::Sine(s) => {
            EngineWaveform::sine(s.amplitude_v, s.frequency_hz, s.offset_v, s.phase)
        }
        Waveform::Sampled(s) => {
            EngineWaveform::sampled(s.times_ms.clone(), s.voltages_v.clone(), s.period_ms)
        }
    }
    .map_err(|e| e.in_field("waveform"))?;
    let dc = match a.dc_offset {
        DcOffset::AsForce => EngineDc::AsForce,
        DcOffset::Ignore => EngineDc::Ignore,
    };
    let engine = EngineActuator::new(a.force_per_volt, a.stiffness, waveform, dc)?;
    for k in 0..2 {
        if !(-1e4..=1e4).contains(&a.side_offset_v[k]) {
            return Err(Error::invalid(
                format!("side_offset_v[{k}]"),
                a.side_offset_v[k],
                "in [-1e4, 1e4] V",
            ));
        }
    }
    engine
        .with_sides(a.side_gain, a.side_offset_v.map(|v| v * a.force_per_volt))?
        .with_dynamics(a.mass_mg, a.damping, a.cubic_stiffness)
}

fn vec6(field: &str, v: &Option<Vec<f64>>, n_coords: usize) -> Result<Option<Vec6>> {
    match v {
        None => Ok(None),
        Some(v) if v.len() == n_coords => {
            let mut out = Vec6::zeros();
            for (i, x) in v.iter().enumerate() {
                out[i] = *x;
            }
            Ok(Some(out))
        }
        Some(v) => Err(Error::invalid(
            format!("options.{field}"),
            v.len(),
            format!("{n_coords} values (3 per wing)"),
        )),
    }
}

/// Engine options for a device with `n_coords` coordinates.
///
/// # Errors
/// [`Error::InvalidParameter`] for initial states of the wrong length.
pub fn options(o: &Options, n_coords: usize) -> Result<SimulationOptions> {
    let initial = match (
        vec6("initial_p", &o.initial_p, n_coords)?,
        vec6("initial_p_dot", &o.initial_p_dot, n_coords)?,
    ) {
        (None, None) => None,
        (p, v) => Some((p.unwrap_or_else(Vec6::zeros), v.unwrap_or_else(Vec6::zeros))),
    };
    let to_usize = |x: u64| usize::try_from(x).unwrap_or(usize::MAX);
    Ok(SimulationOptions {
        method: o.method.into(),
        rtol: o.rtol,
        atol: o.atol,
        max_steps: to_usize(o.max_steps),
        initial,
        min_cycles: to_usize(o.min_cycles),
        max_cycles: to_usize(o.max_cycles),
        steady_tol: o.steady_tol,
        samples_per_cycle: to_usize(o.samples_per_cycle),
        record_cycles: to_usize(o.record_cycles),
        perturbation: o.perturbation.as_ref().map(|p| EngineKick {
            target: match p.target {
                PerturbTarget::Named(_) => EngineTarget::WhippletreeRate,
                PerturbTarget::Coordinate(i) => EngineTarget::Coordinate(usize::from(i)),
            },
            delta: p.delta,
            phase: p.phase,
        }),
        duration_ms: o.duration_ms,
        steady_state: o.steady_state.into(),
        max_wall_ms: Some(o.max_wall_ms),
        ..SimulationOptions::default()
    })
}
