//! Parameter sweeps: many independent simulations on a local rayon pool.
//!
//! A sweep is a list of points; each point is a device (plus its options) built from a base
//! design and a row of parameter values. Every point runs [`simulate`](crate::simulate()) on its
//! own and produces the selected metrics (and optionally its last recorded cycle):
//!
//! * **Order and determinism.** Results come back in input order whatever the thread count.
//!   Points with [`SteadyState::Shooting`] (the default) run in continuation chains of
//!   [`CHAIN_LENGTH`] consecutive points of one call ([`run_points`]), each started from its
//!   converged neighbours' orbit, Jacobian and step grid; other points run on their own. The
//!   chains are fixed by the input order alone and each is computed sequentially, so results
//!   are **bit-identical for any thread count and on repeated runs**. A chained point is *not*
//!   bit-identical to a direct [`simulate`](crate::simulate()) of the same device (another
//!   start, another frozen step grid), but both converge the same periodic orbit: their
//!   metrics agree to the accuracy of the orbit (Newton residual `≤ rtol / 10`, or
//!   `≤ steady_tol` along a nearly neutral direction, amplified by slow modes, plus the two
//!   grids' truncation errors): about 1e-7 of each metric's scale at the default options
//!   (measured 3e-8 to 1.2e-7). A chained start that does not converge or needs the
//!   transient fallback (Newton failed, or found an unstable orbit) is rerun from the spec's
//!   own start, and only orbits found by shooting continue a chain, so a point without a
//!   stable orbit is exactly its direct `simulate`. The same holds between two different splittings of a table into calls
//!   (chunks, resumed checkpoints).
//! * **Failures are rows.** A point whose device cannot be built (an invalid combination) or
//!   whose integration fails yields `Err(error)` in its slot; every other point is kept. A panic
//!   inside a point is caught and reported the same way (it never unwinds into the caller).
//! * **Progress and cancellation.** [`SweepControl`] holds an atomic counter of finished points
//!   (poll it from another thread) and a cancel flag: once set, no new point starts, the running
//!   ones stop at their integrator's next budget check, and their slots and the unstarted ones
//!   come back as `None`.
//! * **Threads.** [`resolve_threads`]: an explicit count, else the environment variable
//!   [`THREADS_ENV`] (`PARITYSIM_THREADS`), else all available cores. Each run builds its own
//!   pool, so the global rayon pool is never touched.
//!
//! ```
//! use paritysim_dynamics::sweep::{Grid, SweepControl, SweepSettings, sweep};
//! # use paritysim_dynamics::{Device, DeviceSpec, Formulation, Wing, WingAero, JointSpring, SimulationOptions};
//! # use paritysim_constraints::Constraints;
//! # use paritysim_kinematics::SphericalShoulder;
//! # use nalgebra::Matrix3;
//! // A free wing on a stroke spring, swept over the spring stiffness.
//! let build = |values: &[f64]| {
//!     let mut springs = [JointSpring::default(); 6];
//!     springs[0] = JointSpring::linear(values[0], 0.0)?;
//!     let wing = Wing::new(
//!         SphericalShoulder::new(std::f64::consts::FRAC_PI_2, 0.0)?,
//!         Matrix3::from_diagonal_element(10.0),
//!         springs,
//!         WingAero::None,
//!     )?;
//!     Device::new(DeviceSpec {
//!         wings: vec![wing],
//!         constraints: Constraints::none(3)?,
//!         transmission: None,
//!         actuator: None,
//!         formulation: Formulation::Auto,
//!     })
//! };
//! let grid = Grid::new().axis("stiffness", [1.0, 2.0, 4.0])?;
//! let options = SimulationOptions {
//!     duration_ms: Some(5.0),
//!     initial: Some((nalgebra::Vector6::zeros(), nalgebra::Vector6::new(0.1, 0.0, 0.0, 0.0, 0.0, 0.0))),
//!     ..Default::default()
//! };
//! let control = SweepControl::new();
//! let result = sweep(&grid.table(), build, &options, &SweepSettings::default(), &control)?;
//! assert_eq!(result.rows.len(), 3);
//! assert_eq!(control.finished(), 3);
//! # Ok::<(), paritysim_dynamics::Error>(())
//! ```

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;

use paritysim_error::{Error, Result, bail};

use crate::device::Device;
use crate::integrate::budget::{Budget, CancelFlag};
use crate::metrics;
use crate::simulate::{SimulationOptions, SimulationResult, SteadyState, Trajectory, simulate};
use crate::trajectory::column_table;
use paritysim_constraints::Vec6;

/// Environment variable read by [`resolve_threads`] when no thread count is given:
/// a positive integer (`PARITYSIM_THREADS=4`).
pub const THREADS_ENV: &str = "PARITYSIM_THREADS";

/// Largest accepted thread count (a sanity bound against typos such as `threads=10000`).
pub const MAX_THREADS: usize = 1024;

/// The thread count a sweep uses: `requested` if given, else [`THREADS_ENV`], else the number
/// of available cores.
///
/// # Errors
/// [`Error::InvalidParameter`] for `0`, more than [`MAX_THREADS`], or an environment value that
/// is not such an integer (the message names `threads` or `PARITYSIM_THREADS`).
pub fn resolve_threads(requested: Option<usize>) -> Result<usize> {
    let allowed = format!("an integer in [1, {MAX_THREADS}]");
    if let Some(n) = requested {
        if !(1..=MAX_THREADS).contains(&n) {
            bail!(invalid "threads", n, allowed);
        }
        return Ok(n);
    }
    if let Ok(raw) = std::env::var(THREADS_ENV) {
        let raw = raw.trim();
        if !raw.is_empty() {
            return match raw.parse::<usize>() {
                Ok(n) if (1..=MAX_THREADS).contains(&n) => Ok(n),
                _ => Err(Error::invalid(THREADS_ENV, format!("{raw:?}"), allowed)),
            };
        }
    }
    Ok(std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// Progress counter and cancel flag shared between a running sweep and its observers
/// (wrap it in an `Arc` to share it with another thread).
#[derive(Debug, Default)]
pub struct SweepControl {
    finished: AtomicUsize,
    cancelled: CancelFlag,
}

impl SweepControl {
    /// A fresh control: nothing finished, not cancelled.
    pub fn new() -> Self {
        Self::default()
    }

    /// Points finished so far (successfully or not).
    pub fn finished(&self) -> usize {
        self.finished.load(Ordering::Acquire)
    }

    /// Counts one finished point unless it was stopped by the cancel (then it did not finish).
    pub(crate) fn count_point<T>(&self, result: &Result<T>) {
        if !(matches!(result, Err(Error::Cancelled)) && self.is_cancelled()) {
            self.finished.fetch_add(1, Ordering::AcqRel);
        }
    }

    /// Stops scheduling new points and stops the running ones at their next budget check
    /// (they are reported as not run).
    pub fn cancel(&self) {
        self.cancelled.cancel();
    }

    /// Whether [`SweepControl::cancel`] was called.
    pub fn is_cancelled(&self) -> bool {
        self.cancelled.is_cancelled()
    }
}

/// Runs `f(0..n)` on a pool of `threads` threads; slot `i` holds `f(i)`, or `None` when the
/// point was not started because the sweep was cancelled. A panic in `f` becomes an
/// [`Error::Integration`] whose reason starts with `internal error (panic)`.
///
/// # Errors
/// [`Error::InvalidParameter`] for a bad thread count; the pool itself failing to start is
/// reported the same way (`threads`).
pub fn run_indexed<T, F>(
    n: usize,
    threads: usize,
    control: &SweepControl,
    f: F,
) -> Result<Vec<Option<Result<T>>>>
where
    T: Send,
    F: Fn(usize) -> Result<T> + Sync,
{
    run_tasks(n, threads, control, true, f)
}

/// [`run_indexed`]; `count`: whether a finished task counts as one finished point (a chain
/// of points counts its points itself).
pub(crate) fn run_tasks<T, F>(
    n: usize,
    threads: usize,
    control: &SweepControl,
    count: bool,
    f: F,
) -> Result<Vec<Option<Result<T>>>>
where
    T: Send,
    F: Fn(usize) -> Result<T> + Sync,
{
    let threads = resolve_threads(Some(threads))?;
    let one = |i: usize| -> Option<Result<T>> {
        if control.is_cancelled() {
            return None;
        }
        // The sweep's cancel flag reaches the integrator of a running point too.
        let _budget = Budget::new(None, Some(control.cancelled.clone())).enter();
        let out = catch_unwind(AssertUnwindSafe(|| f(i))).unwrap_or_else(|payload| {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| (*s).to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            Err(Error::Integration {
                time: f64::NAN,
                state: Vec::new(),
                reason: format!("internal error (panic) at sweep point {i}: {what}"),
            })
        });
        if matches!(out, Err(Error::Cancelled)) && control.is_cancelled() {
            // Stopped mid-run by the cancel: not finished (a resume recomputes it).
            return None;
        }
        if count {
            control.finished.fetch_add(1, Ordering::AcqRel);
        }
        Some(out)
    };
    if threads == 1 {
        // No pool: the calling thread does the work (and tests the sequential path).
        return Ok((0..n).map(one).collect());
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("paritysim-sweep-{i}"))
        .build()
        .map_err(|e| {
            Error::invalid(
                "threads",
                threads,
                format!("a count the OS can start ({e})"),
            )
        })?;
    // One point per task: points take milliseconds, so scheduling overhead is negligible and
    // fine-grained stealing keeps both ends of the run busy.
    Ok(pool.install(|| (0..n).into_par_iter().with_max_len(1).map(one).collect()))
}

/// The metric names [`simulate`](crate::simulate()) reports for this device, in order.
pub fn metric_names(device: &Device) -> Vec<String> {
    metrics::names(device)
}

/// The trajectory column names [`simulate`](crate::simulate()) records for this device
/// (without `time_ms`), in order.
pub fn trajectory_columns(device: &Device) -> Vec<String> {
    column_table(device).into_iter().map(|c| c.name).collect()
}

/// Checks requested names against the allowed ones; `None` selects them all.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `field` and listing the valid names.
pub fn select(field: &str, requested: Option<&[String]>, valid: &[String]) -> Result<Vec<String>> {
    let Some(requested) = requested else {
        return Ok(valid.to_vec());
    };
    for name in requested {
        if !valid.contains(name) {
            return Err(Error::invalid(
                field.to_string(),
                format!("{name:?}"),
                format!("one of: {}", valid.join(", ")),
            ));
        }
    }
    Ok(requested.to_vec())
}

/// What each point reports.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct SweepSettings {
    /// Threads (`None`: [`resolve_threads`]).
    pub threads: Option<usize>,
    /// Metric names to keep, in this order (`None`: all of [`metric_names`]).
    pub metrics: Option<Vec<String>>,
    /// Keep the last recorded cycle of each point (Δτ and the imbalance percentages are metrics
    /// now; this is only for the waveforms themselves).
    pub keep_cycle: bool,
}

/// The outcome of one successful point.
#[derive(Clone, Debug, PartialEq)]
pub struct PointOutput {
    /// Selected metric values, aligned with the requested names (NaN if a name is missing).
    pub metrics: Vec<f64>,
    /// Whether the steady-state tolerance was met.
    pub converged: bool,
    /// Cycles simulated before recording.
    pub cycles_run: usize,
    /// The last recorded cycle (its closing sample included), when asked for.
    pub cycle: Option<Trajectory>,
    /// Relative change over the last cycle, or the shooting residual
    /// ([`crate::SimulationResult::residual`]).
    pub residual: f64,
    /// `(p, ṗ)` at the start of the recorded window: the next point's initial guess in a
    /// continuation chain.
    pub steady_state: Option<(Vec6, Vec6)>,
    /// The shooting's Jacobian of the stroboscopic map (the next point's Newton guess).
    pub monodromy: Option<nalgebra::DMatrix<f64>>,
    /// The shooting's step grid (the next point's, while it meets the tolerances).
    pub step_grid: Vec<f64>,
    /// Drive periods per period of the steady state ([`crate::SimulationResult::orbit_cycles`]).
    pub orbit_cycles: usize,
}

/// Simulates one point and keeps what the sweep asked for.
///
/// # Errors
/// Whatever [`simulate`](crate::simulate()) returns.
pub fn run_point(
    device: &Device,
    options: &SimulationOptions,
    metric_names: &[String],
    keep_cycle: bool,
) -> Result<PointOutput> {
    let result = if keep_cycle {
        simulate(device, options)?
    } else {
        // Metrics only: no trajectory column is built, only the asked metrics are computed.
        let options = SimulationOptions {
            columns: Some(Vec::new()),
            metrics: Some(metric_names.to_vec()),
            ..options.clone()
        };
        simulate(device, &options)?
    };
    let steady_state = device.coordinates(&result.steady_state).ok();
    Ok(PointOutput::keep(
        result,
        metric_names,
        keep_cycle,
        options.samples_per_cycle,
        steady_state,
    ))
}

impl PointOutput {
    /// What a sweep keeps of one run: the asked metrics in order (NaN where absent) and, with
    /// `keep_cycle`, the last recorded orbit (`orbit_cycles × samples_per_cycle + 1` samples;
    /// the whole trajectory of an aperiodic run).
    pub fn keep(
        result: SimulationResult,
        metric_names: &[String],
        keep_cycle: bool,
        samples_per_cycle: usize,
        steady_state: Option<(Vec6, Vec6)>,
    ) -> Self {
        let metrics = metric_names
            .iter()
            .map(|name| {
                result
                    .metrics
                    .iter()
                    .find(|(n, _)| n == name)
                    .map_or(f64::NAN, |(_, v)| *v)
            })
            .collect();
        let cycle = keep_cycle.then(|| {
            let traj = result.trajectory;
            let len = traj.time.len();
            let keep = if result.period_ms.is_finite() {
                (result.orbit_cycles * samples_per_cycle + 1).min(len)
            } else {
                len
            };
            let start = len - keep;
            Trajectory {
                time: traj.time[start..].to_vec(),
                columns: traj
                    .columns
                    .into_iter()
                    .map(|(name, v)| (name, v[start..].to_vec()))
                    .collect(),
            }
        });
        Self {
            metrics,
            converged: result.converged,
            cycles_run: result.cycles_run,
            cycle,
            residual: result.residual,
            steady_state,
            monodromy: result.monodromy,
            step_grid: result.step_grid,
            orbit_cycles: result.orbit_cycles,
        }
    }
}

/// A converged point of a continuation chain: its index, `(p, ṗ)`, shooting Jacobian and step
/// grid.
pub(crate) type Converged = (
    usize,
    (Vec6, Vec6),
    Option<nalgebra::DMatrix<f64>>,
    Vec<f64>,
);

/// The start of point `i` of a chain from its converged predecessors: the secant (linear)
/// extrapolation `2 y₁ − y₀` of state and Jacobian when the two previous points converged
/// (neighbours along a grid axis: the first Newton residual falls by the parameter step
/// once more), else the last converged state and Jacobian.
fn predict(
    previous: &[Converged],
    i: usize,
) -> (Option<(Vec6, Vec6)>, Option<nalgebra::DMatrix<f64>>) {
    match previous {
        [.., (i0, s0, j0, _), (i1, s1, j1, _)] if *i1 + 1 == i && *i0 + 2 == i => {
            let state = (2.0 * s1.0 - s0.0, 2.0 * s1.1 - s0.1);
            let jacobian = match (j0, j1) {
                (Some(a), Some(b)) if a.shape() == b.shape() => Some(2.0 * b - a),
                _ => j1.clone(),
            };
            (Some(state), jacobian)
        }
        [.., (_, s1, j1, _)] => (Some(*s1), j1.clone()),
        [] => (None, None),
    }
}

/// Points per continuation chain (see [`run_points`]); fixed, so results do not depend on the
/// thread count.
pub const CHAIN_LENGTH: usize = 16;

/// Runs prepared points: slot `i` is `(device, options)` or the error that prevented building
/// it (kept as that point's result). `metric_names` are those to report (see [`select`]).
///
/// Points whose options ask for [`SteadyState::Shooting`] without an initial state run in
/// continuation chains: consecutive points in groups of [`CHAIN_LENGTH`] (neighbours along the
/// last grid axis), each started from the steady state of the previous converged point of its
/// chain. Chains are fixed by the input order alone, so results are the same for any thread
/// count.
///
/// # Errors
/// [`Error::InvalidParameter`] for a bad thread count only; point failures are per-slot.
pub fn run_points(
    points: &[Result<(Device, SimulationOptions)>],
    metric_names: &[String],
    keep_cycle: bool,
    threads: Option<usize>,
    control: &SweepControl,
) -> Result<Vec<Option<Result<PointOutput>>>> {
    run_points_with_lanes(points, metric_names, keep_cycle, threads, None, control)
}

/// [`run_points`] with an explicit SIMD lane width (`None`: [`crate::lanes::resolve_lanes`]).
/// With more than one lane, continued shooting points of qualifying devices
/// ([`crate::lanes`]) run their fixed-grid periods several at once in SIMD lanes; the results
/// are bit-identical to one lane (the scalar path) and, as there, for any thread count.
///
/// # Errors
/// [`Error::InvalidParameter`] for a bad thread count or lane width; point failures are
/// per-slot.
pub fn run_points_with_lanes(
    points: &[Result<(Device, SimulationOptions)>],
    metric_names: &[String],
    keep_cycle: bool,
    threads: Option<usize>,
    lanes: Option<usize>,
    control: &SweepControl,
) -> Result<Vec<Option<Result<PointOutput>>>> {
    let threads = resolve_threads(threads)?;
    if !(0..points.len()).any(|i| continued(points, i)) {
        return run_indexed(points.len(), threads, control, |i| match &points[i] {
            Ok((device, options)) => run_point(device, options, metric_names, keep_cycle),
            Err(e) => Err(e.clone()),
        });
    }
    let n_chains = points.len().div_ceil(CHAIN_LENGTH);
    let lanes = crate::lanes::resolve_lanes(lanes)?;
    // Lane groups only when some device has a lane model: otherwise one task per chain
    // balances the pool better.
    let lane_devices = points
        .iter()
        .any(|p| matches!(p, Ok((d, _)) if crate::lanes::has_lane_model(d)));
    let chains: Vec<Option<Result<Vec<Result<PointOutput>>>>> =
        if lanes > 1 && !keep_cycle && lane_devices {
            crate::lanes::run_chains(points, metric_names, n_chains, threads, lanes, control)?
        } else {
            run_tasks(n_chains, threads, control, false, |c| {
                let mut previous: Vec<Converged> = Vec::with_capacity(2);
                let mut out = Vec::with_capacity(CHAIN_LENGTH);
                for i in chain_range(c, points.len()) {
                    // Cancelled mid-chain: the rest of the chain does not start (reported as not run).
                    if control.is_cancelled() {
                        break;
                    }
                    let start = chain_start(points, &mut previous, i);
                    let result = chain_point(points, i, &start, metric_names, keep_cycle, None);
                    remember(&mut previous, i, &result);
                    control.count_point(&result);
                    out.push(result);
                }
                Ok(out)
            })?
        };
    let mut slots = Vec::with_capacity(points.len());
    for (c, chain) in chains.into_iter().enumerate() {
        let len = ((c + 1) * CHAIN_LENGTH).min(points.len()) - c * CHAIN_LENGTH;
        match chain {
            Some(Ok(results)) => {
                let ran = results.len();
                slots.extend(results.into_iter().map(|r| match r {
                    // Points of the chain stopped by the cancel did not run.
                    Err(Error::Cancelled) if control.is_cancelled() => None,
                    other => Some(other),
                }));
                // The points after a mid-chain cancel never started.
                slots.extend((ran..len).map(|_| None));
            }
            Some(Err(e)) => slots.extend((0..len).map(|_| Some(Err(e.clone())))),
            None => slots.extend((0..len).map(|_| None)),
        }
    }
    Ok(slots)
}

/// The points of chain `c` (consecutive, [`CHAIN_LENGTH`] of them).
pub(crate) fn chain_range(c: usize, n_points: usize) -> std::ops::Range<usize> {
    c * CHAIN_LENGTH..((c + 1) * CHAIN_LENGTH).min(n_points)
}

/// Whether point `i` continues its chain (shooting, no initial state of its own).
pub(crate) fn continued(points: &[Result<(Device, SimulationOptions)>], i: usize) -> bool {
    matches!(&points[i], Ok((_, o)) if o.steady_state == SteadyState::Shooting && o.initial.is_none())
}

/// Where point `i` of a chain starts: the prediction from its converged predecessors
/// ([`predict`]) and the last one's step grid.
pub(crate) struct ChainStart {
    /// `(p, ṗ)` guess.
    pub(crate) guess: Option<(Vec6, Vec6)>,
    /// Jacobian guess of the stroboscopic map.
    pub(crate) jacobian: Option<nalgebra::DMatrix<f64>>,
    /// The predecessor's step grid.
    pub(crate) grid: Option<Vec<f64>>,
}

/// [`ChainStart`] of point `i`; drops predecessors driven at another period first.
pub(crate) fn chain_start(
    points: &[Result<(Device, SimulationOptions)>],
    previous: &mut Vec<Converged>,
    i: usize,
) -> ChainStart {
    // Only neighbours driven at the same period continue into this point: across a
    // frequency step their state and Jacobian are no model of this point's map
    // (measured: Newton from them accepted a state 4e-7 off the orbit).
    let period = |k: usize| points[k].as_ref().ok().and_then(|(d, _)| d.period());
    if previous.last().is_some_and(|c| period(c.0) != period(i)) {
        previous.clear();
    }
    if previous.len() == 2 && period(previous[0].0) != period(i) {
        previous.remove(0);
    }
    let (guess, jacobian) = predict(previous, i);
    let grid = previous
        .last()
        .map(|c| c.3.clone())
        .filter(|g| !g.is_empty());
    ChainStart {
        guess,
        jacobian,
        grid,
    }
}

/// The options of a continued point started at `start` (`None` when it starts on its own).
pub(crate) fn continued_options(
    points: &[Result<(Device, SimulationOptions)>],
    i: usize,
    start: &ChainStart,
) -> Option<SimulationOptions> {
    let (_, options) = points[i].as_ref().ok()?;
    match start.guess {
        Some(initial) if continued(points, i) => Some(SimulationOptions {
            initial: Some(initial),
            shooting_jacobian: start.jacobian.clone(),
            shooting_grid: start.grid.clone(),
            ..options.clone()
        }),
        _ => None,
    }
}

/// Runs point `i` of a chain from `start`; `started` is its run from the continued options
/// when it was already computed (the SIMD-lane path), else it is run here.
pub(crate) fn chain_point(
    points: &[Result<(Device, SimulationOptions)>],
    i: usize,
    start: &ChainStart,
    metric_names: &[String],
    keep_cycle: bool,
    started: Option<Result<PointOutput>>,
) -> Result<PointOutput> {
    let (device, options) = match &points[i] {
        Ok(p) => p,
        Err(e) => return Err(e.clone()),
    };
    let started = match started {
        Some(s) => s,
        None => match continued_options(points, i, start) {
            Some(options) => run_point(device, &options, metric_names, keep_cycle),
            None => run_point(device, options, metric_names, keep_cycle),
        },
    };
    // A continuation start that fails, does not converge or needs the transient fallback
    // (no stable orbit near the neighbour's) is retried from the spec's own start: the point
    // then is exactly a direct `simulate`. Why the fallback too: on an unstable orbit the
    // transient from a neighbour's state amplifies its round-off (measured on
    // examples/drag_parity.toml, whippletree multiplier 1.43-2.0: the antisymmetric part grew
    // 20-40× per chained point, up to an imbalance of 1.2e-5 %), where a symmetric cold start
    // stays exactly symmetric.
    match started {
        Err(Error::Cancelled) => Err(Error::Cancelled),
        Err(_) if start.guess.is_some() => run_point(device, options, metric_names, keep_cycle),
        Ok(o)
            if start.guess.is_some()
                && continued(points, i)
                && !(o.converged && o.monodromy.is_some() && o.orbit_cycles == 1) =>
        {
            run_point(device, options, metric_names, keep_cycle)
        }
        other => other,
    }
}

/// Keeps a converged result of point `i` as a predecessor (the last two). Only an orbit
/// found by shooting (a stable one, with its monodromy) continues into the next point.
pub(crate) fn remember(previous: &mut Vec<Converged>, i: usize, result: &Result<PointOutput>) {
    if let Ok(o) = result {
        // A period-doubled orbit's map (two cycles) is no guess for a neighbour's one-cycle map.
        let continues = o.monodromy.is_some() && o.orbit_cycles == 1;
        if let (true, Some(state), true) = (o.converged, o.steady_state, continues) {
            if previous.len() == 2 {
                previous.remove(0);
            }
            previous.push((i, state, o.monodromy.clone(), o.step_grid.clone()));
        }
    }
}

/// A table of parameter values: named columns, one row per point.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct ParameterTable {
    /// Column names (e.g. `drivetrain.balance_stiffness`).
    pub names: Vec<String>,
    /// Rows, each as long as `names`.
    pub rows: Vec<Vec<f64>>,
}

impl ParameterTable {
    /// Explicit rows.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for duplicate names; [`Error::Shape`] for a row of the wrong
    /// length.
    pub fn new(names: Vec<String>, rows: Vec<Vec<f64>>) -> Result<Self> {
        for (i, name) in names.iter().enumerate() {
            if names[..i].contains(name) {
                return Err(Error::invalid(
                    format!("parameters[{i}]"),
                    format!("{name:?}"),
                    "a name not used by another column",
                ));
            }
        }
        if let Some((i, row)) = rows
            .iter()
            .enumerate()
            .find(|(_, r)| r.len() != names.len())
        {
            bail!(Shape "row {i} has {} values but there are {} parameters", row.len(), names.len());
        }
        Ok(Self { names, rows })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }
}

/// A Cartesian product of named axes (the first axis varies slowest, like
/// `itertools.product`).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Grid {
    axes: Vec<(String, Vec<f64>)>,
}

impl Grid {
    /// An empty grid (one point with no parameters).
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds an axis.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a repeated name or an empty axis.
    pub fn axis(mut self, name: &str, values: impl IntoIterator<Item = f64>) -> Result<Self> {
        if self.axes.iter().any(|(n, _)| n == name) {
            bail!(invalid format!("grid.{name}"), "a repeated axis", "each parameter once");
        }
        let values: Vec<f64> = values.into_iter().collect();
        if values.is_empty() {
            bail!(invalid format!("grid.{name}"), "[]", "at least one value");
        }
        self.axes.push((name.to_string(), values));
        Ok(self)
    }

    /// Number of points (the product of the axis lengths).
    pub fn len(&self) -> usize {
        self.axes.iter().map(|(_, v)| v.len()).product()
    }

    /// Whether the grid has no points (never: an empty grid is one point).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The values of point `index` (row-major: the last axis varies fastest).
    pub fn point(&self, mut index: usize) -> Vec<f64> {
        let mut out = vec![0.0; self.axes.len()];
        for (k, (_, values)) in self.axes.iter().enumerate().rev() {
            out[k] = values[index % values.len()];
            index /= values.len();
        }
        out
    }

    /// All points as a table.
    pub fn table(&self) -> ParameterTable {
        ParameterTable {
            names: self.axes.iter().map(|(n, _)| n.clone()).collect(),
            rows: (0..self.len()).map(|i| self.point(i)).collect(),
        }
    }
}

/// One row of a [`SweepResult`].
#[derive(Clone, Debug, PartialEq)]
pub struct SweepRow {
    /// Position in the input table.
    pub index: usize,
    /// The parameter values of this point.
    pub parameters: Vec<f64>,
    /// Its metrics, or why it failed.
    pub outcome: Result<PointOutput>,
}

/// The finished rows of a sweep, in input order.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepResult {
    /// Parameter names (the table's columns).
    pub parameters: Vec<String>,
    /// Metric names (the columns of [`PointOutput::metrics`]).
    pub metrics: Vec<String>,
    /// Finished points in input order (fewer than the table when cancelled).
    pub rows: Vec<SweepRow>,
    /// Whether the sweep was cancelled before every point ran.
    pub cancelled: bool,
}

/// Sweeps a table: `build(values)` makes each point's device (an `Err` there becomes that
/// point's error row), all points share `options`.
///
/// Metric names are validated against the device of the first point that builds, before any
/// simulation runs.
///
/// # Errors
/// [`Error::InvalidParameter`] for an unknown metric name or a bad thread count. Point failures
/// are reported in their rows.
pub fn sweep<F>(
    table: &ParameterTable,
    build: F,
    options: &SimulationOptions,
    settings: &SweepSettings,
    control: &SweepControl,
) -> Result<SweepResult>
where
    F: Fn(&[f64]) -> Result<Device> + Sync,
{
    let threads = resolve_threads(settings.threads)?;
    let devices: Vec<Result<(Device, SimulationOptions)>> =
        run_indexed(table.len(), threads, &SweepControl::new(), |i| {
            build(&table.rows[i]).map(|d| (d, options.clone()))
        })?
        .into_iter()
        .map(|slot| slot.unwrap_or(Err(Error::Cancelled)))
        .collect();
    let names = match devices.iter().find_map(|d| d.as_ref().ok()) {
        Some((device, _)) => select(
            "metrics",
            settings.metrics.as_deref(),
            &metric_names(device),
        )?,
        None => settings.metrics.clone().unwrap_or_default(),
    };
    let slots = run_points(
        &devices,
        &names,
        settings.keep_cycle,
        Some(threads),
        control,
    )?;
    let cancelled = slots.iter().any(Option::is_none);
    let rows = slots
        .into_iter()
        .enumerate()
        .filter_map(|(index, slot)| {
            slot.map(|outcome| SweepRow {
                index,
                parameters: table.rows[index].clone(),
                outcome,
            })
        })
        .collect();
    Ok(SweepResult {
        parameters: table.names.clone(),
        metrics: names,
        rows,
        cancelled,
    })
}
