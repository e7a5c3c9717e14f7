//! The windows of starts near the orbit, from the base window's samples moved by `Φ(t)`.

use nalgebra::{DMatrix, DVector};
use paritysim_error::Result;

use crate::device::Device;
use crate::integrate::State;
use crate::simulate::{SimulationOptions, WindowSampler};

use super::periods::in_lanes;

/// The base window's samples (times, states) and `Φ(t, 0)` at each: the window of a start
/// `x* + δ` is, to first order in `δ`, the window of the states `y(t) + Φ(t) δ`.
pub(super) struct Replay {
    pub(super) states: Vec<State>,
    pub(super) phi: Vec<DMatrix<f64>>,
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
        let moved: Vec<State> = states
            .iter()
            .zip(&self.phi)
            .map(|(y, phi)| {
                // Φ·shift, Φ column-major.
                let mut delta = [0.0; 2 * crate::integrate::MAX_DOF];
                for (column, s) in phi.as_slice().chunks_exact(m).zip(shift) {
                    for (d, p) in delta.iter_mut().zip(column) {
                        *d += p * s;
                    }
                }
                let mut moved = *y;
                for i in 0..n {
                    moved.coords[i] += delta[i];
                    moved.rates[i] += delta[n + i];
                }
                moved
            })
            .collect();
        let (mut sampler, times) = WindowSampler::of_grid_window(device, grid, period, options);
        if let (Some(names), true) = (&options.metrics, in_lanes(options)?) {
            // The lanes' sampling, as the lanes' windows took theirs (the same bits).
            if let Some(metrics) = crate::lanes::batch::window_metrics(
                device,
                &times,
                &moved,
                names,
                options.weight_mn,
            ) {
                return Ok(metrics);
            }
        }
        for (i, (t, y)) in times.iter().zip(&moved).enumerate() {
            sampler.add(i, *t, y)?;
        }
        Ok(sampler.finish().1)
    }
}
