//! The windows of starts near the orbit, from the base window's samples moved by `Φ(t)`.

use std::borrow::Cow;

use nalgebra::DVector;
use paritysim_error::Result;
use paritysim_simd::Real;
use wide::f64x4;

use crate::device::Device;
use crate::integrate::State;
use crate::lanes::batch::{SampleBlocks, blocks_of, compact_of};
use crate::simulate::{OrbitSamples, SimulationOptions, WindowSampler};

use super::periods::{WindowStates, in_lanes};

/// The base window's samples (times, states) and `Φ(t, 0)` at each: the window of a start
/// `x* + δ` is, to first order in `δ`, the window of the states `y(t) + Φ(t) δ`.
/// Borrowed from the run's kept period, or owned when the sensitivity integrated its own:
/// the compact states (`2n` each) and `Φ` (`2n × 2n`, column-major) at the samples, one after
/// another.
pub(super) struct Replay<'a> {
    samples: Cow<'a, OrbitSamples>,
    /// The samples in the lanes' blocks, where the windows' metrics are taken in the lanes.
    lanes: Option<LaneSamples>,
}

/// The base window in the lanes' blocks (`SampleBlocks`): its states and, per block, `Φ`'s 16
/// entries (column-major), four samples' in each vector.
struct LaneSamples {
    states: SampleBlocks,
    phi: Vec<[f64x4; 16]>,
}

impl<'a> Replay<'a> {
    /// The replay of `samples` of a device with `n` degrees of freedom.
    ///
    /// # Errors
    /// That of an unknown `PARITYSIM_LANES`.
    pub(super) fn new(
        samples: Cow<'a, OrbitSamples>,
        n: usize,
        options: &SimulationOptions,
    ) -> Result<Self> {
        let stroke_metrics = options
            .metrics
            .as_ref()
            .is_some_and(|names| names.iter().all(|m| crate::metrics::is_stroke_metric(m)));
        let lanes = (n == 2 && stroke_metrics && in_lanes(options)?).then(|| {
            let phi = blocks_of::<16>(&samples.phi);
            LaneSamples {
                states: blocks_of::<4>(&samples.states),
                phi,
            }
        });
        Ok(Replay { samples, lanes })
    }

    /// The base window's own states, as the windows of perturbed maps are given.
    pub(super) fn base_states(&self) -> WindowStates {
        match &self.lanes {
            Some(lanes) => WindowStates::Blocks(lanes.states.clone()),
            None => WindowStates::Compact(self.samples.states.clone()),
        }
    }

    /// The metrics of the window of `point` whose sample states are `states` (at the base
    /// window's phases) moved to the start `x* + shift` (compact): to first order, the states
    /// `y(t) + Φ(t) shift`. The central differences cancel the first-order error of taking
    /// the base point's `Φ` at a perturbed one.
    pub(super) fn window_along(
        &self,
        (device, grid, period): (&Device, &[f64], f64),
        states: &WindowStates,
        shift: &DVector<f64>,
        options: &SimulationOptions,
    ) -> Result<Vec<(String, f64)>> {
        let m = 2 * device.n_dof();
        let shift = shift.as_slice();
        if let (Some(names), Some(lanes), Ok(shift)) =
            (&options.metrics, &self.lanes, <&[f64; 4]>::try_from(shift))
        {
            let times = crate::simulate::grid_window_times(grid, period, options);
            // The lanes' sampling, as the lanes' windows took theirs (the same bits).
            let blocks = match states {
                WindowStates::Blocks(blocks) => Cow::Borrowed(blocks),
                WindowStates::Compact(compact) => Cow::Owned(blocks_of::<4>(compact)),
            };
            let moved = blocks
                .iter()
                .zip(&lanes.phi)
                .map(|(y, phi)| moved(y, phi, shift));
            let weight = options.weight_mn;
            if let Some(metrics) =
                crate::lanes::batch::window_metrics(device, &times, moved, names, weight)
            {
                return Ok(metrics);
            }
        }
        let (mut sampler, times) = WindowSampler::of_grid_window(device, grid, period, options);
        let states = match states {
            WindowStates::Compact(compact) => Cow::Borrowed(compact),
            WindowStates::Blocks(blocks) => Cow::Owned(compact_of(blocks, times.len())),
        };
        let phis = self.samples.phi.chunks_exact(m * m);
        match m {
            2 => sample_moved::<2>(&mut sampler, &times, &states, phis, shift)?,
            4 => sample_moved::<4>(&mut sampler, &times, &states, phis, shift)?,
            6 => sample_moved::<6>(&mut sampler, &times, &states, phis, shift)?,
            8 => sample_moved::<8>(&mut sampler, &times, &states, phis, shift)?,
            10 => sample_moved::<10>(&mut sampler, &times, &states, phis, shift)?,
            _ => sample_moved::<12>(&mut sampler, &times, &states, phis, shift)?,
        }
        Ok(sampler.finish().1)
    }
}

/// Adds to `sampler` the samples `states` (compact) moved by `Φ·shift` (`M = 2n`, see
/// [`moved`]).
fn sample_moved<const M: usize>(
    sampler: &mut WindowSampler,
    times: &[f64],
    states: &[f64],
    phis: std::slice::ChunksExact<'_, f64>,
    shift: &[f64],
) -> Result<()> {
    let shift: &[f64; M] = shift.try_into().map_err(|_| {
        paritysim_error::Error::Singular(format!(
            "a window's shift has {} entries, not {M}",
            shift.len()
        ))
    })?;
    let n = M / 2;
    for (i, ((t, y), phi)) in times
        .iter()
        .zip(states.chunks_exact(M))
        .zip(phis)
        .enumerate()
    {
        let compact = moved(y, phi, shift);
        let mut y = State::default();
        y.coords[..n].copy_from_slice(&compact[..n]);
        y.rates[..n].copy_from_slice(&compact[n..]);
        sampler.add(i, *t, &y)?;
    }
    Ok(())
}

/// The compact state `y + Φ·shift` (`y` compact; `M = 2n`; `Φ` column-major, `M × M`), of one
/// sample (`f64`) or of four in the lanes (`f64x4`), with the same operations.
#[inline]
fn moved<S: Real, const M: usize>(y: &[S], phi: &[S], shift: &[f64; M]) -> [S; M] {
    let mut delta = [S::splat(0.0); M];
    for (column, s) in phi.chunks_exact(M).zip(shift) {
        for (d, p) in delta.iter_mut().zip(column) {
            *d = *d + *p * S::splat(*s);
        }
    }
    for (d, y) in delta.iter_mut().zip(y) {
        *d = *d + *y;
    }
    delta
}
