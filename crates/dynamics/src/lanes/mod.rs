//! Sweep chains in SIMD lanes: several shooting points integrated at once.
//!
//! A shooting point of [`crate::SteadyState::Shooting`] is a sequence of one-period integrations:
//! the warm-up and the variational period of a chain's start, then (continued points) the
//! neighbour's grid checked or a new one picked, Newton trials on the frozen grid and the
//! recorded window (docs/findings.md §6-7). Here `LANES` chains advance side by side, one
//! point per lane: every lane carries its own grid or step control, time, step and state
//! through the DOP853 stages (`integrate::dop853_lanes`, `wide::f64x4`), and a lane whose
//! period ends is handed its point's next period (or the next point of its chain, or the next
//! chain from the sweep's shared queue) while the others keep stepping: the ensemble technique
//! of heyoka and MPGOS. One such worker runs on each thread of the sweep's rayon pool.
//!
//! * **Which points.** A shooting point qualifies when it records one plain cycle, uses DOP853
//!   and its device has a lane model ([`has_lane_model`]): drivetrain coordinates of the linear
//!   differential map with an actuator and stroke drag (or no aerodynamics) on both wings
//!   (`linear_stroke`; stroke metrics only). The switched devices (§3.4 stroke plane, §2.5 free
//!   deviation) have no lanes (theirs did not pay, docs/findings.md §24), so no lane holds a
//!   switching function. Every other point runs the scalar path in place, in its chain's order.
//! * **Same results.** The lanes perform the scalar path's floating-point operations in its
//!   order (the right-hand side is the scalar form's own generic `linear_map::accelerations`),
//!   and each lane point (`point::LanePoint`) is an executor of the one shooting machine
//!   (`shooting::machine`), as `shooting::grid::shoot` is. The branches it does not follow (a
//!   failing period, a singular Newton step, no convergence, an unstable orbit: `shoot`'s
//!   `Ok(None)` and errors) rerun the point on the scalar path from the same start, so every
//!   point's result is bit-identical to the scalar sweep (`PARITYSIM_LANES=1`; tested for lane
//!   widths 1 to 4 and thread counts).
//! * **Failures are rows**: a failing point fails on the scalar rerun, with the scalar error.
//!   A panic (an engine bug) fails the chains its worker had taken and not completed (up to
//!   `LANES` chains) rather than only its chain.
//! * **Budgets**: each point's `max_wall_ms` runs from its start in a lane and is checked
//!   every `CHECK_EVERY` steps inside its periods (as the scalar integrator checks a run's);
//!   a spent budget is the point's row, the scalar path's budget error (not a rerun). The
//!   sweep's cancel is checked between periods.

pub(crate) mod batch;
pub(crate) mod linear_stroke;
mod point;
mod schedule;

use paritysim_error::{Error, Result, bail};

use crate::device::Device;
use crate::integrate::lanes::LANES;
use linear_stroke::LinearStroke;
pub(crate) use schedule::run_chains;

/// Environment variable read by [`resolve_lanes`] when no lane width is given: an integer in
/// `[1, 4]` (`PARITYSIM_LANES=1` runs the scalar path).
pub const LANES_ENV: &str = "PARITYSIM_LANES";

/// The largest lane width (one `f64x4`).
pub const MAX_LANES: usize = LANES;

/// The lane width a sweep uses: `requested` if given, else [`LANES_ENV`], else
/// [`MAX_LANES`]. One lane is the scalar path.
///
/// # Errors
/// [`Error::InvalidParameter`] for 0, more than [`MAX_LANES`], or an environment value that is
/// not such an integer (naming `lanes` or `PARITYSIM_LANES`).
pub fn resolve_lanes(requested: Option<usize>) -> Result<usize> {
    let allowed = format!("an integer in [1, {MAX_LANES}]");
    if let Some(n) = requested {
        if !(1..=MAX_LANES).contains(&n) {
            bail!(invalid "lanes", n, allowed);
        }
        return Ok(n);
    }
    if let Ok(raw) = std::env::var(LANES_ENV) {
        let raw = raw.trim();
        if !raw.is_empty() {
            return match raw.parse::<usize>() {
                Ok(n) if (1..=MAX_LANES).contains(&n) => Ok(n),
                _ => Err(Error::invalid(LANES_ENV, format!("{raw:?}"), allowed)),
            };
        }
    }
    Ok(MAX_LANES)
}

/// Whether `device` has a SIMD-lane model: its continued shooting points then run in lanes
/// when the sweep's other conditions hold (see the module). Today: drivetrain coordinates of
/// the two-DOF linear differential map (eq. 2.15) with stroke drag or no aerodynamics, the
/// §3.4 stroke-plane devices (blade elements on both wings, a single drive) and the §2.5
/// free-deviation devices (Lift and Dual PARITY with blade elements).
pub fn has_lane_model(device: &Device) -> bool {
    LinearStroke::of(device).is_some()
}

/// Points completed in lanes since the process started (tests and benchmarks read it to see
/// that the lanes ran).
pub(crate) static COMPLETED_IN_LANES: std::sync::atomic::AtomicUsize =
    std::sync::atomic::AtomicUsize::new(0);

/// A converged lane point as `simulate` and `run_point` report it (metrics only, one orbit
/// cycle), counted in [`COMPLETED_IN_LANES`].
pub(super) struct Converged<'a> {
    pub(super) device: &'a Device,
    pub(super) metric_names: &'a [String],
    pub(super) samples_per_cycle: usize,
    pub(super) period: f64,
    pub(super) metrics: Vec<(String, f64)>,
    pub(super) cycles_run: usize,
    pub(super) residual: f64,
    pub(super) state: crate::integrate::State,
    pub(super) multipliers: Vec<nalgebra::Complex<f64>>,
    pub(super) jacobian: nalgebra::DMatrix<f64>,
    pub(super) grid: Vec<f64>,
}

impl Converged<'_> {
    /// The point's output.
    pub(super) fn output(self) -> Box<crate::sweep::PointOutput> {
        let steady_state = self.state.without_work();
        let result = crate::simulate::SimulationResult {
            trajectory: crate::trajectory::Trajectory::default(),
            metrics: self.metrics,
            cycles_run: self.cycles_run,
            converged: true,
            period_ms: self.period,
            residual: self.residual,
            steady_state,
            multipliers: self.multipliers,
            monodromy: Some(self.jacobian),
            step_grid: self.grid,
            orbit_cycles: 1,
            orbit_samples: None,
        };
        let coordinates = self.device.coordinates(&steady_state).ok();
        COMPLETED_IN_LANES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        Box::new(crate::sweep::PointOutput::keep(
            result,
            self.metric_names,
            false,
            self.samples_per_cycle,
            coordinates,
        ))
    }
}

/// The shooting's tolerances of a lane point, as `simulate` gives `shooting::grid::shoot`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Limits {
    /// Newton's convergence tolerance and the residual a neutral orbit is accepted at.
    pub(super) tol: f64,
    pub(super) accept_tol: f64,
    /// The run's integration tolerances, and the grid chooser's (`GRID_TOLERANCE_FACTOR`×).
    pub(super) newton: crate::integrate::lanes::LaneTolerances,
    pub(super) grid: crate::integrate::lanes::LaneTolerances,
    pub(super) max_steps: usize,
}

impl Limits {
    pub(super) fn of(options: &crate::simulate::SimulationOptions) -> Self {
        let chooser = crate::shooting::newton::GRID_TOLERANCE_FACTOR.clamp(f64::MIN_POSITIVE, 1.0);
        let tolerances = |factor: f64| crate::integrate::lanes::LaneTolerances {
            rtol: options.rtol * factor,
            atol: options.atol * factor,
        };
        Self {
            tol: crate::shooting::newton::newton_tolerance(options.steady_tol, options.rtol),
            accept_tol: options.steady_tol,
            newton: crate::integrate::lanes::LaneTolerances {
                rtol: options.rtol,
                atol: options.atol,
            },
            grid: tolerances(chooser),
            max_steps: options.max_steps,
        }
    }
}

/// The recorded window's `n_samples + 1` sample times from 0 over `period`
/// (`simulate::window_times`), from `cache` when the last point had the same.
pub(super) fn cached_window_times(
    cache: &mut Option<(f64, usize, std::rc::Rc<[f64]>)>,
    period: f64,
    n_samples: usize,
) -> std::rc::Rc<[f64]> {
    match cache {
        Some((p, n, times)) if *p == period && *n == n_samples => times.clone(),
        _ => {
            let times: std::rc::Rc<[f64]> =
                crate::simulate::window_times(0.0, period, n_samples).collect();
            *cache = Some((period, n_samples, times.clone()));
            times
        }
    }
}

/// How many sweep points the SIMD lanes have completed in this process (monotonic; points
/// rerun on the scalar path are not counted).
pub fn points_completed_in_lanes() -> usize {
    COMPLETED_IN_LANES.load(std::sync::atomic::Ordering::Relaxed)
}

/// How many sensitivity periods (perturbed maps and windows, `batch`) the SIMD lanes have
/// completed in this process (monotonic).
pub fn periods_completed_in_lanes() -> usize {
    batch::COMPLETED.load(std::sync::atomic::Ordering::Relaxed)
}
