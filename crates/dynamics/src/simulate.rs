//! Running a device: periodic steady state, perturbations, streamed metrics and (when asked)
//! trajectory columns.

use paritysim_constraints::Vec6;
use paritysim_error::{Error, Result, bail, check_positive};

use crate::device::Device;
use crate::grid_shooting::{Finished, Guess};
use crate::integrate::budget::{Budget, CancelFlag};
use crate::integrate::{Integrator, Method, RungeKutta, State};
use crate::metrics::{MetricsAccumulator, StrokeNeeds};
use crate::trajectory::{PlaneSample, Recorder, Sample, StrokeSample, select_columns};
pub use crate::trajectory::{Trajectory, record};

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

/// How the periodic steady state is reached.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SteadyState {
    /// Cycle-to-cycle simulation until the change per cycle is below `steady_tol` (also the
    /// automatic fallback of [`SteadyState::Shooting`]).
    Transient,
    /// Newton shooting on the stroboscopic map retraced on a frozen step grid
    /// (`grid_shooting`): warm-up of up to `min_cycles` (none with
    /// [`SimulationOptions::shooting_jacobian`]), one adaptive period at `rtol / 100` that picks
    /// the grid (with the variational equations when no Jacobian is given), Newton steps with
    /// Broyden updates; the last Newton period is the recorded window. Converged when the
    /// predicted state error and the residual are `≤ min(steady_tol / 100, rtol / 10)` (or the
    /// residual `≤ steady_tol` along a neutral direction). Falls back to
    /// [`SteadyState::Transient`] when Newton fails. The residual and the Floquet multipliers
    /// (of the final Jacobian estimate) come with the result. The default: it meets
    /// issue 12's accuracy goals (torques 1e-7 relative, percentages 1e-5 points of the
    /// periodic orbit) at default tolerances, where the transient's `steady_tol` stop leaves a
    /// slow mode (multiplier 0.98) ~5e-6 off the orbit.
    #[default]
    Shooting,
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
    /// Trajectory columns to build (`None`: all of them; `Some(vec![])`: none, metrics only).
    pub columns: Option<Vec<String>>,
    /// Metrics the caller reads (`None`: all). When no column is built and the device
    /// integrates drivetrain coordinates, the samples are [`crate::trajectory::StrokeSample`]s
    /// (stroke-plane devices: [`crate::trajectory::PlaneSample`]s) computing only what these
    /// need ([`crate::metrics::StrokeNeeds`]) and the metrics they do not provide come back
    /// NaN.
    pub metrics: Option<Vec<String>>,
    /// How the periodic steady state is found (driven devices).
    pub steady_state: SteadyState,
    /// A guess of the stroboscopic map's Jacobian at `initial` (`2n × 2n`, e.g. a converged
    /// neighbour's [`SimulationResult::monodromy`] in a sweep chain): shooting then skips the
    /// warm-up and the variational period. Ignored by the transient.
    pub shooting_jacobian: Option<nalgebra::DMatrix<f64>>,
    /// With [`Self::shooting_jacobian`]: a neighbour's step grid over one period
    /// ([`SimulationResult::step_grid`]), reused while its steps meet the tolerances.
    pub shooting_grid: Option<Vec<f64>>,
    /// Wall-clock budget of one run (ms; None: unlimited), checked inside integration: past
    /// it the run fails with an [`Error::Integration`] naming `options.max_wall_ms`.
    pub max_wall_ms: Option<f64>,
    /// Stops the run at the next budget check with [`Error::Cancelled`] once set (not part of
    /// the spec: a sweep's or a caller's flag).
    pub cancel: Option<CancelFlag>,
}

/// Default wall-clock budget of one run (ms): a minute.
pub const DEFAULT_MAX_WALL_MS: f64 = 60_000.0;

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
            columns: None,
            metrics: None,
            steady_state: SteadyState::Shooting,
            shooting_jacobian: None,
            shooting_grid: None,
            max_wall_ms: Some(DEFAULT_MAX_WALL_MS),
            cancel: None,
        }
    }
}

/// The outcome of [`simulate`].
#[derive(Clone, Debug, PartialEq)]
pub struct SimulationResult {
    /// The recorded window (only the columns of [`SimulationOptions::columns`]; no samples
    /// when none is asked for).
    pub trajectory: Trajectory,
    /// Metrics over the recorded window (see [`crate::metrics`]).
    pub metrics: Vec<(String, f64)>,
    /// Cycles simulated before recording.
    pub cycles_run: usize,
    /// Whether the steady-state tolerance was met.
    pub converged: bool,
    /// Drive period (ms), NaN without an actuator.
    pub period_ms: f64,
    /// Relative change of the state over the last cycle before recording
    /// (`‖P(y) − y‖∞ / max(‖y‖∞, 1e-12)` for transient runs, the shooting residual
    /// `‖P(y) − y‖∞ / (1 + ‖y‖∞)` for Newton); NaN without a drive.
    pub residual: f64,
    /// The state at the start of the recorded window (on the periodic orbit when converged).
    pub steady_state: State,
    /// Floquet multipliers, largest modulus first, of the Jacobian the shooting used (evaluated
    /// within the warm-up tolerance of the orbit: accurate to about that; the stroke-plane
    /// devices with switching functions, the §3.4 blade elements, take it at the accepted
    /// orbit on the coarser first grid: measured 4.9e-9 off; use [`crate::stability::floquet`]
    /// for multipliers at the orbit itself). Newton shooting only; empty otherwise.
    pub multipliers: Vec<nalgebra::Complex<f64>>,
    /// The Jacobian of the stroboscopic map the shooting ended with (exact or
    /// Broyden-updated; `None` for transient runs): the multipliers are its eigenvalues.
    pub monodromy: Option<nalgebra::DMatrix<f64>>,
    /// The shooting's step grid over one period of the orbit (empty for transient runs).
    pub step_grid: Vec<f64>,
    /// Drive periods per period of the steady state: 1, or 2 for a period-doubled orbit (the
    /// state repeats every second cycle: the period-1 orbit has lost stability through a flip,
    /// a multiplier below −1). The recorded window, its samples and metrics then span
    /// `orbit_cycles × record_cycles` drive periods, the residual is that of the two-cycle map,
    /// and the multipliers and `monodromy` are of the two-cycle map.
    pub orbit_cycles: usize,
}

/// A transient whose state changes by less than this over two cycles (relative, as the
/// residual) but not over one has settled near a period-doubled orbit: shooting on the
/// two-cycle map takes it from there (the warm-up's threshold).
pub const PERIOD_DOUBLED_SETTLED: f64 = 1e-3;

/// A transient whose two-cycle change is below `steady_tol` has settled on a period-doubled
/// orbit when its one-cycle change is more than this many times larger (else it is a period-1
/// orbit approached with a multiplier within 1e-3 of −1).
pub const PERIOD_DOUBLED_SEPARATION: f64 = 1e3;

/// A transient fallback after shooting found an unstable orbit shoots once more when it has
/// settled (one-cycle change below [`PERIOD_DOUBLED_SETTLED`]) farther than this (relative, as
/// the residual) from that orbit: near another, stable orbit, which Newton then finishes
/// (measured on the §2.5 Dual PARITY: unstable orbit μ = 1.99 from the warm-up, the transient's
/// orbit μ = 0.855, 0.9 apart). A transient that settles on the rejected orbit itself (held
/// there by symmetry, docs/findings.md §10) is left alone.
pub const SHOOTING_RETRY_APART: f64 = 1e-2;

pub(crate) fn validate(options: &SimulationOptions) -> Result<()> {
    check_positive("steady_tol", options.steady_tol)?;
    if let Some(ms) = options.max_wall_ms {
        check_positive("max_wall_ms", ms)?;
    }
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

/// Most samples one run records (`samples_per_cycle × record_cycles`).
pub const MAX_RECORDED_SAMPLES: usize = 10_000_000;

/// Most memory (bytes) the recorded columns of one run may take.
pub const MAX_RECORDING_BYTES: usize = 1 << 30;

/// The work limit of the recording: samples and the memory of the asked columns, checked
/// before anything runs.
fn check_recording_size(options: &SimulationOptions, n_columns: usize) -> Result<()> {
    // The field to blame: the per-cycle count when it alone is too much, else the cycles.
    let field = if options.samples_per_cycle > MAX_RECORDED_SAMPLES {
        "samples_per_cycle"
    } else {
        "record_cycles"
    };
    let (spc, cycles) = (options.samples_per_cycle, options.record_cycles);
    let samples = spc
        .checked_mul(cycles)
        .filter(|&n| n <= MAX_RECORDED_SAMPLES);
    let Some(samples) = samples else {
        bail!(invalid field, options_value(field, spc, cycles),
            format!("samples_per_cycle × record_cycles ≤ {MAX_RECORDED_SAMPLES} recorded samples per run"));
    };
    // Time plus every asked column, one f64 per sample each.
    let bytes = (samples + 1)
        .saturating_mul(n_columns + 1)
        .saturating_mul(8);
    if bytes > MAX_RECORDING_BYTES {
        bail!(invalid field, format!("{} ({n_columns} columns: {} MiB)", options_value(field, spc, cycles), bytes >> 20),
            format!("at most {} MiB of recorded columns per run (ask fewer columns, samples or cycles)",
                MAX_RECORDING_BYTES >> 20));
    }
    Ok(())
}

fn options_value(field: &str, samples_per_cycle: usize, record_cycles: usize) -> String {
    match field {
        "samples_per_cycle" => format!("{samples_per_cycle} (× record_cycles = {record_cycles})"),
        _ => format!("{record_cycles} (× samples_per_cycle = {samples_per_cycle})"),
    }
}

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
                        transient_needed = false;
                    }
                    Shot::Unstable(state) => retry = Some(Some(state)),
                    Shot::Failed => retry = Some(None),
                }
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
                    if residual < PERIOD_DOUBLED_SETTLED
                        && residual <= residual_two
                        && retry.as_ref().is_some_and(|r| {
                            r.as_ref()
                                .is_none_or(|r| state_change(&y, r) > SHOOTING_RETRY_APART)
                        })
                    {
                        // Settled, and not on the unstable orbit the shooting found from the
                        // warm-up (the §2.5 Dual PARITY has one next to its stable orbit):
                        // Newton once more, from here.
                        retry = None;
                        if let Shot::Found(found) = shooting_steady_state(
                            device, options, &recording, &transient, period, 1, true, &y, &columns,
                            stroke,
                        )? {
                            (y, residual, converged) = (found.state, found.residual, true);
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
                                (y, residual, converged) = (found.state, found.residual, true);
                                t += found.t;
                                cycles_run += found.cycles_run;
                                break;
                            }
                            (y, residual, converged, orbit_cycles) =
                                (found.state, found.residual, true, 2);
                            recorded = found.recorded;
                            if let Some((trajectory, _)) = &mut recorded {
                                // Labelled after the transient's cycles too.
                                for time in &mut trajectory.time {
                                    *time += t;
                                }
                            }
                            t += found.t;
                            cycles_run += found.cycles_run;
                            multipliers = found.multipliers;
                            monodromy = Some(found.jacobian);
                            step_grid = found.grid;
                            break;
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
    })
}

/// Shooting results whose largest Floquet multiplier exceeds `1 + UNSTABLE_MARGIN` are
/// unstable orbits, which a run never settles on: [`SteadyState::Shooting`] then falls back to
/// the transient (the margin covers the error of the Broyden-updated Jacobian; K2 = 0's neutral
/// multiplier 1 stays a steady state).
pub const UNSTABLE_MARGIN: f64 = 1e-2;

/// The tolerances of the switched devices' warm-up and first grid, relative to the run's
/// (see [`shooting_steady_state`]): the start of Newton's iteration, whose accuracy the
/// second grid's Newton does not inherit.
const STEPPING_STONE_LOOSENING: f64 = 1e4;

/// What [`shooting_steady_state`] ended with.
enum Shot {
    /// A stable orbit.
    Found(Box<ShotSteadyState>),
    /// An orbit with a multiplier beyond `1 + UNSTABLE_MARGIN`: its state.
    Unstable(State),
    /// Newton did not converge.
    Failed,
}

/// What [`shooting_steady_state`] found.
struct ShotSteadyState {
    state: State,
    /// Start of the recorded window.
    t: f64,
    cycles_run: usize,
    residual: f64,
    jacobian: nalgebra::DMatrix<f64>,
    grid: Vec<f64>,
    multipliers: Vec<nalgebra::Complex<f64>>,
    /// The recorded window, when the last Newton period recorded it.
    recorded: Option<(Trajectory, Vec<(String, f64)>)>,
}

/// [`SteadyState::Shooting`]: warm-up (without a neighbour's Jacobian), then Newton on the
/// frozen grid ([`crate::grid_shooting`]) of the `orbit_cycles`-period map (2: a
/// period-doubled orbit), with a warm-up first unless `settled` (a state the caller's
/// transient settled); the final Newton period records the window when it is one plain orbit.
/// Not [`Shot::Found`]: the caller runs the transient.
#[allow(clippy::too_many_arguments)]
fn shooting_steady_state(
    device: &Device,
    options: &SimulationOptions,
    recording: &RungeKutta,
    transient: &RungeKutta,
    period: f64,
    orbit_cycles: usize,
    settled: bool,
    y0: &State,
    columns: &[crate::trajectory::Column],
    stroke: Option<StrokeNeeds>,
) -> Result<Shot> {
    let mut y = *y0;
    let mut cycles = 0;
    let guess = options.shooting_jacobian.as_ref();
    let map_period = period * orbit_cycles as f64;
    let switched = crate::integrate::OdeSystem::n_switches(device) > 0;
    // The stepping stones need a cheap exact Jacobian at the first orbit (the stroke-plane
    // model's analytic one). The free-θ devices' comes from central differences (two
    // right-hand sides per column and stage): their first pass runs at the run's tolerances and hands
    // its Jacobian to the second (measured on the §2.5 Dual PARITY with stepping stones: the
    // orbit returned within 1.05e-9 instead of 8.8e-11).
    let stepping_stone = switched && device.has_analytic_jacobian();
    if guess.is_none() && !settled {
        // Far from the orbit Newton's model is poor: settle the fast modes first. Only the
        // start of Newton's iteration: for the stepping-stone devices, whose multipliers are
        // taken at the accepted orbit (below), at looser tolerances (the others' warm-up state
        // is where their Jacobian is taken, and the lanes repeat it).
        // The loose warm-up does not locate the blade elements' switches: at its long steps
        // each root's cut step and search cost more than the rejected steps they save
        // (measured on the §3.4 device: 3.9 M → 2.2 M instructions for its three cycles).
        let (warm_up, warm_up_system): (_, &dyn crate::integrate::OdeSystem) = if stepping_stone {
            (
                transient.loosened(STEPPING_STONE_LOOSENING),
                &crate::integrate::WithoutEvents(device),
            )
        } else {
            (*transient, device)
        };
        while cycles < options.min_cycles {
            crate::integrate::budget::check(cycles as f64 * period)?;
            let next = match warm_up.advance(warm_up_system, 0.0, &y, period) {
                Ok(next) => next,
                // A spent budget ends the run; any other failure is left to the fallback.
                Err(e) if crate::grid_shooting::out_of_budget(&e) => return Err(e),
                Err(_) => break,
            };
            let change = state_change(&next, &y);
            y = next.without_work();
            cycles += 1;
            if change < 1e-3 {
                break;
            }
        }
    }
    // Below the integration's own accuracy (~rtol) a tighter orbit changes nothing.
    let tol = (1e-2 * options.steady_tol).min(0.1 * options.rtol);
    let n_samples = options.samples_per_cycle * orbit_cycles;
    let records = options.record_cycles == 1 && options.perturbation.is_none();
    let mut recorded = None;
    let mut finish = |grid: &[f64], y: &State| -> Result<Finished> {
        if !records {
            return transient
                .integrate_on_grid(device, grid, y, &[], &mut |_, _, _| Ok(()))
                .map(|end| (end, None));
        }
        // Samples that read no work integral: the lighter state suffices.
        let integrator = match stroke {
            Some(needs) if !needs.work => transient,
            _ => recording,
        };
        let (trajectory, metrics, end) = record_window(
            device,
            integrator,
            grid[0],
            y,
            map_period,
            n_samples,
            Some(period),
            None,
            columns.to_vec(),
            stroke,
            Some(grid),
        )?;
        recorded = Some((trajectory, metrics));
        Ok((end, None))
    };
    // A right-hand side with switches (event location): the adaptive period cuts the grid at
    // the roots of its start state, which move by the distance to the orbit, and the steps
    // next to them then integrate a continued branch (measured on the §3.4 device: the true
    // map's residual 3e-7 at the frozen grid's orbit). So a first orbit on that grid, then
    // the grid picked again from it (its roots within Newton's last correction); a
    // neighbour's grid is not reused. Lanes never run such devices (no lane model). (One pass
    // on the first grid, whose steps are cut at the trial's own roots, left the §3.4 orbit
    // 1.3e-9 off the true map's; 2.4e-12 with two.)
    // The first grid is a stepping stone: picked and solved at 1e4 × the run's tolerances
    // (its orbit only places the second grid's roots) to a tenth of `steady_tol`, its last
    // Newton trial not integrated (the second grid's Newton starts from that state and checks
    // it). Its Jacobian (taken at the warm-up state, Broyden-updated) and the contraction it
    // achieved start the second grid's Newton, whose first step is then usually the recorded
    // period itself; the multipliers come from the variational equations at the accepted
    // orbit on the first grid (measured on the §3.4 device: 4.9e-9 off an rtol-1e-12
    // reference, where one variational period at the start of the second grid cost 3 × as
    // much; with the loose warm-up below, 25.8 M → 19.8 M instructions per trial).
    let mut first_pass = None;
    let first_rk = if stepping_stone {
        transient.loosened(STEPPING_STONE_LOOSENING)
    } else {
        *transient
    };
    if switched && guess.is_none() {
        let mut plain = |_: &[f64], y: &State| -> Result<Finished> { Ok((*y, None)) };
        // A stepping stone's orbit is only the second grid's start, which that grid's Newton
        // corrects: a tenth of `steady_tol` (its first Newton step from the warm-up suffices).
        let first_tol = if stepping_stone {
            tol.max(0.1 * options.steady_tol)
        } else {
            tol
        };
        if let Some(first) = crate::grid_shooting::shoot(
            device,
            &first_rk,
            map_period,
            0.0,
            &y,
            None,
            first_tol,
            options.steady_tol,
            20,
            &mut plain,
        )? {
            y = first.state;
            cycles += first.periods * orbit_cycles;
            first_pass = Some(first);
        }
    }
    let guess = match &first_pass {
        Some(first) => Some(Guess {
            jacobian: &first.jacobian,
            grid: None,
            // The stepping stone's contraction predicts the second grid's first error: its
            // first Newton step is the final period when that is below `tol`.
            contraction: first.contraction.filter(|_| stepping_stone),
        }),
        None => guess.map(|jacobian| Guess {
            jacobian,
            grid: options.shooting_grid.as_deref().filter(|_| !switched),
            contraction: None,
        }),
    };
    let Some(mut orbit) = crate::grid_shooting::shoot(
        device,
        transient,
        map_period,
        0.0,
        &y,
        guess,
        tol,
        options.steady_tol,
        20,
        &mut finish,
    )?
    else {
        return Ok(Shot::Failed);
    };
    cycles += orbit.periods * orbit_cycles;
    if let Some(first) = first_pass.filter(|_| stepping_stone && !orbit.jacobian_at_orbit) {
        // The second grid's Newton ran on the stepping stone's Broyden-updated Jacobian
        // (taken off the orbit): the multipliers from the variational equations at the
        // orbit, on the stepping stone's coarser grid (a third of the second grid's steps).
        match first_rk.flow_with_sensitivity_on_grid(device, &first.grid, &orbit.state) {
            Ok((_, jacobian)) => orbit.jacobian = jacobian,
            Err(e) if crate::grid_shooting::out_of_budget(&e) => return Err(e),
            Err(_) => {}
        }
    }
    let multipliers = crate::floquet::eigenvalues(&orbit.jacobian).unwrap_or_default();
    if multipliers
        .first()
        .is_some_and(|m| m.norm() > 1.0 + UNSTABLE_MARGIN)
    {
        // An unstable orbit is not a state a run settles on: the transient decides.
        return Ok(Shot::Unstable(orbit.state));
    }
    let t = cycles as f64 * period;
    if let Some((trajectory, _)) = &mut recorded {
        // The window was integrated on the section t = 0; the drive is T-periodic, so it is
        // the window after the cycles run, labelled as such.
        for time in &mut trajectory.time {
            *time += t;
        }
    }
    Ok(Shot::Found(Box::new(ShotSteadyState {
        state: orbit.state,
        t,
        cycles_run: cycles,
        residual: orbit.residual,
        jacobian: orbit.jacobian,
        grid: orbit.grid,
        multipliers,
        recorded,
    })))
}

/// The metrics of one drive period recorded from `state` at `t = 0` (a state on the section
/// `t ≡ 0 mod T`, e.g. a periodic orbit from continuation), with `options`' tolerances and
/// `samples_per_cycle`; no transient, no columns.
///
/// # Errors
/// [`Error::Constraint`] without a periodic drive; integration errors.
pub fn orbit_metrics(
    device: &Device,
    state: &State,
    options: &SimulationOptions,
) -> Result<Vec<(String, f64)>> {
    validate(options)?;
    let _budget = Budget::new(options.max_wall_ms, options.cancel.clone()).enter();
    let Some(period) = device.period() else {
        bail!(Constraint "orbit metrics need a periodic drive (the device has no actuator)");
    };
    let integrator = RungeKutta::new(
        options.method,
        options.rtol,
        options.atol,
        options.max_steps,
    )?;
    let stroke = stroke_sampling(device, options.metrics.as_deref(), &[]);
    let (_, metrics, _) = record_window(
        device,
        &integrator,
        0.0,
        &state.without_work(),
        period,
        options.samples_per_cycle,
        Some(period),
        None,
        Vec::new(),
        stroke,
        None,
    )?;
    Ok(metrics)
}

/// How samples are taken (see [`SimulationOptions::metrics`]): `Some(needs)` for lean
/// [`StrokeSample`]s (no column asked, drivetrain coordinates) or [`PlaneSample`]s (no column
/// asked, the stroke-plane model), else `None` (full samples).
fn stroke_sampling(
    device: &Device,
    metrics: Option<&[String]>,
    columns: &[crate::trajectory::Column],
) -> Option<StrokeNeeds> {
    let lean = columns.is_empty()
        && (device.formulation() == crate::device::Formulation::DrivetrainCoordinates
            || device.has_stroke_plane_model());
    lean.then(|| StrokeNeeds::of(metrics))
}

/// A recorded window: its columns, its metrics and the state at its end.
type Recorded = (Trajectory, Vec<(String, f64)>, State);

/// Integrates the recorded window from `(t_start, y)`, evaluating each of the `n_samples + 1`
/// samples once: it feeds the metrics and the asked columns, nothing else is kept.
#[allow(clippy::too_many_arguments)]
fn record_window(
    device: &Device,
    integrator: &RungeKutta,
    t_start: f64,
    y: &State,
    window: f64,
    n_samples: usize,
    period: Option<f64>,
    perturbation: Option<Perturbation>,
    columns: Vec<crate::trajectory::Column>,
    stroke: Option<StrokeNeeds>,
    grid: Option<&[f64]>,
) -> Result<Recorded> {
    // The last sample is exactly the window's end: t_start + window·k/n can round one ulp past
    // it.
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
    let mut metrics = MetricsAccumulator::new(device, period);
    let plane = device.formulation() != crate::device::Formulation::DrivetrainCoordinates;
    let mut recorder = Recorder::new(columns, times.len());
    let mut sink = |i: usize, t: f64, y: &State| -> Result<()> {
        // `stroke` is only set for drivetrain-coordinate and stroke-plane devices (see
        // `stroke_sampling`).
        if let Some(needs) = stroke {
            if plane {
                if let Some(sample) = PlaneSample::new(device, t, y, needs) {
                    metrics.add_plane(&sample?, i == n_samples);
                    return Ok(());
                }
                // Outside the closed form: the general sample (which reports why).
            } else {
                let sample = StrokeSample::of_stroke_device(device, t, y, needs)?;
                metrics.add_stroke(&sample, i == n_samples);
                return Ok(());
            }
        }
        let sample = Sample::new(device, t, y)?;
        metrics.add(&sample, i == n_samples);
        recorder.push(&sample)
    };
    let end = match (perturbation, grid) {
        (None, Some(grid)) => integrator.integrate_on_grid(device, grid, y, &times, &mut sink)?,
        (None, None) => integrator.integrate_with(device, t_start, y, t_end, &times, &mut sink)?,
        (Some(kick), _) => {
            let t_kick = t_start + kick.phase * period.unwrap_or(window);
            let split = times.partition_point(|&s| s < t_kick);
            let y_kick = if t_kick > t_start {
                let (before, _) = times.split_at(split);
                integrator.integrate_with(device, t_start, y, t_kick, before, &mut sink)?
            } else {
                *y
            };
            let y_kicked = apply_kick(device, t_kick, &y_kick, kick)?;
            let after = &times[split..];
            // Sample indices continue after the kick.
            let mut shifted = |i: usize, t: f64, y: &State| sink(i + split, t, y);
            integrator.integrate_with(device, t_kick, &y_kicked, t_end, after, &mut shifted)?
        }
    };
    Ok((recorder.finish(), metrics.finish(), end))
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
