//! One sweep point: its settings, its output row and its run.

use paritysim_error::Result;

use crate::device::Device;
use crate::simulate::{SimulationOptions, SimulationResult, Trajectory, simulate};
use paritysim_constraints::Vec6;

/// What each point reports.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct SweepSettings {
    /// Threads (`None`: [`resolve_threads`](super::resolve_threads)).
    pub threads: Option<usize>,
    /// Metric names to keep, in this order (`None`: all of [`metric_names`](super::metric_names)).
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
    /// Whether the orbit belongs to a family of orbits (a Floquet multiplier within
    /// [`NEUTRAL_MULTIPLIER_TOL`] of 1, e.g. the whippletree's differential offset at K2 = 0):
    /// such an orbit neither continues a chain nor is taken from one (`sweep/chain.rs`).
    pub neutral: bool,
}

/// A multiplier within this distance of 1 marks a family of periodic orbits (a neutral mode):
/// which member a run reaches depends on where it starts, so only a run from the spec's own
/// start gives *the* answer (the orbit an experiment started from rest sees). Structural
/// neutral modes (a cyclic coordinate) sit at 1 to the Jacobian's accuracy (about 1e-8);
/// the slowest decaying modes of the shipped devices are farther than 1e-2 from 1.
pub const NEUTRAL_MULTIPLIER_TOL: f64 = 1e-3;

/// Whether `multipliers` contain a neutral one ([`NEUTRAL_MULTIPLIER_TOL`]).
pub fn has_neutral_mode(multipliers: &[nalgebra::Complex<f64>]) -> bool {
    multipliers
        .iter()
        .any(|m| (m - 1.0).norm() <= NEUTRAL_MULTIPLIER_TOL)
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
            neutral: has_neutral_mode(&result.multipliers),
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
