//! Derived quantities at a sample, and the trajectory column table (name, unit, getter).
//!
//! Body reaction torques: the wing pushes on the body with
//! `τ_react = R6 (τ_aero⁶ − (I ω̇ + ω × I ω))` (aerodynamic part and inertial part), expressed
//! in the wing's shoulder ground frame. Body axes (Fig. 2.10, our reading): roll about the
//! stroke axis x̂, yaw about ŷ (normal to the resting wing plane, the lift direction of a
//! deviated stroke plane), pitch about ẑ (spanwise, lateral). The left wing's frame is the
//! mirror image of the right's through the sagittal plane, so its roll and yaw components change
//! sign: with symmetric strokes the roll torques cancel (eq. 3.23: `Δτ = τL + τR`).

use nalgebra::{Vector2, Vector3};
use paritysim_error::{Error, Result};

use crate::device::{Device, Evaluation};
use crate::integrate::State;
use crate::metrics::forces;
use crate::metrics::needs::StrokeNeeds;
pub use crate::metrics::plane_sample::PlaneSample;

/// Everything derived from one sample `(t, y)`: the model evaluation and the body torques.
#[derive(Clone, Copy, Debug)]
pub struct Sample {
    /// Time (ms).
    pub time: f64,
    /// Integrator state.
    pub state: State,
    /// Full model evaluation.
    pub eval: Evaluation,
    /// Aerodynamic body reaction torque (roll, yaw, pitch) per wing (mN·mm).
    pub aero: [Vector3<f64>; 2],
    /// Inertial body reaction torque per wing (mN·mm).
    pub inertial: [Vector3<f64>; 2],
    /// Sum over wings of aerodynamic + inertial (mN·mm).
    pub total: Vector3<f64>,
    /// Aerodynamic force on each wing (mN), in the body frame (the left wing mirrored,
    /// `crate::metrics::forces`); zero for wings without a force model.
    pub force: [Vector3<f64>; 2],
    /// Power the wings give to the air (mW = µJ/ms; the rate of `−work_aero`).
    pub aero_power: f64,
    /// Power the drive delivers, both sides of a dual drivetrain ([`Device::actuator_power`];
    /// mW, the rate of `work_actuator`).
    pub actuator_power: f64,
    /// Drive voltage (V).
    pub voltage: f64,
    /// Mechanical energy (µJ).
    pub energy: f64,
}

impl Sample {
    /// Evaluates the model and the body torques at `(t, y)`.
    ///
    /// # Errors
    /// Whatever [`Device::evaluate_state`] returns.
    pub fn new(device: &Device, time: f64, state: &State) -> Result<Self> {
        let eval = device.evaluate_state(time, state)?;
        let mut aero = [Vector3::zeros(); 2];
        let mut inertial = [Vector3::zeros(); 2];
        let mut total = Vector3::zeros();
        for w in 0..device.n_wings() {
            (aero[w], inertial[w]) = body_torques(device, &eval, w);
            total += aero[w] + inertial[w];
        }
        let voltage = device
            .spec()
            .actuator
            .as_ref()
            .map_or(0.0, |a| a.waveform().voltage(time));
        Ok(Self {
            time,
            state: *state,
            energy: device.energy(&eval),
            force: forces::of_evaluation(device, &eval),
            aero_power: forces::aero_power(device, &eval),
            actuator_power: device.actuator_power(
                time,
                eval.drive.actuator_force,
                &eval.drive.q_dot,
            ),
            eval,
            aero,
            inertial,
            total,
            voltage,
        })
    }

    /// Body reaction torque of wing `w` (aerodynamic + inertial).
    pub fn wing_torque(&self, w: usize) -> Vector3<f64> {
        self.aero[w] + self.inertial[w]
    }
}

/// What the metrics read at a sample of a fixed-wing device in drivetrain coordinates, computed
/// only as far as the asked metrics need ([`StrokeNeeds`]): the stroke kinematics always (the
/// forward map), the actuator force, the body reaction torques (closed form,
/// [`crate::wing::Wing::stroke_reaction_torques`]) and the work integrals when needed. No mass
/// matrix, no general wing terms: the same numbers as a [`Sample`] (tested to 1e-12) at a
/// fraction of its cost.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StrokeSample {
    /// Time (ms).
    pub time: f64,
    /// What was computed (the other fields are zero).
    pub needs: StrokeNeeds,
    /// `(φL, φR)` (rad).
    pub stroke: Vector2<f64>,
    /// Aerodynamic body roll torque per wing (mN·mm; the left wing mirrored, as
    /// [`Sample::aero`]`[w].x`): the drag torque about the stroke axis, which a stroke-only
    /// wing's roll frame keeps.
    pub roll_aero: [f64; 2],
    /// Actuator force (mN; with [`StrokeNeeds::force`] or [`StrokeNeeds::torques`]).
    pub actuator_force: f64,
    /// Whippletree angle `q2` (rad; on a dual drivetrain the right actuator's displacement, mm).
    pub q2: f64,
    /// Body reaction torque (aerodynamic + inertial, roll/yaw/pitch, left mirrored) per wing,
    /// as [`Sample::wing_torque`] (with [`StrokeNeeds::torques`]).
    pub torque: [Vector3<f64>; 2],
    /// Their sum, as [`Sample::total`].
    pub total: Vector3<f64>,
    /// `(work_actuator, work_aero)` of the state (µJ; with [`StrokeNeeds::work`]).
    pub work: (f64, f64),
}

impl StrokeSample {
    /// The sample at `(t, y)`; `None` unless the device integrates drivetrain coordinates.
    ///
    /// # Errors
    /// A drivetrain evaluation outside the linkage's domain.
    pub fn new(device: &Device, time: f64, y: &State, needs: StrokeNeeds) -> Option<Result<Self>> {
        device.stroke_state(y)?.ok()?;
        Some(Self::of_stroke_device(device, time, y, needs))
    }

    /// [`Self::new`] for a device known to integrate drivetrain coordinates.
    #[inline]
    pub(crate) fn of_stroke_device(
        device: &Device,
        time: f64,
        y: &State,
        needs: StrokeNeeds,
    ) -> Result<Self> {
        let wings = &device.spec().wings;
        let work = if needs.work {
            (y.work_actuator, y.work_aero)
        } else {
            (0.0, 0.0)
        };
        if needs.torques {
            let m = device.stroke_motion_unchecked(time, y)?;
            let mut torque = [Vector3::zeros(); 2];
            let mut total = Vector3::zeros();
            let mut roll_aero = [0.0; 2];
            for (w, wing) in wings.iter().enumerate() {
                let (aero, inertial) =
                    wing.stroke_reaction_torques(m.stroke[w], m.rate[w], m.accel[w]);
                // The left wing (index 0) mirrored through the sagittal plane.
                let (aero, inertial) = if w == 0 {
                    let mirror = Vector3::new(-1.0, -1.0, 1.0);
                    (aero.component_mul(&mirror), inertial.component_mul(&mirror))
                } else {
                    (aero, inertial)
                };
                roll_aero[w] = aero.x;
                torque[w] = aero + inertial;
                total += torque[w];
            }
            return Ok(Self {
                time,
                needs,
                stroke: m.stroke,
                roll_aero,
                actuator_force: m.actuator_force,
                q2: m.q2,
                torque,
                total,
                work,
            });
        }
        let (stroke, rate, q2) = device.stroke_state_unchecked(y)?;
        let right = wings[1].aero().stroke_torque(rate.y);
        // The left wing's roll axis is mirrored through the sagittal plane.
        let left = -wings[0].aero().stroke_torque(rate.x);
        let actuator_force = match (&device.spec().actuator, needs.force) {
            (Some(a), true) => a.force(time),
            _ => 0.0,
        };
        Ok(Self {
            time,
            needs,
            stroke,
            roll_aero: [left, right],
            actuator_force,
            q2,
            torque: [Vector3::zeros(); 2],
            total: Vector3::zeros(),
            work,
        })
    }
}

impl PlaneSample {
    /// The sample at `(t, y)`; `None` unless the device has the stroke-plane model and `y`
    /// is in its closed form (then a [`Sample`] applies).
    ///
    /// # Errors
    /// A reduced mass matrix that is not positive definite.
    pub fn new(device: &Device, time: f64, y: &State, needs: StrokeNeeds) -> Option<Result<Self>> {
        device.plane_sample(time, y, needs)
    }
}

/// Body reaction torques (roll, yaw, pitch) of wing `w`: (aerodynamic, inertial).
fn body_torques(device: &Device, e: &Evaluation, w: usize) -> (Vector3<f64>, Vector3<f64>) {
    let terms = &e.wings[w];
    let inertia = device.spec().wings[w].inertia();
    let k = 3 * w;
    let p_ddot = Vector3::new(e.p_ddot[k], e.p_ddot[k + 1], e.p_ddot[k + 2]);
    let omega_dot = terms.j6 * p_ddot + terms.jdot_pdot;
    let inertial6 = -(inertia * omega_dot + terms.omega.cross(&(inertia * terms.omega)));
    let aero = terms.rotation * terms.aero_frame6;
    let inertial = terms.rotation * inertial6;
    // Mirror the left wing (index 0 of two) through the sagittal plane.
    let mirror = if device.n_wings() == 2 && w == 0 {
        Vector3::new(-1.0, -1.0, 1.0)
    } else {
        Vector3::new(1.0, 1.0, 1.0)
    };
    (aero.component_mul(&mirror), inertial.component_mul(&mirror))
}

/// How a column reads a [`Sample`].
#[derive(Clone, Copy)]
enum Getter {
    Wing(usize, fn(&Sample, usize) -> f64),
    Device(fn(&Sample) -> f64),
}

/// One trajectory column: name, unit and how it is computed from a sample.
#[derive(Clone)]
pub struct Column {
    /// Column name (`left_phi`, `q2_dot`, ...).
    pub name: String,
    /// Unit (mg-mm-ms-rad-V system).
    pub unit: &'static str,
    getter: Getter,
}

impl std::fmt::Debug for Column {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Column({} [{}])", self.name, self.unit)
    }
}

impl Column {
    /// The column's value at a sample.
    pub fn get(&self, s: &Sample) -> f64 {
        match self.getter {
            Getter::Wing(w, g) => g(s, w),
            Getter::Device(g) => g(s),
        }
    }
}

type WingGetter = (&'static str, &'static str, fn(&Sample, usize) -> f64);
type DeviceGetter = (&'static str, &'static str, fn(&Sample) -> f64);

const PER_WING: [WingGetter; 23] = [
    ("phi", "rad", |s, w| s.eval.p[3 * w]),
    ("theta", "rad", |s, w| s.eval.p[3 * w + 1]),
    ("psi", "rad", |s, w| s.eval.p[3 * w + 2]),
    ("phi_dot", "rad/ms", |s, w| s.eval.p_dot[3 * w]),
    ("theta_dot", "rad/ms", |s, w| s.eval.p_dot[3 * w + 1]),
    ("psi_dot", "rad/ms", |s, w| s.eval.p_dot[3 * w + 2]),
    ("phi_ddot", "rad/ms^2", |s, w| s.eval.p_ddot[3 * w]),
    // θ̈, ψ̈: the rest of Appendix A's p̈, so the equations of motion can be checked from outside.
    ("theta_ddot", "rad/ms^2", |s, w| s.eval.p_ddot[3 * w + 1]),
    ("psi_ddot", "rad/ms^2", |s, w| s.eval.p_ddot[3 * w + 2]),
    ("theta_w", "rad", |s, w| s.eval.wings[w].theta_w),
    ("tau_aero_phi", "mN*mm", |s, w| s.eval.wings[w].aero[0]),
    ("tau_aero_theta", "mN*mm", |s, w| s.eval.wings[w].aero[1]),
    ("tau_aero_psi", "mN*mm", |s, w| s.eval.wings[w].aero[2]),
    ("tau_spring_phi", "mN*mm", |s, w| -s.eval.wings[w].spring[0]),
    ("tau_spring_theta", "mN*mm", |s, w| {
        -s.eval.wings[w].spring[1]
    }),
    ("tau_spring_psi", "mN*mm", |s, w| -s.eval.wings[w].spring[2]),
    ("roll_aero", "mN*mm", |s, w| s.aero[w].x),
    ("yaw_aero", "mN*mm", |s, w| s.aero[w].y),
    ("pitch_aero", "mN*mm", |s, w| s.aero[w].z),
    ("roll_inertial", "mN*mm", |s, w| s.inertial[w].x),
    ("yaw_inertial", "mN*mm", |s, w| s.inertial[w].y),
    ("pitch_inertial", "mN*mm", |s, w| s.inertial[w].z),
    ("kinetic_energy", "uJ", |s, w| s.eval.wings[w].kinetic),
];

const PER_DEVICE: [DeviceGetter; 14] = [
    ("q1", "mm", |s| s.eval.drive.q.x),
    ("q2", "rad", |s| s.eval.drive.q.y),
    ("q1_dot", "mm/ms", |s| s.eval.drive.q_dot.x),
    ("q2_dot", "rad/ms", |s| s.eval.drive.q_dot.y),
    ("voltage", "V", |s| s.voltage),
    ("actuator_force", "mN", |s| s.eval.drive.actuator_force),
    // Both sides of a dual drivetrain: the rate of `work_actuator` (it was the left side's).
    ("actuator_power", "uJ/ms", |s| s.actuator_power),
    ("work_actuator", "uJ", |s| s.state.work_actuator),
    ("work_aero", "uJ", |s| s.state.work_aero),
    ("mechanical_energy", "uJ", |s| s.energy),
    ("roll_total", "mN*mm", |s| s.total.x),
    ("yaw_total", "mN*mm", |s| s.total.y),
    ("pitch_total", "mN*mm", |s| s.total.z),
    ("aero_power", "uJ/ms", |s| s.aero_power),
];

/// Per-wing force columns (body frame), where the device offers forces
/// ([`forces::offers_forces`]).
const PER_WING_FORCE: [WingGetter; 3] = [
    ("lift", "mN", |s, w| s.force[w].x),
    ("aero_force_y", "mN", |s, w| s.force[w].y),
    ("aero_force_z", "mN", |s, w| s.force[w].z),
];

/// Wing name prefixes: `left`, `right` for two wings, `wing` for one.
pub fn wing_prefixes(device: &Device) -> &'static [&'static str] {
    if device.n_wings() == 2 {
        &["left", "right"]
    } else {
        &["wing"]
    }
}

/// Every trajectory column of this device, in the recorded order.
pub fn column_table(device: &Device) -> Vec<Column> {
    let mut out = Vec::with_capacity(PER_WING.len() * 2 + PER_DEVICE.len());
    for (w, prefix) in wing_prefixes(device).iter().enumerate() {
        for (name, unit, g) in PER_WING {
            out.push(Column {
                name: format!("{prefix}_{name}"),
                unit,
                getter: Getter::Wing(w, g),
            });
        }
    }
    for (name, unit, g) in PER_DEVICE {
        // A dual drivetrain's second coordinate is the right actuator's displacement, not a
        // whippletree angle (`right_phi = −T q2`).
        let unit = match (device.is_dual(), name) {
            (true, "q2") => "mm",
            (true, "q2_dot") => "mm/ms",
            _ => unit,
        };
        out.push(Column {
            name: name.to_string(),
            unit,
            getter: Getter::Device(g),
        });
    }
    if forces::offers_forces(device) {
        for (w, prefix) in wing_prefixes(device).iter().enumerate() {
            for (name, unit, g) in PER_WING_FORCE {
                out.push(Column {
                    name: format!("{prefix}_{name}"),
                    unit,
                    getter: Getter::Wing(w, g),
                });
            }
        }
    }
    out
}

/// The columns named in `names` (in that order), or all of them for `None`.
///
/// # Errors
/// [`Error::InvalidParameter`] (`columns`) for an unknown name, listing the valid ones.
pub fn select_columns(device: &Device, names: Option<&[String]>) -> Result<Vec<Column>> {
    let table = column_table(device);
    let Some(names) = names else {
        return Ok(table);
    };
    names
        .iter()
        .map(|name| {
            table
                .iter()
                .find(|c| &c.name == name)
                .cloned()
                .ok_or_else(|| {
                    Error::invalid(
                        "columns",
                        format!("{name:?}"),
                        format!(
                            "one of: {}",
                            table
                                .iter()
                                .map(|c| c.name.as_str())
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                    )
                })
        })
        .collect()
}

/// Sampled trajectory: time and named columns (ready for a DataFrame).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Trajectory {
    /// Sample times (ms).
    pub time: Vec<f64>,
    /// `(name, values)` in a fixed order.
    pub columns: Vec<(String, Vec<f64>)>,
}

impl Trajectory {
    /// A column by name.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.columns
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }
}

/// Builds the asked columns sample by sample.
pub(crate) struct Recorder {
    columns: Vec<Column>,
    trajectory: Trajectory,
}

impl Recorder {
    pub(crate) fn new(columns: Vec<Column>, capacity: usize) -> Self {
        let trajectory = Trajectory {
            time: Vec::with_capacity(if columns.is_empty() { 0 } else { capacity }),
            columns: columns
                .iter()
                .map(|c| (c.name.clone(), Vec::with_capacity(capacity)))
                .collect(),
        };
        Self {
            columns,
            trajectory,
        }
    }

    pub(crate) fn push(&mut self, s: &Sample) -> Result<()> {
        if self.columns.is_empty() {
            return Ok(());
        }
        self.trajectory.time.push(s.time);
        for (c, (_, values)) in self.columns.iter().zip(&mut self.trajectory.columns) {
            let v = c.get(s);
            if !v.is_finite() {
                return Err(Error::Integration {
                    time: s.time,
                    state: s.state.to_vec(),
                    reason: format!("non-finite derived quantity {}", c.name),
                });
            }
            values.push(v);
        }
        Ok(())
    }

    pub(crate) fn finish(self) -> Trajectory {
        self.trajectory
    }
}

/// Evaluates every column at the given samples.
///
/// # Errors
/// A model error at a sample, or [`Error::Integration`] for a non-finite derived quantity.
pub fn record(device: &Device, times: &[f64], states: &[State]) -> Result<Trajectory> {
    let mut recorder = Recorder::new(column_table(device), times.len());
    for (t, y) in times.iter().zip(states) {
        recorder.push(&Sample::new(device, *t, y)?)?;
    }
    Ok(recorder.finish())
}
