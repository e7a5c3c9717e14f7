//! Chains of neighbouring points: each continued point starts from its converged neighbour
//! (its state, period and grid), scalar or in SIMD lanes.

use paritysim_error::{Error, Result};

use crate::device::Device;
use crate::simulate::{SimulationOptions, SteadyState};
use paritysim_constraints::Vec6;

use super::{PointOutput, SweepControl, resolve_threads, run_indexed, run_point, run_tasks};

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
/// it (kept as that point's result). `metric_names` are those to report (see [`select`](super::select)).
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

/// Whether point `i` continues its chain (shooting, no initial state of its own, and a device
/// whose orbit at one drive is unique where the shipped studies go: a device with coexisting
/// stable orbits, [`Device::has_free_deviation_model`], would continue its neighbour's branch
/// instead of reaching the orbit a run from rest reaches, and its points run on their own).
pub(crate) fn continued(points: &[Result<(Device, SimulationOptions)>], i: usize) -> bool {
    matches!(&points[i], Ok((d, o)) if o.steady_state == SteadyState::Shooting
        && o.initial.is_none()
        && !d.has_free_deviation_model())
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
        // A neutral orbit (one of a family) started from a neighbour is another member of the
        // family than the run from the spec's own start reaches: rerun from there.
        Ok(o)
            if start.guess.is_some()
                && continued(points, i)
                && (o.neutral
                    || !(o.converged && o.monodromy.is_some() && o.orbit_cycles == 1)) =>
        {
            run_point(device, options, metric_names, keep_cycle)
        }
        other => other,
    }
}

/// Keeps a converged result of point `i` as a predecessor (the last two). Only an orbit
/// found by shooting (a stable, non-neutral one, with its monodromy) continues into the next
/// point.
pub(crate) fn remember(previous: &mut Vec<Converged>, i: usize, result: &Result<PointOutput>) {
    if let Ok(o) = result {
        // A period-doubled orbit's map (two cycles) is no guess for a neighbour's one-cycle map.
        // A neutral orbit is no start for a neighbour: it would land on the neighbour's family
        // member nearest to it, not on the one its own start reaches.
        let continues = o.monodromy.is_some() && o.orbit_cycles == 1 && !o.neutral;
        if let (true, Some(state), true) = (o.converged, o.steady_state, continues) {
            if previous.len() == 2 {
                previous.remove(0);
            }
            previous.push((i, state, o.monodromy.clone(), o.step_grid.clone()));
        }
    }
}
