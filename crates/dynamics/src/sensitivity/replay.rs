//! The windows of starts near the orbit, from the base window's samples moved by `Φ(t)`.

use std::borrow::Cow;

use nalgebra::DVector;
use paritysim_error::Result;

use crate::device::Device;
use crate::integrate::State;
use crate::simulate::{OrbitSamples, SimulationOptions, WindowSampler};

use super::periods::in_lanes;

/// The base window's samples (times, states) and `Φ(t, 0)` at each: the window of a start
/// `x* + δ` is, to first order in `δ`, the window of the states `y(t) + Φ(t) δ`.
/// Borrowed from the run's kept period, or owned when the sensitivity integrated its own:
/// the compact states (`2n` each) and `Φ` (`2n × 2n`, column-major) at the samples, one after
/// another.
pub(super) struct Replay<'a> {
    pub(super) samples: Cow<'a, OrbitSamples>,
}

impl Replay<'_> {
    /// The metrics of the window of `point` whose sample states are `states` (compact, at the
    /// base window's phases) moved to the start `x* + shift` (compact): to first order, the states
    /// `y(t) + Φ(t) shift`. The central differences cancel the first-order error of taking
    /// the base point's `Φ` at a perturbed one.
    pub(super) fn window_along(
        &self,
        (device, grid, period): (&Device, &[f64], f64),
        states: &[f64],
        shift: &DVector<f64>,
        options: &SimulationOptions,
    ) -> Result<Vec<(String, f64)>> {
        let m = 2 * device.n_dof();
        let shift = shift.as_slice();
        let samples = states
            .chunks_exact(m)
            .zip(self.samples.phi.chunks_exact(m * m));
        let (mut sampler, times) = WindowSampler::of_grid_window(device, grid, period, options);
        if let (Some(names), true, Ok(shift)) =
            (&options.metrics, in_lanes(options)?, shift.try_into())
        {
            // The lanes' sampling, as the lanes' windows took theirs (the same bits).
            let compact: Vec<[f64; 4]> = samples
                .clone()
                .map(|(y, phi)| moved(y, phi, shift))
                .collect();
            if let Some(metrics) = crate::lanes::batch::window_metrics(
                device,
                &times,
                &compact,
                names,
                options.weight_mn,
            ) {
                return Ok(metrics);
            }
        }
        let phis = self.samples.phi.chunks_exact(m * m);
        match m {
            2 => sample_moved::<2>(&mut sampler, &times, states, phis, shift)?,
            4 => sample_moved::<4>(&mut sampler, &times, states, phis, shift)?,
            6 => sample_moved::<6>(&mut sampler, &times, states, phis, shift)?,
            8 => sample_moved::<8>(&mut sampler, &times, states, phis, shift)?,
            10 => sample_moved::<10>(&mut sampler, &times, states, phis, shift)?,
            _ => sample_moved::<12>(&mut sampler, &times, states, phis, shift)?,
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

/// The compact state `y + Φ·shift` (`y` compact; `M = 2n`; `Φ` column-major, `M × M`).
#[inline]
fn moved<const M: usize>(y: &[f64], phi: &[f64], shift: &[f64; M]) -> [f64; M] {
    let mut delta = [0.0; M];
    for (column, s) in phi.chunks_exact(M).zip(shift) {
        for (d, p) in delta.iter_mut().zip(column) {
            *d += p * s;
        }
    }
    for (d, y) in delta.iter_mut().zip(y) {
        *d += y;
    }
    delta
}
