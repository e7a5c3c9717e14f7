//! Running a device: periodic steady state, perturbations, trajectories.
//!
//! Body reaction torques: the wing pushes on the body with
//! `τ_react = R6 (τ_aero⁶ − (I ω̇ + ω × I ω))` (aerodynamic part and inertial part), expressed
//! in the wing's shoulder ground frame. Body axes (Fig. 2.10, our reading): roll about the
//! stroke axis x̂, yaw about ŷ (normal to the resting wing plane, the lift direction of a
//! deviated stroke plane), pitch about ẑ (spanwise, lateral). The left wing's frame is the
//! mirror image of the right's through the sagittal plane, so its roll and yaw components change
//! sign: with symmetric strokes the roll torques cancel (eq. 3.23: `Δτ = τL + τR`).

use nalgebra::Vector3;
use paritysim_constraints::Vec6;
use paritysim_error::{Error, Result, bail, check_positive};

use crate::device::{Device, Evaluation};
use crate::integrate::{Integrator, Method, RungeKutta, State};
use crate::metrics;

/// An instantaneous velocity change.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PerturbTarget {
    /// The whippletree rate `q̇2` (rad/ms); Fig. 3.4 uses +2 rad/s = +0.002 rad/ms.
    WhippletreeRate,
    /// A configuration rate `ṗ_i` (i in 0..6).
    Coordinate(usize),
}

/// A velocity kick applied after the steady state, at `phase` (fraction of a cycle) into the
/// recording window.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Perturbation {
    /// What is kicked.
    pub target: PerturbTarget,
    /// Velocity change (rad/ms).
    pub delta: f64,
    /// Fraction of the first recorded cycle at which it is applied, in [0, 1).
    pub phase: f64,
}

/// Options of [`simulate`].
#[derive(Clone, Debug, PartialEq)]
pub struct SimulationOptions {
    /// Runge-Kutta pair.
    pub method: Method,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
    /// Step limit per integration call.
    pub max_steps: usize,
    /// Initial `(p, ṗ)`; zeros by default (must satisfy the constraints).
    pub initial: Option<(Vec6, Vec6)>,
    /// Cycles always simulated before checking for steady state.
    pub min_cycles: usize,
    /// Give up waiting for steady state after this many cycles (the result says `converged = false`).
    pub max_cycles: usize,
    /// Steady when the cycle-to-cycle change of the state is below this (relative to its size).
    pub steady_tol: f64,
    /// Samples per recorded cycle.
    pub samples_per_cycle: usize,
    /// Cycles recorded after steady state.
    pub record_cycles: usize,
    /// Optional velocity kick in the recording window.
    pub perturbation: Option<Perturbation>,
    /// Duration (ms) for devices without a periodic drive.
    pub duration_ms: Option<f64>,
}

impl Default for SimulationOptions {
    fn default() -> Self {
        Self {
            method: Method::Dop853,
            rtol: 1e-8,
            atol: 1e-10,
            max_steps: 1_000_000,
            initial: None,
            min_cycles: 3,
            max_cycles: 300,
            steady_tol: 1e-7,
            samples_per_cycle: 200,
            record_cycles: 1,
            perturbation: None,
            duration_ms: None,
        }
    }
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

/// The outcome of [`simulate`].
#[derive(Clone, Debug, PartialEq)]
pub struct SimulationResult {
    /// The recorded window.
    pub trajectory: Trajectory,
    /// Metrics over the recorded window (see [`metrics::compute`]).
    pub metrics: Vec<(String, f64)>,
    /// Cycles simulated before recording.
    pub cycles_run: usize,
    /// Whether the steady-state tolerance was met.
    pub converged: bool,
    /// Drive period (ms), NaN without an actuator.
    pub period_ms: f64,
}

fn validate(options: &SimulationOptions) -> Result<()> {
    check_positive("steady_tol", options.steady_tol)?;
    if options.samples_per_cycle < 8 {
        bail!(invalid "samples_per_cycle", options.samples_per_cycle, ">= 8");
    }
    if options.record_cycles == 0 {
        bail!(invalid "record_cycles", 0, ">= 1");
    }
    if options.max_cycles == 0 || options.max_cycles > 100_000 {
        bail!(invalid "max_cycles", options.max_cycles, "in [1, 100000]");
    }
    if let Some(p) = options.perturbation {
        if !p.delta.is_finite() {
            bail!(invalid "perturbation.delta", p.delta, "a finite number (rad/ms)");
        }
        if !(0.0..1.0).contains(&p.phase) {
            bail!(invalid "perturbation.phase", p.phase, "in [0, 1)");
        }
    }
    Ok(())
}

fn state_change(a: &State, b: &State) -> f64 {
    let mut num: f64 = 0.0;
    let mut den: f64 = 1e-12;
    for (x, y) in a
        .coords
        .iter()
        .chain(&a.rates)
        .zip(b.coords.iter().chain(&b.rates))
    {
        num = num.max((x - y).abs());
        den = den.max(x.abs());
    }
    num / den
}

/// Runs a device to periodic steady state (or for `duration_ms` without a drive) and records
/// the trajectory.
///
/// # Errors
/// [`Error::InvalidParameter`] for bad options; [`Error::Constraint`] for an inconsistent
/// initial state; [`Error::Integration`] (with time and state) when integration fails.
pub fn simulate(device: &Device, options: &SimulationOptions) -> Result<SimulationResult> {
    validate(options)?;
    let integrator = RungeKutta::new(
        options.method,
        options.rtol,
        options.atol,
        options.max_steps,
    )?;
    let (p0, pd0) = options
        .initial
        .unwrap_or((*device.spec().constraints.particular(), Vec6::zeros()));
    let mut y = device.state_from(&p0, &pd0)?;
    let mut t = 0.0;
    let mut cycles_run = 0;
    let mut converged = false;
    let period = device.period();
    let (window, n_samples) = match period {
        Some(period) => {
            // Cycles before the first convergence check run in one integrator call (no restarts).
            let warm_up = options
                .min_cycles
                .saturating_sub(1)
                .min(options.max_cycles.saturating_sub(1));
            if warm_up > 0 {
                let t_end = warm_up as f64 * period;
                y = integrator.integrate(device, 0.0, &y, t_end, &[t_end])?[0];
                t = t_end;
                cycles_run = warm_up;
            }
            while cycles_run < options.max_cycles {
                let next = integrator.integrate(device, t, &y, t + period, &[t + period])?[0];
                let change = state_change(&next, &y);
                y = next;
                t += period;
                cycles_run += 1;
                if cycles_run >= options.min_cycles && change < options.steady_tol {
                    converged = true;
                    break;
                }
            }
            (
                period * options.record_cycles as f64,
                options.samples_per_cycle * options.record_cycles,
            )
        }
        None => {
            let duration = options.duration_ms.ok_or_else(|| {
                Error::invalid(
                    "duration_ms",
                    "None",
                    "a duration (ms) for a device without a periodic drive",
                )
            })?;
            check_positive("duration_ms", duration)?;
            (duration, options.samples_per_cycle * options.record_cycles)
        }
    };
    // Work integrals restart in the recorded window.
    y = y.without_work();
    let t_start = t;
    // The last sample is exactly the window's end: t_start + window·k/n can round one ulp past
    // it, and the solver would then return one sample short.
    let t_end = t_start + window;
    let times: Vec<f64> = (0..=n_samples)
        .map(|k| {
            if k == n_samples {
                t_end
            } else {
                t_start + window * k as f64 / n_samples as f64
            }
        })
        .collect();
    let states = match options.perturbation {
        None => integrator.integrate(device, t_start, &y, t_end, &times)?,
        Some(kick) => {
            let t_kick = t_start + kick.phase * period.unwrap_or(window);
            let (before, after): (Vec<f64>, Vec<f64>) = times.iter().partition(|&&s| s < t_kick);
            let mut states = if before.is_empty() {
                Vec::new()
            } else {
                integrator.integrate(device, t_start, &y, t_kick, &before)?
            };
            let y_kick = if t_kick > t_start {
                integrator.integrate(device, t_start, &y, t_kick, &[t_kick])?[0]
            } else {
                y
            };
            let y_kicked = apply_kick(device, t_kick, &y_kick, kick)?;
            states.extend(integrator.integrate(device, t_kick, &y_kicked, t_end, &after)?);
            states
        }
    };
    let trajectory = record(device, &times, &states)?;
    let metrics = metrics::compute(device, &trajectory, period);
    Ok(SimulationResult {
        trajectory,
        metrics,
        cycles_run,
        converged,
        period_ms: period.unwrap_or(f64::NAN),
    })
}

fn apply_kick(device: &Device, t: f64, y: &State, kick: Perturbation) -> Result<State> {
    let (p, mut p_dot) = device.coordinates(y)?;
    match kick.target {
        PerturbTarget::WhippletreeRate => {
            let Some(tr) = &device.spec().transmission else {
                bail!(Constraint "a whippletree perturbation needs a 2-DOF drivetrain");
            };
            if tr.kinematics().dof() != 2 {
                bail!(Constraint "the {} drivetrain has no whippletree (q2)", tr.kinematics().name());
            }
            let drive = device.drive(t, &p, &p_dot)?;
            let j = tr.kinematics().evaluate(drive.q.x, drive.q.y)?.jacobian;
            p_dot[0] += j[(0, 1)] * kick.delta;
            p_dot[3] += j[(1, 1)] * kick.delta;
        }
        PerturbTarget::Coordinate(i) => {
            if i >= device.n_coords() {
                bail!(invalid "perturbation.coordinate", i, format!("in [0, {})", device.n_coords()));
            }
            p_dot[i] += kick.delta;
        }
    }
    let mut out = device.state_from(&p, &p_dot)?;
    out.work_actuator = y.work_actuator;
    out.work_aero = y.work_aero;
    Ok(out)
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

/// Evaluates every derived quantity at the samples.
pub fn record(device: &Device, times: &[f64], states: &[State]) -> Result<Trajectory> {
    let n_wings = device.n_wings();
    let prefixes: &[&str] = if n_wings == 2 {
        &["left", "right"]
    } else {
        &["wing"]
    };
    let per_wing = [
        "phi",
        "theta",
        "psi",
        "phi_dot",
        "theta_dot",
        "psi_dot",
        "phi_ddot",
        "theta_w",
        "tau_aero_phi",
        "tau_aero_theta",
        "tau_aero_psi",
        "tau_spring_phi",
        "tau_spring_theta",
        "tau_spring_psi",
        "roll_aero",
        "yaw_aero",
        "pitch_aero",
        "roll_inertial",
        "yaw_inertial",
        "pitch_inertial",
        "kinetic_energy",
    ];
    let device_cols = [
        "q1",
        "q2",
        "q1_dot",
        "q2_dot",
        "voltage",
        "actuator_force",
        "actuator_power",
        "work_actuator",
        "work_aero",
        "mechanical_energy",
        "roll_total",
        "yaw_total",
        "pitch_total",
    ];
    let mut names: Vec<String> = Vec::new();
    for p in prefixes {
        for c in per_wing {
            names.push(format!("{p}_{c}"));
        }
    }
    names.extend(device_cols.iter().map(|s| s.to_string()));
    let mut data: Vec<Vec<f64>> = vec![Vec::with_capacity(times.len()); names.len()];
    for (t, y) in times.iter().zip(states) {
        let e = device.evaluate_state(*t, y)?;
        let (p, p_dot) = (e.p, e.p_dot);
        let mut col = 0;
        let mut push = |v: f64| {
            data[col].push(v);
            col += 1;
        };
        let mut total = Vector3::zeros();
        for w in 0..n_wings {
            let k = 3 * w;
            let terms = &e.wings[w];
            for i in 0..3 {
                push(p[k + i]);
            }
            for i in 0..3 {
                push(p_dot[k + i]);
            }
            push(e.p_ddot[k]);
            push(terms.theta_w);
            for i in 0..3 {
                push(terms.aero[i]);
            }
            for i in 0..3 {
                push(-terms.spring[i]);
            }
            let (aero, inertial) = body_torques(device, &e, w);
            for i in 0..3 {
                push(aero[i]);
            }
            for i in 0..3 {
                push(inertial[i]);
            }
            push(terms.kinetic);
            total += aero + inertial;
        }
        let voltage = device
            .spec()
            .actuator
            .as_ref()
            .map_or(0.0, |a| a.waveform().voltage(*t));
        push(e.drive.q.x);
        push(e.drive.q.y);
        push(e.drive.q_dot.x);
        push(e.drive.q_dot.y);
        push(voltage);
        push(e.drive.actuator_force);
        push(e.drive.actuator_force * e.drive.q_dot.x);
        push(y.work_actuator);
        push(y.work_aero);
        push(device.energy(&e));
        push(total.x);
        push(total.y);
        push(total.z);
    }
    debug_assert!(data.iter().all(|c| c.len() == times.len()));
    if data.iter().flatten().any(|v| !v.is_finite()) {
        return Err(Error::Integration {
            time: *times.last().unwrap_or(&0.0),
            state: vec![],
            reason: "non-finite derived quantity".into(),
        });
    }
    Ok(Trajectory {
        time: times.to_vec(),
        columns: names.into_iter().zip(data).collect(),
    })
}
