//! From a spec's `body` section to the flight model (`paritysim-flight`), and one entry point
//! that runs any spec: the fixed-body engine or free flight.

use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use paritysim_dynamics::sweep::PointOutput;
use paritysim_dynamics::{Device, SimulationOptions, SimulationResult};
use paritysim_error::{Error, Result};
use paritysim_flight::run::{Release, Schedule};
use paritysim_flight::{
    Body as EngineBody, BodyMode as EngineMode, Control as EngineControl,
    ControlInput as EngineInput, DriveCoordinate as EngineCoordinate, FlightModel,
    Interpolation as EngineInterpolation, Mechanism as EngineMechanism, SetPoint as EngineSetPoint,
};

use crate::body::{Axis, Body, BodyMode, ControlInput, DriveCoordinate, Interpolation, Mechanism};
use crate::spec::Simulation;

/// A flight run: model, release state and slow inputs.
#[derive(Clone, Debug)]
pub struct Flight {
    /// The coupled model.
    pub model: FlightModel,
    /// Initial body state.
    pub release: Release,
    /// Set points and controller.
    pub schedule: Schedule,
}

fn v3(a: &[f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

fn input(i: ControlInput) -> EngineInput {
    match i {
        ControlInput::Q2Bias => EngineInput::Q2Bias,
        ControlInput::ActuatorOffset => EngineInput::ActuatorOffset,
        ControlInput::ActuatorGain => EngineInput::ActuatorGain,
        ControlInput::LogQ3 => EngineInput::LogQ3,
        ControlInput::SideGainLeft => EngineInput::SideGainLeft,
        ControlInput::SideGainRight => EngineInput::SideGainRight,
        ControlInput::SideOffsetLeft => EngineInput::SideOffsetLeft,
        ControlInput::SideOffsetRight => EngineInput::SideOffsetRight,
        ControlInput::SideGainDifference => EngineInput::SideGainDifference,
        ControlInput::SideOffsetDifference => EngineInput::SideOffsetDifference,
    }
}

/// Whether `input` can act on `device`'s drivetrain (`field` names it in the error).
fn check_input(device: &Device, i: ControlInput, field: &str) -> Result<()> {
    let field = field.to_string();
    let engine = input(i);
    let kinematics = device.spec().transmission.as_ref().map(|t| t.kinematics());
    let name = kinematics.map_or("none", |k| k.name());
    let two = kinematics.is_some_and(|k| k.dof() == 2);
    let value = serde_json::to_string(&i).unwrap_or_default();
    if engine.needs_whippletree() && (!two || device.is_dual()) {
        return Err(Error::invalid(
            field.clone(),
            value,
            format!(
                "an input of this drivetrain ({name}): q2_bias and log_q3 need a whippletree (linear_differential, linkage_differential)"
            ),
        ));
    }
    // A configuration that ties the strokes (`hmf`) holds the whippletree: its reaction would
    // take the input, which would then do nothing.
    if engine.needs_whippletree()
        && paritysim_dynamics::device::ties_strokes(&device.spec().constraints)
    {
        return Err(Error::invalid(
            field.clone(),
            value,
            "an input of a free whippletree: this configuration ties the strokes (phi_L = phi_R, as the HMF's), so q2 cannot move; q2_bias and log_q3 need a PARITY configuration (drag_parity, lift_parity, ...)",
        ));
    }
    if engine.needs_dual() && !device.is_dual() {
        return Err(Error::invalid(
            field.clone(),
            value,
            format!(
                "an input of this drivetrain ({name}): side_* inputs need drivetrain.kind = \"dual_four_bar\" or \"dual_linear\" (one drive per wing)"
            ),
        ));
    }
    if kinematics.is_none() {
        return Err(Error::invalid(
            field,
            value,
            "an input of a device with a drivetrain",
        ));
    }
    Ok(())
}

fn coordinate(c: DriveCoordinate) -> EngineCoordinate {
    match c {
        DriveCoordinate::Q1 => EngineCoordinate::Q1,
        DriveCoordinate::Q2 => EngineCoordinate::Q2,
    }
}

/// The engine body of a spec body.
pub fn engine_body(b: &Body) -> EngineBody {
    EngineBody {
        mode: match b.mode {
            BodyMode::Fixed => EngineMode::Fixed,
            BodyMode::Clamped => EngineMode::Clamped,
            BodyMode::Roll => EngineMode::Roll,
            BodyMode::Yaw => EngineMode::Yaw,
            BodyMode::Pitch => EngineMode::Pitch,
            BodyMode::RollPitchYaw => EngineMode::RollPitchYaw,
            BodyMode::Free => EngineMode::Free,
        },
        mass: b.mass_mg,
        inertia: Matrix3::from_fn(|i, j| b.inertia[i][j]),
        center_of_mass: v3(&b.center_of_mass_mm),
        shoulders: [v3(&b.shoulders_mm[0]), v3(&b.shoulders_mm[1])],
        gravity: v3(&b.gravity_mm_per_ms2),
        force_radius: b.force_radius_mm,
        wing_mass: b.wing_mass_mg,
        wing_center_of_mass: [
            v3(&b.wing_center_of_mass_mm[0]),
            v3(&b.wing_center_of_mass_mm[1]),
        ],
    }
}

impl Simulation {
    /// Whether the spec flies (a `body` section with a mode other than `fixed`).
    pub fn flies(&self) -> bool {
        self.body
            .as_ref()
            .is_some_and(|b| b.mode != BodyMode::Fixed)
    }

    /// The flight model of a spec whose body is not fixed (None otherwise).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the `body.` field; the device's errors.
    pub fn flight(&self, device: &Device) -> Result<Option<Flight>> {
        let Some(b) = self.body.as_ref().filter(|_| self.flies()) else {
            // A fixed body runs the device alone: its inputs would be silently unused.
            if let Some(b) = &self.body {
                let field = if !b.set_points.is_empty() {
                    Some("body.set_points")
                } else if b.control.is_some() {
                    Some("body.control")
                } else {
                    None
                };
                if let Some(field) = field {
                    return Err(Error::invalid(
                        field,
                        "given with body.mode = \"fixed\"",
                        "empty on a fixed body (inputs act through the body's dynamics: mode = \"clamped\" holds the body and applies them)",
                    ));
                }
            }
            return Ok(None);
        };
        let mechanisms = b
            .mechanisms
            .iter()
            .enumerate()
            .map(|(i, m)| {
                match m {
                    Mechanism::GravityPendulum(p) => EngineMechanism::pendulum(
                        coordinate(p.coordinate),
                        p.moment_mg_mm,
                        v3(&p.direction),
                        v3(&p.axis),
                    ),
                    Mechanism::RateElement(r) => {
                        EngineMechanism::rate(coordinate(r.coordinate), r.gain, v3(&r.axis))
                    }
                }
                .map_err(|e| e.in_field(&format!("body.mechanisms[{i}]")))
            })
            .collect::<Result<Vec<_>>>()?;
        let model = FlightModel::new(device, engine_body(b), mechanisms)?;
        let schedule = |input_kind: ControlInput,
                        times: &[f64],
                        values: &[f64],
                        interpolation: Interpolation,
                        period: Option<f64>| {
            let point = EngineSetPoint::new(input(input_kind), times.to_vec(), values.to_vec())
                .map(|p| {
                    p.with_interpolation(match interpolation {
                        Interpolation::Linear => EngineInterpolation::Linear,
                        Interpolation::Previous => EngineInterpolation::Previous,
                    })
                });
            match period {
                None => point,
                Some(period) => point.and_then(|p| p.with_period(period)),
            }
        };
        let set_points = b
            .set_points
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let at = format!("body.set_points[{i}]");
                check_input(device, s.input, &format!("{at}.input"))?;
                schedule(
                    s.input,
                    &s.times_ms,
                    &s.values,
                    s.interpolation,
                    s.period_ms,
                )
                .map_err(|e| e.in_field(&at))
            })
            .collect::<Result<Vec<_>>>()?;
        let control = match b.control.as_ref() {
            None => None,
            Some(c) => Some(EngineControl {
                input: input(c.input),
                axis: match c.axis {
                    Axis::Roll => 0,
                    Axis::Yaw => 1,
                    Axis::Pitch => 2,
                },
                target: c.target_rad,
                kp: c.kp,
                kd: c.kd,
                target_rate: c.target_rate_rad_per_ms,
                rate_hz: c.rate_hz,
                limit: c.limit,
                shape: c
                    .shape
                    .as_ref()
                    .map(|s| {
                        schedule(
                            c.input,
                            &s.times_ms,
                            &s.values,
                            s.interpolation,
                            s.period_ms,
                        )
                        .map_err(|e| e.in_field("body.control.shape"))
                    })
                    .transpose()?,
            }),
        };
        if let Some(c) = &control {
            c.validate()?;
        }
        if let Some(c) = &b.control {
            check_input(device, c.input, "body.control.input")?;
        }
        let [roll, yaw, pitch] = b.initial_attitude_rad;
        let attitude = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), roll)
            * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), yaw)
            * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), pitch);
        Ok(Some(Flight {
            model,
            release: Release {
                attitude,
                omega: v3(&b.initial_rates_rad_per_ms),
                velocity: v3(&b.initial_velocity_mm_per_ms),
            },
            schedule: Schedule {
                set_points,
                control,
            },
        }))
    }

    /// `options` building only the asked trajectory columns and metrics (`None`: all of
    /// them; an empty list: none). Fewer columns and metrics cost less: no column is recorded
    /// that is not asked for, and a drivetrain-coordinate device's samples compute only what
    /// the asked metrics need.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`columns` or `metrics`, naming the nearest valid name) for
    /// an unknown name; as [`Simulation::flight`].
    pub fn with_outputs(
        &self,
        device: &Device,
        options: &SimulationOptions,
        columns: Option<&[String]>,
        metrics: Option<&[String]>,
    ) -> Result<SimulationOptions> {
        let mut options = options.clone();
        if let Some(c) = columns {
            let valid = self.column_names(device)?;
            options.columns = Some(crate::schema::select("columns", Some(c), &valid)?);
        }
        if let Some(m) = metrics {
            let valid = self.metric_names(device)?;
            options.metrics = Some(crate::schema::select("metrics", Some(m), &valid)?);
        }
        Ok(options)
    }

    /// The metrics of `result` reduced to `options.metrics` (in that order) when they were
    /// asked for ([`Simulation::with_outputs`]); all of them otherwise.
    pub fn asked_metrics(
        options: &SimulationOptions,
        mut result: SimulationResult,
    ) -> SimulationResult {
        if let Some(names) = &options.metrics {
            let all = std::mem::take(&mut result.metrics);
            result.metrics = names
                .iter()
                .filter_map(|n| all.iter().find(|(k, _)| k == n).cloned())
                .collect();
        }
        result
    }

    /// Runs the spec: the engine's [`paritysim_dynamics::simulate()`] for a fixed body, free
    /// flight ([`paritysim_flight::fly`]) otherwise. `device` and `options` are those of
    /// [`Simulation::model`] (the caller may set a cancel flag on the options).
    ///
    /// # Errors
    /// As [`Simulation::flight`] and the run itself.
    pub fn run(&self, device: &Device, options: &SimulationOptions) -> Result<SimulationResult> {
        match self.flight(device)? {
            None => paritysim_dynamics::simulate(device, options),
            Some(f) => paritysim_flight::fly(&f.model, options, &f.release, &f.schedule),
        }
    }

    /// [`Simulation::run`] with an external controller ticking at `rate_hz` (e.g. a Python
    /// callback: [`paritysim_flight::fly_controlled`]).
    ///
    /// # Errors
    /// As [`Simulation::run`]; [`Error::InvalidParameter`] (`body.mode`) for a fixed body
    /// (nothing to control) and (`control_rate_hz`) for a non-positive rate; whatever the
    /// controller returns.
    pub fn run_controlled(
        &self,
        device: &Device,
        options: &SimulationOptions,
        rate_hz: f64,
        controller: &mut paritysim_flight::Controller<'_>,
    ) -> Result<SimulationResult> {
        let Some(f) = self.flight(device)? else {
            return Err(Error::invalid(
                "body.mode",
                "\"fixed\"",
                "a moving or clamped body for a controller (clamped, roll, yaw, pitch, roll_pitch_yaw, free)",
            ));
        };
        paritysim_flight::fly_controlled(
            &f.model,
            options,
            &f.release,
            &f.schedule,
            Some((1000.0 / rate_hz, controller)),
        )
    }

    /// Metric names [`Simulation::run`] reports.
    ///
    /// # Errors
    /// As [`Simulation::flight`].
    pub fn metric_names(&self, device: &Device) -> Result<Vec<String>> {
        Ok(match self.flight(device)? {
            None => paritysim_dynamics::metrics::names_weighed(device, self.body.is_some()),
            Some(f) => paritysim_flight::flight_metrics(&f.model),
        })
    }

    /// Trajectory column names [`Simulation::run`] records.
    ///
    /// # Errors
    /// As [`Simulation::flight`].
    pub fn column_names(&self, device: &Device) -> Result<Vec<String>> {
        let units = self.column_units(device)?;
        Ok(units.into_iter().map(|(name, _)| name).collect())
    }

    /// [`Self::column_names`] with each column's unit (`mN*mm`, `rad/ms`, `uJ`, ...).
    ///
    /// # Errors
    /// As [`Self::column_names`].
    pub fn column_units(&self, device: &Device) -> Result<Vec<(String, &'static str)>> {
        Ok(match self.flight(device)? {
            None => paritysim_dynamics::trajectory::column_table(device)
                .into_iter()
                .map(|c| (c.name, c.unit))
                .collect(),
            Some(f) => paritysim_flight::flight_column_units(&f.model),
        })
    }
}

/// One sweep point of a flying spec: [`Simulation::run`] and what the sweep keeps (the
/// engine's [`PointOutput`]: selected metrics, the last recorded wingbeat when asked).
///
/// # Errors
/// As [`Simulation::run`].
pub fn run_point(
    spec: &Simulation,
    device: &Device,
    options: &SimulationOptions,
    metric_names: &[String],
    keep_cycle: bool,
) -> Result<PointOutput> {
    let options = SimulationOptions {
        columns: if keep_cycle { None } else { Some(Vec::new()) },
        ..options.clone()
    };
    let result = spec.run(device, &options)?;
    // No neighbour chaining for flying points: each starts from its own clamped orbit (the
    // flight result carries no monodromy or step grid).
    Ok(PointOutput::keep(
        result,
        metric_names,
        keep_cycle,
        options.samples_per_cycle,
        None,
    ))
}
