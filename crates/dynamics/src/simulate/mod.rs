//! Running a device: periodic steady state, perturbations, streamed metrics and (when asked)
//! trajectory columns.

mod options;
mod shooting;
mod window;
pub(crate) use window::{
    WindowSampler, grid_window, grid_window_times, sampled_variational_period, window_times,
};

use paritysim_constraints::Vec6;
use paritysim_error::{Error, Result, bail, check_positive};

use crate::device::Device;
use crate::integrate::budget::Budget;
use crate::integrate::{Integrator, RungeKutta, State};
use crate::trajectory::select_columns;
pub use crate::trajectory::{Trajectory, record};

use options::check_recording_size;
pub(crate) use options::validate;
pub use options::{
    DEFAULT_MAX_WALL_MS, MAX_RECORDED_SAMPLES, MAX_RECORDING_BYTES, OrbitSamples,
    PERIOD_DOUBLED_SEPARATION, PERIOD_DOUBLED_SETTLED, PerturbTarget, Perturbation,
    SHOOTING_RETRY_APART, SimulationOptions, SimulationResult, SteadyState,
};
use shooting::Shot;
pub use shooting::UNSTABLE_MARGIN;
pub(crate) use shooting::shooting_steady_state;
pub use window::orbit_metrics;
use window::{record_window, stroke_sampling};

pub(crate) fn state_change(a: &State, b: &State) -> f64 {
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
/// initial state; [`Error::Integration`] (with time and state) when integration fails, more
/// than `max_steps` steps are needed in one integration or the run takes longer than
/// `max_wall_ms`; [`Error::Cancelled`] when `options.cancel` is set during the run.
pub fn simulate(device: &Device, options: &SimulationOptions) -> Result<SimulationResult> {
    validate(options)?;
    let _budget = Budget::new(options.max_wall_ms, options.cancel.clone()).enter();
    let columns = select_columns(device, options.columns.as_deref())?;
    check_recording_size(options, columns.len())?;
    let recording = RungeKutta::new(
        options.method,
        options.rtol,
        options.atol,
        options.max_steps,
    )?;
    // The transient needs no work integrals.
    let transient = recording.with_work(false);
    let (p0, pd0) = options
        .initial
        .unwrap_or((*device.spec().constraints.particular(), Vec6::zeros()));
    let mut y = device.state_from(&p0, &pd0)?;
    let mut t = 0.0;
    let mut cycles_run = 0;
    let mut converged = false;
    let mut residual = f64::NAN;
    let mut multipliers = Vec::new();
    let mut monodromy = None;
    let mut step_grid = Vec::new();
    let mut orbit_cycles = 1;
    // The recorded window when the shooting's last period already was it.
    let mut recorded: Option<(Trajectory, Vec<(String, f64)>)> = None;
    let mut orbit_samples = None;
    let stroke = stroke_sampling(device, options.metrics.as_deref(), &columns);
    // Lean samples that read no work integral need no work in the recorded window either.
    let recording = match stroke {
        Some(needs) if !needs.work => transient,
        _ => recording,
    };
    let period = device.period();
    let (window, n_samples) = match period {
        Some(period) => {
            let mut transient_needed = true;
            // After a first shooting that failed (`Some(None)`) or found an unstable orbit
            // (its state), the transient shoots once more when settled away from it.
            let mut retry: Option<Option<State>> = None;
            if options.steady_state == SteadyState::Shooting {
                match shooting_steady_state(
                    device, options, &recording, &transient, period, 1, false, &y, &columns, stroke,
                )? {
                    Shot::Found(found) => {
                        (y, t, cycles_run, residual, converged) =
                            (found.state, found.t, found.cycles_run, found.residual, true);
                        multipliers = found.multipliers;
                        monodromy = Some(found.jacobian);
                        step_grid = found.grid;
                        recorded = found.recorded;
                        orbit_samples = found.sampled;
                        transient_needed = false;
                    }
                    Shot::Unstable(state) => retry = Some(Some(state)),
                    Shot::Failed => retry = Some(None),
                }
            }
            // Takes a shooting result found after the transient's `t`: its orbit of
            // `$orbit_cycles` cycles, multipliers, grid and recorded window (labelled after the
            // transient's cycles too).
            macro_rules! take_found {
                ($found:expr, $orbit_cycles:expr) => {{
                    let found = $found;
                    (y, residual, converged, orbit_cycles) =
                        (found.state, found.residual, true, $orbit_cycles);
                    recorded = found.recorded;
                    if let Some((trajectory, _)) = &mut recorded {
                        for time in &mut trajectory.time {
                            *time += t;
                        }
                    }
                    t += found.t;
                    cycles_run += found.cycles_run;
                    multipliers = found.multipliers;
                    monodromy = Some(found.jacobian);
                    step_grid = found.grid;
                }};
            }
            if transient_needed {
                // Cycles before the first convergence check run in one integrator call.
                let warm_up = options
                    .min_cycles
                    .saturating_sub(1)
                    .min(options.max_cycles.saturating_sub(1));
                if warm_up > 0 {
                    let t_end = warm_up as f64 * period;
                    y = transient.advance(device, 0.0, &y, t_end)?;
                    t = t_end;
                    cycles_run = warm_up;
                }
                // The state two cycles back: a period-doubled orbit repeats over two cycles.
                let mut two_back: Option<State> = None;
                let mut shot_two_cycles = options.steady_state != SteadyState::Shooting;
                while cycles_run < options.max_cycles {
                    crate::integrate::budget::check(t)?;
                    let next = transient.advance(device, t, &y, t + period)?;
                    residual = state_change(&next, &y);
                    let residual_two = two_back.map(|b| state_change(&next, &b));
                    two_back = Some(y);
                    y = next;
                    t += period;
                    cycles_run += 1;
                    if cycles_run < options.min_cycles {
                        continue;
                    }
                    if residual < options.steady_tol {
                        converged = true;
                        break;
                    }
                    let Some(residual_two) = residual_two else {
                        continue;
                    };
                    // Doubled when the two cycles stay apart: a period-1 orbit approached
                    // with a multiplier μ near −1 has residual / residual_two = |μ / (1 + μ)|.
                    if residual_two < options.steady_tol
                        && residual > PERIOD_DOUBLED_SEPARATION * residual_two
                    {
                        (residual, converged, orbit_cycles) = (residual_two, true, 2);
                        break;
                    }
                    if residual < PERIOD_DOUBLED_SETTLED && retry_open(&retry, &y) {
                        // Settled, and not on the unstable orbit the shooting found from the
                        // warm-up (the §2.5 Dual PARITY has one next to its stable orbit):
                        // Newton once more, from here. Also when the transient alternates in
                        // (a multiplier in (−1, 0): the two-cycle change below the one-cycle
                        // one): it then used to run to `steady_tol` with no monodromy, so a
                        // sweep chain could not continue from it (docs/findings.md §22). A
                        // period-doubled orbit keeps a macroscopic one-cycle change, far above
                        // this gate; a small one near its flip finds the unstable period-1
                        // orbit here (not taken) and the two-cycle shooting below.
                        retry = None;
                        if let Shot::Found(found) = shooting_steady_state(
                            device, options, &recording, &transient, period, 1, true, &y, &columns,
                            stroke,
                        )? {
                            take_found!(found, 1);
                            break;
                        }
                    }
                    if !shot_two_cycles && residual_two < PERIOD_DOUBLED_SETTLED.min(residual) {
                        // Once per run: Newton on the two-cycle map from here.
                        shot_two_cycles = true;
                        if let Shot::Found(found) = shooting_steady_state(
                            device, options, &recording, &transient, period, 2, true, &y, &columns,
                            stroke,
                        )? {
                            // A period-1 orbit is a fixed point of the two-cycle map too (a
                            // transient spiralling in with a multiplier in (−1, 0) looks
                            // doubled): then the one-cycle window is recorded as usual. The
                            // one-cycle change of a doubled orbit is macroscopic; that of a
                            // period-1 orbit is the integration error (measured 4e-8 on the
                            // §2.5 Dual PARITY, 0.8 on the doubled Lift PARITY).
                            let half = transient.advance(device, 0.0, &found.state, period)?;
                            let apart = PERIOD_DOUBLED_SEPARATION * options.steady_tol;
                            if state_change(&half, &found.state) < apart {
                                // A period-1 orbit: Newton on the one-cycle map from it gives
                                // its one-cycle monodromy (the multipliers, and the start a
                                // sweep chain continues from; without it the §2.5 Lift chains
                                // ran every point cold, docs/findings.md §22).
                                t += found.t;
                                cycles_run += found.cycles_run;
                                match shooting_steady_state(
                                    device,
                                    options,
                                    &recording,
                                    &transient,
                                    period,
                                    1,
                                    true,
                                    &found.state,
                                    &columns,
                                    stroke,
                                )? {
                                    Shot::Found(one) => take_found!(one, 1),
                                    _ => {
                                        (y, residual, converged) =
                                            (found.state, found.residual, true);
                                    }
                                }
                                break;
                            }
                            take_found!(found, 2);
                            break;
                        }
                        // Near a flip (a multiplier μ ≈ −1) the two-cycle map is
                        // ill-conditioned (μ² − 1 ≈ 0) where the one-cycle map is not, and the
                        // transient's one-cycle change decays as slowly as |μ|ⁿ: Newton on the
                        // one-cycle map from here, if the retry is still open (measured on a
                        // §2.5 Lift point, μ ≈ −0.98: converged instead of 200 cycles and a
                        // one-cycle change of 2.7e-3, docs/findings.md §23).
                        if retry_open(&retry, &y) {
                            retry = None;
                            if let Shot::Found(found) = shooting_steady_state(
                                device, options, &recording, &transient, period, 1, true, &y,
                                &columns, stroke,
                            )? {
                                take_found!(found, 1);
                                break;
                            }
                        }
                    }
                }
            }
            let window_cycles = orbit_cycles * options.record_cycles;
            (
                period * window_cycles as f64,
                options.samples_per_cycle * window_cycles,
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
    let (trajectory, metrics) = match recorded {
        Some(done) => done,
        None => {
            let (trajectory, metrics, _) = record_window(
                device,
                &recording,
                t,
                &y,
                window,
                n_samples,
                period,
                options.perturbation,
                columns,
                stroke,
                None,
                options.weight_mn,
            )?;
            (trajectory, metrics)
        }
    };
    Ok(SimulationResult {
        trajectory,
        metrics,
        cycles_run,
        converged,
        period_ms: period.unwrap_or(f64::NAN),
        residual,
        steady_state: y,
        multipliers,
        monodromy,
        step_grid,
        orbit_cycles,
        orbit_samples,
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

/// Whether the transient's one retry of the one-cycle shooting is still open at `y`: the first
/// shooting failed (`Some(None)`) or found an unstable orbit (`Some(Some(state))`) that `y` is
/// not on (farther than [`SHOOTING_RETRY_APART`]).
fn retry_open(retry: &Option<Option<State>>, y: &State) -> bool {
    retry.as_ref().is_some_and(|r| {
        r.as_ref()
            .is_none_or(|r| state_change(y, r) > SHOOTING_RETRY_APART)
    })
}
