//! Free-flight runs: the wings are first brought to their periodic steady state on the
//! clamped body (the engine's `simulate`, same options), then the body is released with zero
//! velocity and `record_cycles` wingbeats are integrated and sampled.
//!
//! Results use the engine's types ([`SimulationResult`], [`Trajectory`]): every column and
//! metric of the fixed device (wing angles, drivetrain, per-wing body torques about the
//! shoulders, ...) plus the body's columns ([`BODY_COLUMNS`]) and metrics ([`BODY_METRICS`]).

use nalgebra::{UnitQuaternion, Vector3};
use paritysim_dynamics::device::Evaluation;
use paritysim_dynamics::integrate::{
    ArraySink, ArraySystem, IntegrationStats, MAX_SWITCHES, Method, Sides, integrate_system,
};
use paritysim_dynamics::metrics::MetricsAccumulator;
use paritysim_dynamics::simulate::SimulationResult;
use paritysim_dynamics::trajectory::{Column, Sample, column_table};
use paritysim_dynamics::{SimulationOptions, State, Trajectory};
use paritysim_error::{Error, Result};

use crate::control::{Control, Interpolation, SetPoint};
use crate::model::{FlightEval, FlightModel, Inputs, STATE_LEN};

/// Slow inputs of a run: set points and at most one PD controller.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Schedule {
    /// Time-varying set points (summed per input).
    pub set_points: Vec<SetPoint>,
    /// A PD controller on attitude.
    pub control: Option<Control>,
}

impl Schedule {
    /// The set points at `t` (ms from the release) plus the PD output; piecewise-constant
    /// set points at `leg_middle` instead (a leg never straddles a node, so this is their
    /// value over the whole leg, free of rounding at the leg's ends).
    fn inputs(&self, t: f64, leg_middle: f64, control_output: f64) -> Inputs {
        let mut u = Inputs::default();
        for s in &self.set_points {
            let at = match s.interpolation {
                Interpolation::Linear => t,
                Interpolation::Previous => leg_middle,
            };
            s.input.add_to(&mut u, s.value(at));
        }
        if let Some(c) = &self.control {
            let scale = c.shape.as_ref().map_or(1.0, |s| {
                s.value(match s.interpolation {
                    Interpolation::Linear => t,
                    Interpolation::Previous => leg_middle,
                })
            });
            c.input.add_to(&mut u, control_output * scale);
        }
        u
    }

    /// The first set-point (or control shape) node after `t` (ms from the release; infinite for none).
    fn next_node(&self, t: f64, tol: f64) -> f64 {
        self.set_points
            .iter()
            .chain(self.control.as_ref().and_then(|c| c.shape.as_ref()))
            .map(|s| s.next_node(t, tol))
            .fold(f64::INFINITY, f64::min)
    }
}

/// Roll, yaw, pitch (rad) of an attitude: `R_b = R_x(roll) R_y(yaw) R_z(pitch)` (intrinsic
/// x-y-z, the order of the wing angles of §3.2.3; singular only at yaw = ±90°, which the
/// quaternion state never is).
pub fn euler_angles(q: &UnitQuaternion<f64>) -> Vector3<f64> {
    let r = q.to_rotation_matrix();
    let m = r.matrix();
    let yaw = m[(0, 2)].clamp(-1.0, 1.0).asin();
    let roll = (-m[(1, 2)]).atan2(m[(2, 2)]);
    let pitch = (-m[(0, 1)]).atan2(m[(0, 0)]);
    Vector3::new(roll, yaw, pitch)
}

/// One flight sample: the engine's [`Sample`] (for the device columns and metrics) and the
/// flight evaluation.
#[derive(Clone, Copy, Debug)]
pub struct FlightSample {
    /// The engine sample.
    pub sample: Sample,
    /// The flight evaluation.
    pub flight: FlightEval,
    /// Roll, yaw, pitch (rad).
    pub angles: Vector3<f64>,
    /// Quaternion `(w, x, y, z)`.
    pub quaternion: [f64; 4],
    /// Weight of body + wings (mN).
    pub weight: f64,
    /// Unit "up" vector (world): against gravity.
    pub up: Vector3<f64>,
}

impl FlightSample {
    fn new(model: &FlightModel, t: f64, y: &[f64; STATE_LEN], inputs: &Inputs) -> Result<Self> {
        let f = model.evaluate(t, y, inputs)?;
        let device = model.device();
        let mut total = Vector3::zeros();
        for k in 0..device.n_wings() {
            total += f.aero_torque[k] + f.inertial_torque[k];
        }
        let voltage = device
            .spec()
            .actuator
            .as_ref()
            .map_or(0.0, |a| a.waveform().voltage(t));
        let sample = Sample {
            time: t,
            state: model.wing_state(y),
            eval: Evaluation {
                p: f.p,
                p_dot: f.p_dot,
                p_ddot: f.p_ddot,
                wings: f.wings,
                drive: f.drive,
            },
            aero: f.aero_torque,
            inertial: f.inertial_torque,
            total,
            force: f.wing_aero_force,
            // The power the wings give to the air (the flight's is that of the air on them).
            aero_power: -f.aero_power,
            actuator_power: device.actuator_power(t, f.drive.actuator_force, &f.drive.q_dot),
            voltage,
            energy: f.kinetic + f.potential + f.gravity_potential,
        };
        let q = f.attitude.quaternion();
        let g = model.body().gravity;
        let up = if g.norm() > 0.0 {
            -g / g.norm()
        } else {
            Vector3::x()
        };
        Ok(Self {
            sample,
            angles: euler_angles(&f.attitude),
            quaternion: [q.w, q.i, q.j, q.k],
            weight: model.total_mass() * g.norm(),
            up,
            flight: f,
        })
    }

    /// Lift in the world: the aerodynamic force along "up" (against gravity, mN). The device
    /// metric `lift_mean` is along the body's lift axis `x̂` instead (the same on a clamped
    /// body under the default gravity).
    pub fn lift(&self) -> f64 {
        (self.flight.attitude * self.flight.aero_force).dot(&self.up)
    }
}

type BodyGetter = (&'static str, &'static str, fn(&FlightSample) -> f64);

/// The body's trajectory columns (name, unit): attitude angles and quaternion, rates (body
/// frame), position and velocity of the centre of mass (world), the wings' force and torque
/// on the airframe (body frame, about the centre of mass), the aerodynamic force, lift,
/// momenta and total energy.
pub const BODY_COLUMNS: [BodyGetter; 32] = [
    ("body_roll", "rad", |s| s.angles.x),
    ("body_yaw", "rad", |s| s.angles.y),
    ("body_pitch", "rad", |s| s.angles.z),
    ("body_qw", "1", |s| s.quaternion[0]),
    ("body_qx", "1", |s| s.quaternion[1]),
    ("body_qy", "1", |s| s.quaternion[2]),
    ("body_qz", "1", |s| s.quaternion[3]),
    ("body_omega_roll", "rad/ms", |s| s.flight.omega.x),
    ("body_omega_yaw", "rad/ms", |s| s.flight.omega.y),
    ("body_omega_pitch", "rad/ms", |s| s.flight.omega.z),
    ("body_x", "mm", |s| s.flight.position.x),
    ("body_y", "mm", |s| s.flight.position.y),
    ("body_z", "mm", |s| s.flight.position.z),
    ("body_vx", "mm/ms", |s| s.flight.velocity.x),
    ("body_vy", "mm/ms", |s| s.flight.velocity.y),
    ("body_vz", "mm/ms", |s| s.flight.velocity.z),
    ("body_force_x", "mN", |s| s.flight.wing_force.x),
    ("body_force_y", "mN", |s| s.flight.wing_force.y),
    ("body_force_z", "mN", |s| s.flight.wing_force.z),
    ("body_torque_roll", "mN*mm", |s| s.flight.wing_torque.x),
    ("body_torque_yaw", "mN*mm", |s| s.flight.wing_torque.y),
    ("body_torque_pitch", "mN*mm", |s| s.flight.wing_torque.z),
    ("aero_force_x", "mN", |s| s.flight.aero_force.x),
    ("aero_force_y", "mN", |s| s.flight.aero_force.y),
    ("aero_force_z", "mN", |s| s.flight.aero_force.z),
    ("lift", "mN", FlightSample::lift),
    ("momentum_x", "mg*mm/ms", |s| s.flight.momentum.x),
    ("momentum_y", "mg*mm/ms", |s| s.flight.momentum.y),
    ("momentum_z", "mg*mm/ms", |s| s.flight.momentum.z),
    ("angular_momentum_x", "mg*mm^2/ms", |s| {
        s.flight.angular_momentum.x
    }),
    ("angular_momentum_y", "mg*mm^2/ms", |s| {
        s.flight.angular_momentum.y
    }),
    ("angular_momentum_z", "mg*mm^2/ms", |s| {
        s.flight.angular_momentum.z
    }),
];

/// The body metrics, means over the recorded window's whole wingbeats (`lift_world_mean`:
/// the aerodynamic force along "up" in the world; `lift_mean` and `lift_to_weight`, along the
/// body's lift axis, are device metrics).
pub const BODY_METRICS: [&str; 14] = [
    "body_omega_roll_mean",
    "body_omega_yaw_mean",
    "body_omega_pitch_mean",
    "body_roll_final",
    "body_yaw_final",
    "body_pitch_final",
    "body_force_x_mean",
    "body_force_y_mean",
    "body_force_z_mean",
    "body_torque_roll_mean",
    "body_torque_yaw_mean",
    "body_torque_pitch_mean",
    "lift_world_mean",
    "body_displacement",
];

/// A flight column: a device column or a body column.
#[derive(Clone)]
enum FlightColumn {
    Device(Column),
    Body(BodyGetter),
}

impl FlightColumn {
    fn name(&self) -> String {
        match self {
            FlightColumn::Device(c) => c.name.clone(),
            FlightColumn::Body(b) => b.0.to_string(),
        }
    }
    fn unit(&self) -> &'static str {
        match self {
            FlightColumn::Device(c) => c.unit,
            FlightColumn::Body(b) => b.1,
        }
    }
    fn get(&self, s: &FlightSample) -> f64 {
        match self {
            FlightColumn::Device(c) => c.get(&s.sample),
            FlightColumn::Body(b) => (b.2)(s),
        }
    }
}

fn all_columns(model: &FlightModel) -> Vec<FlightColumn> {
    // The source device: its wings' aero laws say which force columns exist.
    column_table(model.source())
        .into_iter()
        .map(FlightColumn::Device)
        .chain(BODY_COLUMNS.iter().copied().map(FlightColumn::Body))
        .collect()
}

/// Every trajectory column name of a flight run (device columns, then body columns).
pub fn flight_columns(model: &FlightModel) -> Vec<String> {
    all_columns(model).iter().map(FlightColumn::name).collect()
}

/// [`flight_columns`] with each column's unit (`mN*mm`, `rad/ms`, ...).
pub fn flight_column_units(model: &FlightModel) -> Vec<(String, &'static str)> {
    all_columns(model)
        .iter()
        .map(|c| (c.name(), c.unit()))
        .collect()
}

/// Every metric name of a flight run (the device's, then [`BODY_METRICS`]).
pub fn flight_metrics(model: &FlightModel) -> Vec<String> {
    paritysim_dynamics::metrics::names_weighed(model.source(), true)
        .into_iter()
        .chain(BODY_METRICS.iter().map(|s| s.to_string()))
        .collect()
}

fn select(model: &FlightModel, names: Option<&[String]>) -> Result<Vec<FlightColumn>> {
    let table = all_columns(model);
    let Some(names) = names else {
        return Ok(table);
    };
    names
        .iter()
        .map(|name| {
            table
                .iter()
                .find(|c| &c.name() == name)
                .cloned()
                .ok_or_else(|| {
                    Error::invalid(
                        "columns",
                        format!("{name:?}"),
                        format!(
                            "one of: {}",
                            table
                                .iter()
                                .map(FlightColumn::name)
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                    )
                })
        })
        .collect()
}

/// Streams body metrics.
#[derive(Default)]
struct BodyAccumulator {
    n: usize,
    omega: Vector3<f64>,
    force: Vector3<f64>,
    torque: Vector3<f64>,
    lift: f64,
    last_angles: Vector3<f64>,
    start: Option<Vector3<f64>>,
    last_position: Vector3<f64>,
}

impl BodyAccumulator {
    fn add(&mut self, s: &FlightSample, closing: bool) {
        self.last_angles = s.angles;
        self.last_position = s.flight.position;
        if self.start.is_none() {
            self.start = Some(s.flight.position);
        }
        if closing {
            return;
        }
        self.n += 1;
        self.omega += s.flight.omega;
        self.force += s.flight.wing_force;
        self.torque += s.flight.wing_torque;
        self.lift += s.lift();
    }

    fn finish(&self) -> Vec<(String, f64)> {
        let n = self.n.max(1) as f64;
        let (o, f, t) = (self.omega / n, self.force / n, self.torque / n);
        let lift = self.lift / n;
        let moved = (self.last_position - self.start.unwrap_or_default()).norm();
        let values = [
            o.x,
            o.y,
            o.z,
            self.last_angles.x,
            self.last_angles.y,
            self.last_angles.z,
            f.x,
            f.y,
            f.z,
            t.x,
            t.y,
            t.z,
            lift,
            moved,
        ];
        BODY_METRICS
            .iter()
            .zip(values)
            .map(|(k, v)| (k.to_string(), v))
            .collect()
    }
}

/// Initial body state of a flight run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Release {
    /// Attitude (body to world).
    pub attitude: UnitQuaternion<f64>,
    /// Angular velocity (body frame, rad/ms).
    pub omega: Vector3<f64>,
    /// Velocity (world, mm/ms).
    pub velocity: Vector3<f64>,
}

impl Default for Release {
    fn default() -> Self {
        Self {
            attitude: UnitQuaternion::identity(),
            omega: Vector3::zeros(),
            velocity: Vector3::zeros(),
        }
    }
}

/// The body's values at one instant, as the [`BODY_COLUMNS`] name them (what an external
/// controller sees).
pub fn body_values(sample: &FlightSample) -> Vec<(&'static str, f64)> {
    BODY_COLUMNS
        .iter()
        .map(|(name, _, get)| (*name, get(sample)))
        .collect()
}

/// An external controller (e.g. a Python callback): called at `t` (ms) with the flight
/// sample there, returns the inputs held until its next tick (added to the set points and
/// the PD controller's output).
pub type Controller<'a> = dyn FnMut(f64, &FlightSample) -> Result<Inputs> + 'a;

/// The flight equations with constant (or, [`Self::with_inputs_at`], timed) inputs as an
/// [`ArraySystem`]: the wings' switching
/// functions ([`FlightModel::switches`]) make the integrator stop each step at a stroke
/// reversal (and the other surfaces where the blade-element model jumps or kinks) and hold
/// the smooth branch in between (event location, docs/flight.md#cost).
#[derive(Clone, Copy)]
pub struct FlightSystem<'a> {
    model: &'a FlightModel,
    inputs: Inputs,
    /// Inputs varying within the integration (linear set points), else `inputs` throughout.
    inputs_at: Option<&'a dyn Fn(f64) -> Inputs>,
    events: bool,
}

impl<'a> FlightSystem<'a> {
    /// The system of `model` at `inputs`, with event location.
    pub fn new(model: &'a FlightModel, inputs: Inputs) -> Self {
        Self {
            model,
            inputs,
            inputs_at: None,
            events: true,
        }
    }

    /// The same system with inputs that vary with time (`inputs_at(t)` at every evaluation).
    pub fn with_inputs_at(mut self, inputs_at: &'a dyn Fn(f64) -> Inputs) -> Self {
        self.inputs_at = Some(inputs_at);
        self
    }

    /// The same system without event location (the right-hand side on the state's own sides,
    /// steps straddling the jumps: comparisons).
    pub fn without_events(mut self) -> Self {
        self.events = false;
        self
    }

    /// Integrates from `(t0, y0)` to `t_end` with `method`, `rtol`, `atol`, at most
    /// `max_steps` steps, sampling `times` into `sink`; returns the end state and the step
    /// counters.
    ///
    /// # Errors
    /// As [`integrate_system`].
    #[allow(clippy::too_many_arguments)]
    pub fn integrate(
        mut self,
        (method, rtol, atol, max_steps): (Method, f64, f64, usize),
        t0: f64,
        y0: &[f64; STATE_LEN],
        t_end: f64,
        times: &[f64],
        sink: &mut ArraySink<'_, STATE_LEN>,
    ) -> Result<([f64; STATE_LEN], IntegrationStats)> {
        integrate_system(
            method, rtol, atol, max_steps, &mut self, t0, y0, t_end, times, sink,
        )
    }
}

impl ArraySystem<STATE_LEN> for FlightSystem<'_> {
    #[inline]
    fn rhs(
        &mut self,
        t: f64,
        y: &[f64; STATE_LEN],
        sides: Sides,
        dydt: &mut [f64; STATE_LEN],
    ) -> Result<()> {
        let branches = self.events.then(|| self.model.branches(sides));
        let inputs = self.inputs_at.map_or(self.inputs, |at| at(t));
        self.model.rhs_on(t, y, &inputs, branches.as_ref(), dydt)
    }

    fn n_switches(&self) -> usize {
        if self.events {
            self.model.n_switches()
        } else {
            0
        }
    }

    fn switches(
        &mut self,
        _t: f64,
        y: &[f64; STATE_LEN],
        g: &mut [f64; MAX_SWITCHES],
    ) -> Result<()> {
        self.model.switches(y, g)
    }
}

/// Runs a flight: steady state on the clamped body, release, `record_cycles` wingbeats (or
/// `duration_ms` without a drive) sampled `samples_per_cycle` times per wingbeat.
///
/// # Errors
/// The engine's errors for the clamped steady state; [`Error::Integration`] in flight (with
/// the time and the first 12 state entries); [`Error::InvalidParameter`] for unknown columns.
pub fn fly(
    model: &FlightModel,
    options: &SimulationOptions,
    release: &Release,
    schedule: &Schedule,
) -> Result<SimulationResult> {
    fly_controlled(model, options, release, schedule, None)
}

/// [`fly`] with an external controller ticking every `period_ms` from the release (zero-order
/// hold between ticks), next to the schedule's own PD controller (each at its own rate).
///
/// # Errors
/// As [`fly`]; [`Error::InvalidParameter`] (`control_rate_hz`) for a non-positive or
/// non-finite period; whatever the controller returns (the run stops there).
pub fn fly_controlled(
    model: &FlightModel,
    options: &SimulationOptions,
    release: &Release,
    schedule: &Schedule,
    mut external: Option<(f64, &mut Controller<'_>)>,
) -> Result<SimulationResult> {
    if let Some((period, _)) = &external {
        if !(period.is_finite() && *period > 0.0) {
            return Err(Error::invalid(
                "control_rate_hz",
                1000.0 / period,
                "a positive, finite control rate (Hz)",
            ));
        }
    }
    let columns = select(model, options.columns.as_deref())?;
    // Steady state of the wings on the clamped body (no recording).
    let steady_options = SimulationOptions {
        columns: Some(Vec::new()),
        record_cycles: 1,
        samples_per_cycle: 8,
        ..options.clone()
    };
    let device = model.device();
    let steady = paritysim_dynamics::simulate(model.source(), &steady_options)?;
    let wings0 = model.convert_state(&steady.steady_state.without_work())?;
    let period = device.period();
    let t0 = match period {
        Some(p) => steady.cycles_run as f64 * p,
        None => 0.0,
    };
    let window = match period {
        Some(p) => p * options.record_cycles as f64,
        None => options.duration_ms.ok_or_else(|| {
            Error::invalid(
                "duration_ms",
                "None",
                "a duration (ms) for a device without a periodic drive",
            )
        })?,
    };
    let n_samples = options.samples_per_cycle * options.record_cycles;
    let y0 = model.state(
        &release.attitude,
        &Vector3::zeros(),
        &release.velocity,
        &release.omega,
        &wings0,
    );
    let times: Vec<f64> = (0..=n_samples)
        .map(|k| {
            if k == n_samples {
                t0 + window
            } else {
                t0 + window * k as f64 / n_samples as f64
            }
        })
        .collect();
    let _budget = paritysim_dynamics::integrate::budget::Budget::new(
        options.max_wall_ms,
        options.cancel.clone(),
    )
    .enter();
    let weight = model.total_mass() * model.body().gravity.norm();
    let mut metrics = MetricsAccumulator::new(model.source(), period).with_weight(Some(weight));
    let mut body = BodyAccumulator::default();
    let mut trajectory = Trajectory {
        time: Vec::with_capacity(if columns.is_empty() { 0 } else { times.len() }),
        columns: columns
            .iter()
            .map(|c| (c.name(), Vec::with_capacity(times.len())))
            .collect(),
    };
    // Control legs: each controller's output is held between its ticks (tick k at
    // t0 + k·period, so both rates keep their own grid).
    let pd_period = schedule.control.as_ref().map(Control::period_ms);
    let ext_period = external.as_ref().map(|(p, _)| *p);
    let mut ticks = [0usize; 2];
    let tick_time =
        |period: Option<f64>, k: usize| period.map_or(f64::INFINITY, |p| t0 + p * k as f64);
    let mut y = y0;
    let mut t = t0;
    let mut next = 0;
    let t_end = t0 + window;
    let (mut output, mut extra) = (0.0, Inputs::default());
    while t < t_end {
        let due = |period: Option<f64>, k: usize| tick_time(period, k) <= t + 1e-12 * window;
        if due(pd_period, ticks[0]) || due(ext_period, ticks[1]) {
            let f = FlightSample::new(model, t, &y, &Inputs::default())?;
            if due(pd_period, ticks[0]) {
                if let Some(c) = &schedule.control {
                    output = c.output(f.angles[c.axis], f.flight.omega[c.axis]);
                }
                ticks[0] += 1;
            }
            if due(ext_period, ticks[1]) {
                if let Some((_, controller)) = external.as_mut() {
                    extra = controller(t, &f)?;
                }
                ticks[1] += 1;
            }
        }
        // Legs also end at the set points' nodes (no step straddles a kink or a jump; a
        // set point is evaluated inside the leg, at its times from the release).
        let next_tick = tick_time(pd_period, ticks[0])
            .min(tick_time(ext_period, ticks[1]))
            .min(t0 + schedule.next_node(t - t0, 1e-12 * window));
        let t_leg = if next_tick >= t_end - 1e-12 * window {
            t_end
        } else {
            next_tick
        };
        let mid = 0.5 * (t + t_leg) - t0;
        // Without linear set points (or a linear shape) the inputs are constant over the leg.
        let varying = schedule
            .set_points
            .iter()
            .chain(schedule.control.as_ref().and_then(|c| c.shape.as_ref()))
            .any(|s| s.interpolation == Interpolation::Linear);
        let held = schedule.inputs(mid, mid, output).plus(&extra);
        let leg_inputs = |tt: f64| {
            if varying {
                schedule.inputs(tt - t0, mid, output).plus(&extra)
            } else {
                held
            }
        };
        let end = times.partition_point(|&s| s < t_leg);
        let end = if t_leg == t_end { times.len() } else { end };
        let leg_times = &times[next..end];
        let offset = next;
        let mut sink = |i: usize, tt: f64, yy: &[f64; STATE_LEN]| -> Result<()> {
            let s = FlightSample::new(model, tt, yy, &leg_inputs(tt))?;
            let closing = offset + i == n_samples;
            metrics.add(&s.sample, closing);
            body.add(&s, closing);
            if !columns.is_empty() {
                trajectory.time.push(tt);
                for (c, (_, v)) in columns.iter().zip(&mut trajectory.columns) {
                    v.push(c.get(&s));
                }
            }
            Ok(())
        };
        let system = FlightSystem::new(model, held);
        let system = if varying {
            system.with_inputs_at(&leg_inputs)
        } else {
            system
        };
        let (y1, _) = system.integrate(
            (
                options.method,
                options.rtol,
                options.atol,
                options.max_steps,
            ),
            t,
            &y,
            t_leg,
            leg_times,
            &mut sink,
        )?;
        y = y1;
        t = t_leg;
        next = end;
    }
    let mut all = metrics.finish();
    all.extend(body.finish());
    Ok(SimulationResult {
        trajectory,
        metrics: all,
        cycles_run: steady.cycles_run,
        converged: steady.converged,
        period_ms: period.unwrap_or(f64::NAN),
        residual: steady.residual,
        steady_state: steady.steady_state,
        multipliers: steady.multipliers,
        // The flight has no periodic orbit of its own: the clamped start's shooting data
        // describes the torque stand, not this run.
        monodromy: None,
        step_grid: Vec::new(),
        orbit_cycles: 1,
        orbit_samples: None,
    })
}

/// Integrates a flight state from `(t0, y0)` to `t_end` with constant inputs (tests, trim
/// and custom protocols), sampling at `times`.
///
/// # Errors
/// As [`fly`].
#[allow(clippy::too_many_arguments)]
pub fn integrate_flight(
    model: &FlightModel,
    options: &SimulationOptions,
    inputs: &Inputs,
    t0: f64,
    y0: &[f64; STATE_LEN],
    t_end: f64,
    times: &[f64],
    sink: &mut ArraySink<'_, STATE_LEN>,
) -> Result<[f64; STATE_LEN]> {
    FlightSystem::new(model, *inputs)
        .integrate(
            (
                options.method,
                options.rtol,
                options.atol,
                options.max_steps,
            ),
            t0,
            y0,
            t_end,
            times,
            sink,
        )
        .map(|(y, _)| y)
}

/// A state of the flight model from a device state (zero body velocity, identity attitude).
pub fn released(model: &FlightModel, wings: &State) -> [f64; STATE_LEN] {
    let r = Release::default();
    model.state(&r.attitude, &Vector3::zeros(), &r.velocity, &r.omega, wings)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn euler_angles_invert_the_xyz_composition() {
        for (roll, yaw, pitch) in [(0.3, -0.4, 1.1), (-2.5, 0.2, -0.7), (0.0, 1.2, 3.0)] {
            let q = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), roll)
                * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), yaw)
                * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), pitch);
            let a = euler_angles(&q);
            assert!((a - Vector3::new(roll, yaw, pitch)).amax() < 1e-12, "{a:?}");
        }
    }
}
