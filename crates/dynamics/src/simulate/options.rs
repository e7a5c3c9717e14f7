//! What a run is asked for ([`SimulationOptions`], perturbations, the steady-state method),
//! its validation, and what it returns ([`SimulationResult`]).

use paritysim_constraints::Vec6;
use paritysim_error::{Result, bail, check_non_negative, check_positive};

use crate::integrate::budget::CancelFlag;
use crate::integrate::{Method, State};
use crate::trajectory::Trajectory;

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

/// Options of [`simulate`](crate::simulate()).
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
    /// it the run fails with an [`Error::Integration`](paritysim_error::Error::Integration) naming `options.max_wall_ms`.
    pub max_wall_ms: Option<f64>,
    /// Stops the run at the next budget check with [`Error::Cancelled`](paritysim_error::Error::Cancelled) once set (not part of
    /// the spec: a sweep's or a caller's flag).
    pub cancel: Option<CancelFlag>,
    /// Weight (mN) the metric `lift_to_weight` divides the mean lift by (`None`: no such
    /// metric); the spec sets it from its `body` section (body and wing masses times `|g|`).
    pub weight_mn: Option<f64>,
    /// The shooting's last (recorded) period of a period-1 orbit, when its samples read no
    /// work integral (lean stroke samples), also integrates the variational equations and
    /// keeps the states and `Φ(t)` at the window's samples
    /// ([`SimulationResult::orbit_samples`]): a sensitivity's base window, which then needs no
    /// period of its own (`crate::sensitivity`). The shooting itself is unchanged.
    pub sampled_orbit: bool,
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
            weight_mn: None,
            sampled_orbit: false,
        }
    }
}

/// The outcome of [`simulate`](crate::simulate()).
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
    /// With [`SimulationOptions::sampled_orbit`], when the shooting's last period recorded
    /// the window of a period-1 orbit: that period's variational record.
    pub orbit_samples: Option<OrbitSamples>,
}

/// The shooting's last period integrated with the variational equations on
/// [`SimulationResult::step_grid`] from [`SimulationResult::steady_state`], sampled at the
/// recorded window's times.
#[derive(Clone, Debug, PartialEq)]
pub struct OrbitSamples {
    /// The period map's value `P(x*)` (no work integrals).
    pub end: State,
    /// The exact monodromy `∂P/∂x` at the orbit (active rows and columns).
    pub monodromy: nalgebra::DMatrix<f64>,
    /// The states at the window's samples, compact (coordinates, then rates: `2n` each), one
    /// after another.
    pub states: Vec<f64>,
    /// `Φ(t)` at each sample, as [`SimulationResult::monodromy`]'s block, column-major, one
    /// after another.
    pub phi: Vec<f64>,
    /// The window's metrics from those samples (all of them, as the window computes).
    pub metrics: Vec<(String, f64)>,
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
    if let Some(weight) = options.weight_mn {
        check_non_negative("weight_mn", weight)?;
    }
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
pub(super) fn check_recording_size(options: &SimulationOptions, n_columns: usize) -> Result<()> {
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

pub(super) fn options_value(field: &str, samples_per_cycle: usize, record_cycles: usize) -> String {
    match field {
        "samples_per_cycle" => format!("{samples_per_cycle} (× record_cycles = {record_cycles})"),
        _ => format!("{record_cycles} (× samples_per_cycle = {samples_per_cycle})"),
    }
}
