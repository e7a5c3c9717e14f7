//! Derivatives of steady-state metrics with respect to design parameters (issue 31).
//!
//! The steady state `x*` solves `P(x*, p) = x*`, `P` the period map on the section `t ≡ 0
//! (mod T)`. The implicit function theorem gives `dx*/dp = −(∂P/∂x − I)⁺ ∂P/∂p`: `∂P/∂x` is
//! the exact monodromy at the orbit (the variational equations on the shooting's step grid),
//! `∂P/∂p` a central difference of the map on that same fixed grid (a smooth function of `p`:
//! no step-size control to make it noisy; a frequency change scales the grid with the
//! period). A metric's derivative is the central difference of the recorded window (on that
//! grid) along the direction `(dx*/dp, 1)`: the orbit moves with the parameter, so no
//! finite difference ever runs through the shooting's convergence. The window at
//! `(x* + h dx*/dp, p + h)` is the map's own samples from `(x*, p + h)` moved by `Φ(t)·h dx*/dp`,
//! `Φ(t)` the base orbit's, sampled in its variational period (the first-order errors of both
//! cancel in the central differences; measured within 5e-9 of integrated windows). Metrics that
//! read the work integrals, and devices whose monodromy is differenced, integrate the
//! windows. Directions with a
//! multiplier at 1 (a neutral family, K2 = 0's whippletree) are left out of `(∂P/∂x − I)⁺`,
//! not divided by; a metric that changes along them, or whose one-sided differences disagree
//! (a peak jumping between two maxima), is flagged as not differentiable there. A parameter
//! whose `∂P/∂p` has a part `(∂P/∂x − I)` cannot reach (the solvability residual `uᵀ ∂P/∂p`,
//! `u` a left null vector) breaks the family: no orbit through `x*` follows it, and its
//! column is NaN with the reason.

use std::borrow::Cow;

use nalgebra::{DMatrix, DVector};
use paritysim_error::{Error, Result};

use crate::device::Device;
use crate::integrate::{RungeKutta, State};
use crate::shooting::newton::LeastSquares;
use crate::simulate::{SimulationOptions, SteadyState, WindowSampler, simulate};

mod families;
mod periods;
mod replay;

pub use families::{FAMILY_BREAK_FLOOR, FAMILY_BREAK_TOLERANCE, NEUTRAL_CHANGE_TOLERANCE};

use periods::{Keep, periods};
use replay::Replay;

/// One-sided differences of a metric that disagree by more than this (relative to the larger)
/// mark a kink: a peak switching between two maxima, a clipped quantity.
pub const KINK_TOLERANCE: f64 = 1e-2;

/// How closely a replayed window's metrics follow an integrated one's (measured: within 5e-9,
/// docs/findings.md §30). Their second-order error is even in the step, so it does not cancel
/// in `right − left` of the kink check as it does in the central difference: the check's
/// floor is two of these (a metric held at zero by symmetry, the HMF's `pitch_total_mean`,
/// was flagged at 1e-9).
const REPLAY_ACCURACY: f64 = 5e-9;

/// A parameter's size for its step and the family check: `|p|`, or 1 near 0. In
/// mg-mm-ms-rad-V the parameters a designer moves are O(1) and up (a K2 of 1e-3 mN·mm/rad is
/// a whisper); with a floor of 1e-3, a parameter at 0 stepped by 1e-8 and its map's change
/// sat at round-off, which a slow multiplier amplified: d(stroke mean)/d(offset_v) at
/// K2 = 1e-3 on the §3.3 1-Cut was 64 % off without a flag (docs/findings.md §30).
fn parameter_size(p: f64) -> f64 {
    p.abs().max(1.0)
}

/// Relative finite-difference step of the parameters (of `|p|`, or of 1 near 0).
pub const PARAMETER_STEP: f64 = 1e-5;

/// What [`steady_sensitivity`] computes.
#[derive(Clone, Debug)]
pub struct SteadySensitivity {
    /// The metrics at the base point (name, value), in the window's order.
    pub metrics: Vec<(String, f64)>,
    /// `∂metric/∂parameter`: one row per metric, one column per parameter.
    pub jacobian: DMatrix<f64>,
    /// `dx*/dp`: the orbit's start state (coordinates, then rates) per parameter.
    pub state_jacobian: DMatrix<f64>,
    /// Floquet multipliers of the exact monodromy at the orbit, largest modulus first.
    pub multipliers: Vec<nalgebra::Complex<f64>>,
    /// How many directions were neutral (a multiplier at 1) and left out.
    pub neutral_directions: usize,
    /// Per parameter: why the orbit is not differentiable in it here (`None`: it is), e.g. a
    /// parameter that breaks a neutral family ([`FAMILY_BREAK_TOLERANCE`]); its columns of
    /// `jacobian` and `state_jacobian` are NaN.
    pub parameter_not_differentiable: Vec<Option<String>>,
    /// Per metric: why its derivative is not to be trusted (`None`: differentiable).
    pub not_differentiable: Vec<Option<String>>,
    /// The period-map residual `‖P(x*) − x*‖∞ / (1 + ‖x*‖∞)` on the fixed grid.
    pub residual: f64,
}

/// A perturbed device with its period and the base grid scaled to it.
struct Point {
    device: Device,
    grid: Vec<f64>,
    period: f64,
}

/// A periodic orbit to differentiate at: its start state on the section `t ≡ 0`, the step
/// grid of its period map and the drive periods it spans.
#[derive(Clone, Debug)]
pub struct Orbit {
    /// The start state (coordinates and rates; the work integrals are not read).
    pub state: State,
    /// The fixed step grid of the period map (`simulate`'s `step_grid`); fewer than two
    /// times: one adaptive period picks it.
    pub grid: Vec<f64>,
    /// Drive periods per period of the orbit (2: a period-doubled orbit).
    pub cycles: usize,
    /// The variational record of the orbit's last shooting period on `grid`, when the run
    /// kept it ([`SimulationOptions::sampled_orbit`]): the base window and `Φ` then need no
    /// period of their own.
    pub samples: Option<crate::simulate::OrbitSamples>,
}

/// The options `simulate` runs with to find the orbit a sensitivity differentiates at: one
/// recorded cycle, no columns, shooting (a transient steady state is no exact orbit).
pub fn orbit_options(options: &SimulationOptions) -> SimulationOptions {
    let mut run_options = options.clone();
    run_options.record_cycles = 1;
    run_options.columns = Some(Vec::new());
    if run_options.steady_state == SteadyState::Transient {
        run_options.steady_state = SteadyState::Shooting;
    }
    run_options
}

/// Derivatives of the steady-state metrics of `device` (= `device_at(p0)`) with respect to
/// `p` (see the module) at the orbit a run of [`orbit_options`] from the spec's own start
/// reaches.
/// `steps[j]`: the finite-difference step of parameter `j` (`None`: [`PARAMETER_STEP`] ×
/// `max(|p0[j]|, 1e-3)`).
///
/// # Errors
/// [`Error::InvalidParameter`] for a non-finite or non-positive step; those of `device_at`
/// and [`simulate`]; [`Error::Integration`] when the base point does not converge to a
/// periodic orbit or a perturbed period fails.
pub fn steady_sensitivity(
    device_at: &(dyn Fn(&[f64]) -> Result<Device> + Sync),
    device: &Device,
    p0: &[f64],
    steps: Option<&[f64]>,
    options: &SimulationOptions,
) -> Result<SteadySensitivity> {
    finite_difference_steps(p0, steps)?; // bad steps are refused before the run
    let mut run_options = orbit_options(options);
    // The run's last shooting period keeps the base window and `Φ` where the sensitivity
    // would integrate them (see `steady_sensitivity_at`): not for a differenced monodromy.
    run_options.sampled_orbit = !differenced(device);
    let run = simulate(device, &run_options)?;
    if !run.converged {
        return Err(unconverged(
            run.cycles_run as f64 * run.period_ms,
            run.steady_state.to_vec(),
            run.residual,
        ));
    }
    let orbit = Orbit {
        state: run.steady_state,
        grid: run.step_grid,
        cycles: run.orbit_cycles,
        samples: run.orbit_samples,
    };
    steady_sensitivity_at(device_at, device, p0, steps, options, &orbit)
}

/// The steps of the parameters' differences: `steps`, or [`PARAMETER_STEP`] × max(|p0|, 1e-3).
fn finite_difference_steps(p0: &[f64], steps: Option<&[f64]>) -> Result<Vec<f64>> {
    let steps: Vec<f64> = match steps {
        Some(s) => s.to_vec(),
        None => p0
            .iter()
            .map(|p| PARAMETER_STEP * parameter_size(*p))
            .collect(),
    };
    if steps.len() != p0.len() {
        return Err(Error::invalid(
            "steps",
            steps.len().to_string(),
            format!("one step per parameter ({})", p0.len()),
        ));
    }
    if let Some(bad) = steps.iter().find(|h| !(h.is_finite() && **h > 0.0)) {
        return Err(Error::invalid(
            "steps",
            bad.to_string(),
            "finite positive steps",
        ));
    }
    Ok(steps)
}

/// The error of a point whose run ended without a steady state (at `time`, in `state`).
pub fn unconverged(time: f64, state: Vec<f64>, residual: f64) -> Error {
    Error::Integration {
        time,
        state,
        reason: format!(
            "no steady state to differentiate: the run ended unconverged (residual {residual:e})"
        ),
    }
}

/// [`steady_sensitivity`] at a known `orbit` of `device` (= `device_at(p0)`): a sweep's
/// converged point, for one.
///
/// # Errors
/// As [`steady_sensitivity`], but for the run.
pub fn steady_sensitivity_at(
    device_at: &(dyn Fn(&[f64]) -> Result<Device> + Sync),
    device: &Device,
    p0: &[f64],
    steps: Option<&[f64]>,
    options: &SimulationOptions,
    orbit: &Orbit,
) -> Result<SteadySensitivity> {
    let steps = finite_difference_steps(p0, steps)?;
    let Some(period) = device.period() else {
        return Err(Error::Constraint(
            "a sensitivity needs a periodic drive (the device has no actuator)".into(),
        ));
    };
    let n = device.n_dof();
    let rk = RungeKutta::new(
        options.method,
        options.rtol,
        options.atol,
        options.max_steps,
    )?;
    let x_star = orbit.state.without_work();
    let grid = if orbit.grid.len() >= 2 {
        orbit.grid.clone()
    } else {
        // A transient steady state: one adaptive period picks the grid.
        let (_, steps) = rk.with_work(false).advance_with_steps(
            device,
            0.0,
            &x_star,
            period * orbit.cycles.max(1) as f64,
        )?;
        steps
    };
    let differenced = differenced(device);
    let (sampler, times) = WindowSampler::of_grid_window(device, &grid, period, options);
    // The base window is sampled in the variational period, unless the metrics read the work
    // integrals (which that run does not integrate) or the monodromy is differenced; `Φ` at
    // its samples then moves the window to nearby starts without integrating again. The run's
    // last shooting period, when it kept its samples, was this very period.
    let kept = orbit
        .samples
        .as_ref()
        .filter(|kept| kept.states.len() == 2 * n * times.len());
    let (mapped, monodromy, replay, mut base_metrics) = if differenced || sampler.reads_work() {
        let (mapped, monodromy) = if differenced {
            fixed_grid_monodromy(device, &rk, &grid, &x_star)?
        } else {
            rk.with_work(false)
                .flow_with_sensitivity_on_grid(device, &grid, &x_star)?
        };
        let metrics = crate::simulate::grid_window(device, &rk, &grid, period, &x_star, options)?;
        (mapped, monodromy, None, metrics)
    } else {
        let samples = match kept {
            Some(kept) => Cow::Borrowed(kept),
            None => Cow::Owned(
                crate::simulate::sampled_variational_period(
                    device,
                    &rk.with_work(false),
                    &grid,
                    &x_star,
                    &times,
                    sampler,
                )?
                .0,
            ),
        };
        let base = (
            samples.end,
            samples.monodromy.clone(),
            samples.metrics.clone(),
        );
        (
            base.0,
            base.1,
            Some(Replay::new(samples, n, options)?),
            base.2,
        )
    };
    let residual = crate::shooting::newton::residual(n, &x_star, &mapped.without_work()).1;
    let multipliers = crate::stability::eigenvalues(&monodromy).unwrap_or_default();
    // One SVD of `DP − I` for the neutral directions and every parameter's `dx*/dp`.
    let non_finite = || Error::Singular("the orbit's sensitivity: non-finite monodromy".into());
    let least_squares =
        LeastSquares::new(monodromy - DMatrix::identity(2 * n, 2 * n)).ok_or_else(non_finite)?;
    let neutral = least_squares.neutral_directions();
    if let Some(asked) = &options.metrics {
        // The window computes what the asked metrics need (and may compute more).
        base_metrics = asked
            .iter()
            .filter_map(|name| base_metrics.iter().find(|(m, _)| m == name).cloned())
            .collect();
    }
    let n_params = p0.len();
    let state_size = 1.0 + x_star.compact(n).amax();
    let base_map = mapped.without_work().compact(n);
    // Per parameter: its two perturbed points, central (p0 ± h) or, where p0 − h is outside
    // the parameter's range (K2 = 0), one-sided (p0 + h, p0 + 2h: the second-order formula).
    let perturbed = |j: usize| -> Result<(Point, Point, bool)> {
        let at = |offset: f64| -> Result<Option<Point>> {
            let mut p = p0.to_vec();
            p[j] += offset * steps[j];
            let device = match device_at(&p) {
                Ok(d) => d,
                // Below the parameter's range (K2 = 0, a cubic spring at 0; a spec reports
                // every wing's problem at once): the one-sided formula.
                Err(e) if offset < 0.0 && e.kind() == "InvalidParameter" => return Ok(None),
                Err(e) => return Err(e),
            };
            let shifted = device.period().unwrap_or(period);
            Ok(Some(Point {
                grid: grid.iter().map(|t| t * (shifted / period)).collect(),
                device,
                period: shifted,
            }))
        };
        Ok(match at(-1.0)? {
            Some(minus) => (minus, at(1.0)?.expect("a forward step"), true),
            None => (
                at(1.0)?.expect("a forward step"),
                at(2.0)?.expect("a forward step"),
                false,
            ),
        })
    };
    // The parameters in groups (a group's four perturbed periods fill the lanes once), each
    // group's devices, maps and windows on one of the sensitivity's threads: the maps from x*,
    // then the windows along (dx*/dp_j, 1).
    // The base point's drive table, shared by the groups' periods that keep its drive.
    let base_table = if periods::in_lanes(options)? {
        crate::lanes::batch::drive_seed(device, &grid)
    } else {
        None
    };
    let groups: Vec<std::ops::Range<usize>> = (0..n_params)
        .step_by(PARAMETERS_PER_GROUP)
        .map(|first| first..(first + PARAMETERS_PER_GROUP).min(n_params))
        .collect();
    let group_columns = |g: usize| {
        let group = groups[g].clone();
        let pairs = group
            .clone()
            .map(perturbed)
            .collect::<Result<Vec<(Point, Point, bool)>>>()?;
        let points: Vec<&Point> = pairs.iter().flat_map(|(a, b, _)| [a, b]).collect();
        let mut tables = base_table
            .as_ref()
            .map_or_else(Default::default, crate::lanes::batch::DriveTables::seeded);
        let starts = vec![x_star; points.len()];
        let keep = if replay.is_some() {
            Keep::Samples
        } else {
            Keep::End
        };
        let maps = periods(&points, &starts, (keep, &mut tables), &rk, options)?;
        let dxs = pairs
            .iter()
            .zip(group.clone())
            .enumerate()
            .map(|(k, ((_, _, central), j))| {
                let (near, far) = (&maps[2 * k].end, &maps[2 * k + 1].end);
                let dp = difference(*central, steps[j], &base_map, near, far);
                let broken =
                    families::broken(&least_squares, &dp, parameter_size(p0[j]), state_size);
                Ok((least_squares.step(&dp).ok_or_else(non_finite)?, broken))
            })
            .collect::<Result<Vec<_>>>()?;
        let shifts: Vec<DVector<f64>> = pairs
            .iter()
            .zip(group)
            .zip(&dxs)
            .flat_map(|(((_, _, central), j), (dx, _))| {
                let offsets = if *central { [-1.0, 1.0] } else { [1.0, 2.0] };
                offsets.map(|o| dx * (o * steps[j]))
            })
            .collect();
        let mut windows = match &replay {
            // Each window from its map's samples moved by Φ(t)·shift.
            Some(replay) => points
                .iter()
                .zip(&maps)
                .zip(&shifts)
                .map(|((point, map), shift)| {
                    let at = (&point.device, point.grid.as_slice(), point.period);
                    replay.window_along(at, &map.states, shift, options)
                })
                .collect::<Result<Vec<_>>>()?,
            None => {
                let starts: Vec<State> = shifts
                    .iter()
                    .map(|shift| State::from_compact(n, &(x_star.compact(n) + shift)))
                    .collect();
                periods(&points, &starts, (Keep::Metrics, &mut tables), &rk, options)?
                    .into_iter()
                    .map(|period| period.metrics)
                    .collect()
            }
        }
        .into_iter();
        Ok(pairs
            .iter()
            .zip(dxs)
            .map(|((_, _, central), (dx, broken))| {
                let (near, far) = (windows.next(), windows.next());
                (
                    dx,
                    near.unwrap_or_default(),
                    far.unwrap_or_default(),
                    *central,
                    broken,
                )
            })
            .collect::<Vec<_>>())
    };
    // A group in the lanes (four perturbed periods of a linear-map device in SIMD lanes, about
    // 0.1 ms) costs less than handing it to the engine's pool and back, so those groups run
    // here in order; scalar groups (1-3 ms each) run on the engine's threads. Measured on two
    // cores (docs/findings.md §30, session 27): ten parameters on §3.3 took 1.44 ms with one
    // thread and 1.91 ms with two; on the §3.4 1-Cut two threads took 14.4 → 10.4 ms.
    let columns = if base_table.is_some() {
        (0..groups.len())
            .map(group_columns)
            .collect::<Result<Vec<_>>>()?
    } else {
        crate::stability::rows::run_parts(groups.len(), group_columns)?
    }
    .into_iter()
    .flatten()
    .collect::<Vec<_>>();
    let n_metrics = base_metrics.len();
    let mut jacobian = DMatrix::zeros(n_metrics, n_params);
    let mut state_jacobian = DMatrix::zeros(2 * n, n_params);
    let mut not_differentiable: Vec<Option<String>> = base_metrics
        .iter()
        .map(|(_, m)| (!m.is_finite()).then(|| "not defined at this point (NaN)".to_string()))
        .collect();
    let mut parameter_not_differentiable = vec![None; n_params];
    for (j, (dx, m_near, m_far, central, broken)) in columns.into_iter().enumerate() {
        if broken.is_some() {
            // No derivative to give: NaN with the reason, never a number that looks right.
            state_jacobian.set_column(j, &DVector::from_element(2 * n, f64::NAN));
            jacobian.set_column(j, &DVector::from_element(n_metrics, f64::NAN));
            parameter_not_differentiable[j] = broken;
            continue;
        }
        state_jacobian.set_column(j, &dx);
        let h = steps[j];
        for (i, (name, m0)) in base_metrics.iter().enumerate() {
            let (near, far) = (value_of(&m_near, name), value_of(&m_far, name));
            if !central {
                jacobian[(i, j)] = (-3.0 * m0 + 4.0 * near - far) / (2.0 * h);
                continue;
            }
            jacobian[(i, j)] = (far - near) / (2.0 * h);
            let (right, left) = ((far - m0) / h, (m0 - near) / h);
            let scale = right.abs().max(left.abs());
            if not_differentiable[i].is_none()
                && (right - left).abs()
                    > KINK_TOLERANCE * scale + 2.0 * REPLAY_ACCURACY * (1.0 + m0.abs()) / h
            {
                not_differentiable[i] = Some(format!(
                    "one-sided differences disagree along parameter {j} ({left:e} and \
                     {right:e}): a kink (a peak between two maxima, a clipped value)"
                ));
            }
        }
    }
    // Metrics that move along a (nearly) neutral direction: their windows along it, replayed
    // from the base window's Φ where it was kept.
    // (The base window's states are copied only at such orbits.)
    let base_states = std::cell::OnceCell::new();
    let window_along = |shift: &DVector<f64>| -> Result<Vec<(String, f64)>> {
        match &replay {
            Some(replay) => {
                let states = base_states.get_or_init(|| replay.base_states());
                replay.window_along((device, &grid, period), states, shift, options)
            }
            None => {
                let y = State::from_compact(n, &(x_star.compact(n) + shift));
                crate::simulate::grid_window(device, &rk, &grid, period, &y, options)
            }
        }
    };
    families::flag_moving_metrics(
        &least_squares,
        &neutral,
        &window_along,
        &base_metrics,
        &mut not_differentiable,
    )?;
    Ok(SteadySensitivity {
        metrics: base_metrics,
        jacobian,
        state_jacobian,
        multipliers,
        neutral_directions: neutral.len(),
        parameter_not_differentiable,
        not_differentiable,
        residual,
    })
}

/// Parameters whose perturbed periods run together: two central differences are four periods,
/// one load of the lanes.
const PARAMETERS_PER_GROUP: usize = 2;

/// `df/dp` from `f(near)`, `f(far)`: central `(p0 − h, p0 + h)` or, at the range's end,
/// the second-order one-sided formula on `(p0 + h, p0 + 2h)` with `f0 = f(p0)`.
fn difference(
    central: bool,
    h: f64,
    f0: &DVector<f64>,
    near: &DVector<f64>,
    far: &DVector<f64>,
) -> DVector<f64> {
    if central {
        (far - near) / (2.0 * h)
    } else {
        (near * 4.0 - f0 * 3.0 - far) / (2.0 * h)
    }
}

/// The fixed-grid period map from `x` and its Jacobian by central differences of the map (each
/// integration re-locates the switches). A switched device without an analytic Jacobian gets
/// its monodromy this way: its variational equations miss the jumps at the switches (measured
/// on the §2.5 Lift PARITY 1-Cut at K2 = 30: columns up to 40 % off these differences, where
/// the §3.4 device's analytic ones agree to 2e-9; docs/findings.md §30).
fn fixed_grid_monodromy(
    device: &Device,
    rk: &RungeKutta,
    grid: &[f64],
    x: &State,
) -> Result<(State, DMatrix<f64>)> {
    let n = device.n_dof();
    let plain = rk.with_work(false);
    let map = |y: &State| -> Result<DVector<f64>> {
        let end = plain.integrate_on_grid(device, grid, y, &[], &mut |_, _, _| Ok(()))?;
        Ok(end.without_work().compact(n))
    };
    let base = x.compact(n);
    let steps: Vec<f64> = base
        .iter()
        .map(|x| MONODROMY_STEP * x.abs().max(1.0))
        .collect();
    let map_compact = |v: &DVector<f64>| map(&State::from_compact(n, v));
    let jacobian = crate::stability::shooting::difference_jacobian(&base, &steps, &map_compact)?;
    let mapped = State::from_compact(n, &map(x)?);
    Ok((mapped, jacobian))
}

/// Whether `device`'s monodromy is differenced ([`fixed_grid_monodromy`]): a switched device
/// without an analytic Jacobian.
fn differenced(device: &Device) -> bool {
    crate::integrate::OdeSystem::n_switches(device) > 0 && !device.has_analytic_jacobian()
}

/// Step of the central differences of [`fixed_grid_monodromy`] (relative, absolute below 1).
const MONODROMY_STEP: f64 = 1e-6;

/// The value of metric `name` (NaN when absent).
fn value_of(metrics: &[(String, f64)], name: &str) -> f64 {
    metrics
        .iter()
        .find(|(m, _)| m == name)
        .map_or(f64::NAN, |(_, v)| *v)
}
