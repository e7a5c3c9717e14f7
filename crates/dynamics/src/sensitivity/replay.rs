//! The windows of starts near the orbit, from the base window's samples moved by `Φ(t)`.

use nalgebra::DVector;
use paritysim_error::Result;

use crate::device::Device;
use crate::integrate::State;
use crate::simulate::{SimulationOptions, WindowSampler};

use super::periods::in_lanes;

/// The base window's samples (times, states) and `Φ(t, 0)` at each: the window of a start
/// `x* + δ` is, to first order in `δ`, the window of the states `y(t) + Φ(t) δ`.
pub(super) struct Replay {
    pub(super) states: Vec<State>,
    /// `Φ` at each sample: `2n × 2n` (compact state), column-major, one after another.
    pub(super) phi: Vec<f64>,
}

impl Replay {
    /// The metrics of the window of `point` whose sample states are `states` (at the base
    /// window's phases) moved to the start `x* + shift` (compact): to first order, the states
    /// `y(t) + Φ(t) shift`. The central differences cancel the first-order error of taking
    /// the base point's `Φ` at a perturbed one.
    pub(super) fn window_along(
        &self,
        (device, grid, period): (&Device, &[f64], f64),
        states: &[State],
        shift: &DVector<f64>,
        options: &SimulationOptions,
    ) -> Result<Vec<(String, f64)>> {
        let n = device.n_dof();
        let m = 2 * n;
        let shift = shift.as_slice();
        // `Φ·shift` at each sample, into `delta` (compact).
        let moved = |y: &State, phi: &[f64], delta: &mut [f64]| {
            delta.fill(0.0);
            for (column, s) in phi.chunks_exact(m).zip(shift) {
                for (d, p) in delta.iter_mut().zip(column) {
                    *d += p * s;
                }
            }
            for i in 0..n {
                delta[i] += y.coords[i];
                delta[n + i] += y.rates[i];
            }
        };
        let samples = states.iter().zip(self.phi.chunks_exact(m * m));
        let (mut sampler, times) = WindowSampler::of_grid_window(device, grid, period, options);
        if let (Some(names), true, 2) = (&options.metrics, in_lanes(options)?, n) {
            // The lanes' sampling, as the lanes' windows took theirs (the same bits).
            let compact: Vec<[f64; 4]> = samples
                .clone()
                .map(|(y, phi)| {
                    let mut c = [0.0; 4];
                    moved(y, phi, &mut c);
                    c
                })
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
        let mut delta = vec![0.0; m];
        for (i, (t, (y, phi))) in times.iter().zip(samples).enumerate() {
            moved(y, phi, &mut delta);
            let mut y = *y;
            y.coords[..n].copy_from_slice(&delta[..n]);
            y.rates[..n].copy_from_slice(&delta[n..]);
            sampler.add(i, *t, &y)?;
        }
        Ok(sampler.finish().1)
    }
}
