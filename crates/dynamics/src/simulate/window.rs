//! The recorded window: samples at fixed times of the dense output feed the streamed metrics
//! and the asked columns.

use paritysim_error::{Result, bail};

use crate::device::Device;
use crate::integrate::budget::Budget;
use crate::integrate::{Integrator, RungeKutta, State};
use crate::metrics::{MetricsAccumulator, StrokeNeeds, forces};
use crate::trajectory::Trajectory;
use crate::trajectory::{PlaneSample, Recorder, Sample, StrokeSample};

use super::{Perturbation, SimulationOptions, apply_kick, validate};

/// The metrics of one drive period recorded from `state` at `t = 0` (a state on the section
/// `t ≡ 0 mod T`, e.g. a periodic orbit from continuation), with `options`' tolerances and
/// `samples_per_cycle`; no transient, no columns.
///
/// # Errors
/// [`Error::Constraint`](paritysim_error::Error::Constraint) without a periodic drive; integration errors.
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
        options.weight_mn,
    )?;
    Ok(metrics)
}

/// The metrics of the orbit's window recorded on the fixed step `grid` (over one or two
/// periods, as the shooting's last period) from `y` at `grid[0]`, with `options`' metrics and
/// `samples_per_cycle`: a smooth function of `y` and of the device (the sensitivities'
/// central differences, [`crate::sensitivity`]).
///
/// # Errors
/// Integration errors; a bad grid.
pub(crate) fn grid_window(
    device: &Device,
    integrator: &RungeKutta,
    grid: &[f64],
    period: f64,
    y: &State,
    options: &SimulationOptions,
) -> Result<Vec<(String, f64)>> {
    let window = grid[grid.len() - 1] - grid[0];
    let stroke = stroke_sampling(device, options.metrics.as_deref(), &[]);
    let (_, metrics, _) = record_window(
        device,
        integrator,
        grid[0],
        &y.without_work(),
        window,
        window_samples(grid, period, options),
        Some(period),
        None,
        Vec::new(),
        stroke,
        Some(grid),
        options.weight_mn,
    )?;
    Ok(metrics)
}

/// The number of samples of [`grid_window`]'s window (`samples_per_cycle` per period).
fn window_samples(grid: &[f64], period: f64, options: &SimulationOptions) -> usize {
    let window = grid[grid.len() - 1] - grid[0];
    let cycles = ((window / period).round() as usize).max(1);
    options.samples_per_cycle * cycles
}

/// The sample times of [`grid_window`]'s window (`record_window`'s).
pub(crate) fn grid_window_times(
    grid: &[f64],
    period: f64,
    options: &SimulationOptions,
) -> Vec<f64> {
    let window = grid[grid.len() - 1] - grid[0];
    window_times(grid[0], window, window_samples(grid, period, options)).collect()
}

/// How samples are taken (see [`SimulationOptions::metrics`]): `Some(needs)` for lean
/// [`StrokeSample`]s (no column asked, drivetrain coordinates) or [`PlaneSample`]s (no column
/// asked, the stroke-plane model), else `None` (full samples).
pub(super) fn stroke_sampling(
    device: &Device,
    metrics: Option<&[String]>,
    columns: &[crate::trajectory::Column],
) -> Option<StrokeNeeds> {
    let lean = columns.is_empty()
        && (device.formulation() == crate::device::Formulation::DrivetrainCoordinates
            || device.has_stroke_plane_model());
    lean.then(|| StrokeNeeds::of(metrics))
}

/// The `n_samples + 1` sample times of a recorded window from `t_start`: the last one exactly
/// the window's end (`t_start + window·k/n` can round one ulp past it).
pub(crate) fn window_times(
    t_start: f64,
    window: f64,
    n_samples: usize,
) -> impl Iterator<Item = f64> {
    let t_end = t_start + window;
    (0..=n_samples).map(move |k| {
        if k == n_samples {
            t_end
        } else {
            t_start + window * k as f64 / n_samples as f64
        }
    })
}

/// A recorded window: its columns, its metrics and the state at its end.
pub(super) type Recorded = (Trajectory, Vec<(String, f64)>, State);

/// [`record_window`] of a period-1 orbit on its `grid` (no kick) integrating the variational
/// equations too: also the states and `Φ(t)` at the samples and the monodromy
/// ([`SimulationOptions::sampled_orbit`](super::SimulationOptions::sampled_orbit)). The state
/// part integrates as the plain period does. `integrator` without work integrals.
///
/// # Errors
/// As [`record_window`].
#[allow(clippy::too_many_arguments)]
pub(super) fn record_window_sampled(
    device: &Device,
    integrator: &RungeKutta,
    y: &State,
    n_samples: usize,
    period: f64,
    columns: Vec<crate::trajectory::Column>,
    stroke: Option<StrokeNeeds>,
    grid: &[f64],
    weight: Option<f64>,
) -> Result<(Recorded, super::OrbitSamples)> {
    let times: Vec<f64> = window_times(grid[0], period, n_samples).collect();
    let sampler = WindowSampler::new(device, Some(period), columns, stroke, n_samples, weight);
    let (samples, trajectory) =
        sampled_variational_period(device, integrator, grid, y, &times, sampler)?;
    Ok(((trajectory, samples.metrics.clone(), samples.end), samples))
}

/// The variational period on `grid` from `y` (`integrator` without work integrals), each
/// sample at `times` fed to `sampler`: the period's [`super::OrbitSamples`] and the sampler's
/// columns.
///
/// # Errors
/// As [`RungeKutta::flow_with_sensitivity_on_grid_sampled`]; a sample the sampler refuses.
pub(crate) fn sampled_variational_period(
    device: &Device,
    integrator: &RungeKutta,
    grid: &[f64],
    y: &State,
    times: &[f64],
    mut sampler: WindowSampler<'_>,
) -> Result<(super::OrbitSamples, Trajectory)> {
    let n = device.n_dof();
    let mut states = Vec::with_capacity(2 * n * times.len());
    let (end, monodromy, phi) = integrator.flow_with_sensitivity_on_grid_sampled(
        device,
        grid,
        y,
        times,
        &mut |i, t, y| {
            y.push_compact(n, &mut states);
            sampler.add(i, t, y)
        },
    )?;
    let (trajectory, metrics) = sampler.finish();
    let samples = super::OrbitSamples {
        end: end.without_work(),
        monodromy,
        states,
        phi,
        metrics,
    };
    Ok((samples, trajectory))
}

/// Integrates the recorded window from `(t_start, y)`, evaluating each of the `n_samples + 1`
/// samples once: it feeds the metrics and the asked columns, nothing else is kept.
#[allow(clippy::too_many_arguments)]
pub(super) fn record_window(
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
    weight: Option<f64>,
) -> Result<Recorded> {
    let t_end = t_start + window;
    let times: Vec<f64> = window_times(t_start, window, n_samples).collect();
    let mut sampler = WindowSampler::new(device, period, columns, stroke, n_samples, weight);
    let mut sink = |i: usize, t: f64, y: &State| sampler.add(i, t, y);
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
    let (trajectory, metrics) = sampler.finish();
    Ok((trajectory, metrics, end))
}

/// A window's samples turned into its metrics and asked columns, one sample at a time
/// ([`record_window`]'s sink; the sensitivities' windows sampled in another run).
pub(crate) struct WindowSampler<'d> {
    device: &'d Device,
    metrics: MetricsAccumulator,
    recorder: Recorder,
    stroke: Option<StrokeNeeds>,
    plane: bool,
    /// The closing sample's index.
    closing: usize,
}

impl<'d> WindowSampler<'d> {
    /// A sampler of `n_samples + 1` samples (see [`record_window`]).
    pub(crate) fn new(
        device: &'d Device,
        period: Option<f64>,
        columns: Vec<crate::trajectory::Column>,
        stroke: Option<StrokeNeeds>,
        n_samples: usize,
        weight: Option<f64>,
    ) -> Self {
        Self {
            device,
            metrics: MetricsAccumulator::new(device, period).with_weight(weight),
            recorder: Recorder::new(columns, n_samples + 1),
            stroke,
            plane: device.formulation() != crate::device::Formulation::DrivetrainCoordinates,
            closing: n_samples,
        }
    }

    /// The sampler of [`grid_window`]'s window (its metrics, no columns) and its sample times.
    pub(crate) fn of_grid_window(
        device: &'d Device,
        grid: &[f64],
        period: f64,
        options: &SimulationOptions,
    ) -> (Self, Vec<f64>) {
        let stroke = stroke_sampling(device, options.metrics.as_deref(), &[]);
        let n_samples = window_samples(grid, period, options);
        let sampler = Self::new(
            device,
            Some(period),
            Vec::new(),
            stroke,
            n_samples,
            options.weight_mn,
        );
        (sampler, grid_window_times(grid, period, options))
    }

    /// Whether the metrics read the work integrals (which only a run with work integrates).
    pub(crate) fn reads_work(&self) -> bool {
        self.stroke.is_none_or(|needs| needs.work)
    }

    /// Adds sample `i` (at `t`, in state `y`).
    ///
    /// # Errors
    /// A model evaluation outside its domain.
    pub(crate) fn add(&mut self, i: usize, t: f64, y: &State) -> Result<()> {
        let (device, closing) = (self.device, i == self.closing);
        // `stroke` is only set for drivetrain-coordinate and stroke-plane devices (see
        // `stroke_sampling`).
        if let Some(needs) = self.stroke {
            if self.plane {
                if let Some(sample) = PlaneSample::new(device, t, y, needs) {
                    self.metrics.add_plane(&sample?, closing);
                    if needs.forces {
                        self.metrics
                            .add_forces(&forces::of_state(device, y)?, closing);
                    }
                    return Ok(());
                }
                // Outside the closed form: the general sample (which reports why).
            } else {
                let sample = StrokeSample::of_stroke_device(device, t, y, needs)?;
                self.metrics.add_stroke(&sample, closing);
                if needs.forces {
                    self.metrics
                        .add_forces(&forces::of_state(device, y)?, closing);
                }
                return Ok(());
            }
        }
        let sample = Sample::new(device, t, y)?;
        self.metrics.add(&sample, closing);
        self.recorder.push(&sample)
    }

    /// The columns and the metrics.
    pub(crate) fn finish(self) -> (Trajectory, Vec<(String, f64)>) {
        (self.recorder.finish(), self.metrics.finish())
    }
}
