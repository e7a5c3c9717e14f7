//! The full nonlinear model's periodic orbit: stroboscopic map, its Jacobian, Newton shooting
//! with forward sensitivities (the Floquet multipliers of its monodromy: `multipliers.rs`).

use nalgebra::{DMatrix, DVector};
use paritysim_constraints::Vec6;
use paritysim_error::{Error, Result, bail, check_positive};

use crate::device::Device;
use crate::integrate::{Integrator, Method, OdeSystem, RungeKutta, State, budget};

/// Options of [`periodic_orbit`] and [`floquet`](super::floquet); deserialises from a partial record (missing
/// fields take the defaults, unknown ones are rejected).
#[derive(Clone, Debug, PartialEq, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ShootingOptions {
    /// Runge-Kutta pair (`dop853` or `dopri5`).
    #[serde(deserialize_with = "super::records::method_by_name")]
    pub method: Method,
    /// Relative tolerance of every period integration.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
    /// Step limit per period.
    pub max_steps: usize,
    /// Start of the stroboscopic section within the drive period (ms, in `[0, T)`).
    pub t0: f64,
    /// Cycle-to-cycle simulation from the initial state before Newton (stops early once the
    /// change per cycle is below `warmup_tol`).
    pub warmup_cycles: usize,
    /// Relative change per cycle that ends the warm-up.
    pub warmup_tol: f64,
    /// Newton iterations on `P(y) − y`.
    pub max_newton: usize,
    /// Converged when `‖P(y) − y‖∞ ≤ tol (1 + ‖y‖∞)`.
    pub tol: f64,
    /// Relative finite-difference step (scaled by the size of the coordinates or of the rates)
    /// of the independent check of the monodromy
    /// ([`NonlinearFloquet::monodromy_uncertainty`](super::NonlinearFloquet::monodromy_uncertainty)); Newton and the multipliers use the
    /// variational equations.
    pub fd_step: f64,
    /// Cycles of the fallback simulation when Newton fails.
    pub fallback_cycles: usize,
    /// Drive cycles per orbit, in [1, 8]. `None`: one for [`periodic_orbit`];
    /// [`floquet`](super::floquet) then tries two when the one-cycle orbit is flip-unstable
    /// (a period-doubled orbit, as `simulate`'s two-cycle shot finds).
    pub orbit_cycles: Option<usize>,
    /// Initial state (full integrator layout); `None`: rest at the constraints' particular
    /// configuration, as [`crate::simulate()`].
    #[serde(skip)]
    pub initial: Option<State>,
}

impl Default for ShootingOptions {
    fn default() -> Self {
        Self {
            method: Method::Dop853,
            rtol: 1e-12,
            atol: 1e-14,
            max_steps: 1_000_000,
            t0: 0.0,
            warmup_cycles: 20,
            warmup_tol: 1e-6,
            max_newton: crate::shooting::newton::MAX_NEWTON,
            tol: 1e-10,
            fd_step: 1e-5,
            fallback_cycles: 2000,
            orbit_cycles: None,
            initial: None,
        }
    }
}

impl ShootingOptions {
    /// The integrator these options describe, validated for a drive `period` (ms).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the bad option.
    pub fn integrator(&self, period: f64) -> Result<RungeKutta> {
        self.validate(period)
    }

    pub(super) fn validate(&self, period: f64) -> Result<RungeKutta> {
        if !(self.t0.is_finite() && self.t0 >= 0.0 && self.t0 < period) {
            bail!(invalid "t0", self.t0, format!("in [0, {period}) ms (one drive period)"));
        }
        check_positive("tol", self.tol)?;
        check_positive("warmup_tol", self.warmup_tol)?;
        if !(self.fd_step.is_finite() && self.fd_step > 0.0 && self.fd_step < 0.01) {
            bail!(invalid "fd_step", self.fd_step, "in (0, 0.01)");
        }
        if self.warmup_cycles > 100_000 || self.fallback_cycles > 100_000 {
            bail!(invalid "warmup_cycles, fallback_cycles",
                format!("{}, {}", self.warmup_cycles, self.fallback_cycles), "<= 100000");
        }
        if let Some(y) = &self.initial {
            paritysim_error::check_all_finite("initial", &y.to_vec())?;
        }
        if let Some(k) = self
            .orbit_cycles
            .filter(|k| !(1..=MAX_ORBIT_CYCLES).contains(k))
        {
            bail!(invalid "orbit_cycles", k, format!("an integer in [1, {MAX_ORBIT_CYCLES}]"));
        }
        RungeKutta::new(self.method, self.rtol, self.atol, self.max_steps)
    }
}

/// Largest [`ShootingOptions::orbit_cycles`].
pub const MAX_ORBIT_CYCLES: usize = 8;

/// How the periodic orbit was found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OrbitMethod {
    /// Newton on the stroboscopic map (stable or not).
    Newton,
    /// Cycle-to-cycle simulation (the fallback; finds stable orbits only).
    Simulation,
}

/// A periodic orbit of a driven device: the state on the section `t ≡ t0 (mod T)`.
#[derive(Clone, Debug, PartialEq)]
pub struct PeriodicOrbit {
    /// Integrator state at `t0` (work integrals zero).
    pub state: State,
    /// Section time (ms).
    pub t0: f64,
    /// Orbit period (ms): [`ShootingOptions::orbit_cycles`] drive periods.
    pub period: f64,
    /// `‖P(y) − y‖∞ / (1 + ‖y‖∞)` at the returned state.
    pub residual: f64,
    /// Newton iterations used.
    pub newton_iterations: usize,
    /// Cycles simulated (warm-up and fallback).
    pub cycles_simulated: usize,
    /// How it was found.
    pub method: OrbitMethod,
    /// Jacobian of the stroboscopic map from the forward sensitivities, as used by the chord
    /// Newton iteration: evaluated at a state `monodromy_offset` away from `state` (`None` when
    /// the orbit came from plain simulation or needed no Newton step).
    pub monodromy: Option<DMatrix<f64>>,
    /// `‖y_J − state‖∞` of the state `y_J` where [`Self::monodromy`] was evaluated (0: at the
    /// orbit itself; NaN without a monodromy).
    pub monodromy_offset: f64,
}

/// The `2n` integrated entries (coordinates, then rates) of a state.
pub fn compact_state(n: usize, y: &State) -> DVector<f64> {
    y.compact(n)
}

/// A state from its `2n` integrated entries (work integrals zero).
pub fn expand_state(n: usize, v: &DVector<f64>) -> State {
    State::from_compact(n, v)
}

/// The drive period (ms).
///
/// # Errors
/// [`Error::Constraint`] for a device without an actuator.
pub fn drive_period(device: &Device) -> Result<f64> {
    device.period().ok_or_else(|| {
        Error::Constraint(
            "Floquet analysis needs a periodic drive: the device has no actuator".into(),
        )
    })
}

/// The stroboscopic map: integrates `system` over one `period` from `(t0, y)` with the work
/// integrals reset to zero, and returns the state at `t0 + period` (work integrals zeroed).
///
/// # Errors
/// [`Error::Integration`] when the integration fails.
pub fn stroboscopic_map(
    system: &dyn OdeSystem,
    integrator: &RungeKutta,
    t0: f64,
    period: f64,
    y: &State,
) -> Result<State> {
    let integrator = integrator.with_work(false);
    let out = integrator.advance(system, t0, &y.without_work(), t0 + period)?;
    Ok(out.without_work())
}

/// The shooting residual `‖P(y) − y‖∞ / (1 + ‖y‖∞)` ([`crate::shooting::newton::residual`]).
fn residual_norm(n: usize, y: &State, py: &State) -> f64 {
    crate::shooting::newton::residual(n, y, py).1
}

/// Finite-difference steps: `fd_step ×` the largest |coordinate| (resp. |rate|) of `y`, with a
/// floor so that a coordinate at zero (e.g. `q2` of a symmetric orbit) is still perturbed.
fn fd_steps(n: usize, y: &State, fd_step: f64) -> Vec<f64> {
    let pos = y.coords[..n].iter().map(|v| v.abs()).fold(1e-2, f64::max);
    let vel = y.rates[..n].iter().map(|v| v.abs()).fold(1e-2, f64::max);
    (0..2 * n)
        .map(|i| fd_step * if i < n { pos } else { vel })
        .collect()
}

/// Jacobian of the stroboscopic map at `y` by central differences over the `2n` integrated
/// entries (columns evaluated in parallel).
///
/// # Errors
/// [`Error::Integration`] when a perturbed integration fails.
pub fn map_jacobian(
    system: &(dyn OdeSystem + Sync),
    n: usize,
    integrator: &RungeKutta,
    t0: f64,
    period: f64,
    y: &State,
    fd_step: f64,
) -> Result<DMatrix<f64>> {
    let map = |x: &DVector<f64>| -> Result<DVector<f64>> {
        let out = stroboscopic_map(system, integrator, t0, period, &expand_state(n, x))?;
        Ok(compact_state(n, &out))
    };
    difference_jacobian(&compact_state(n, y), &fd_steps(n, y, fd_step), &map)
}

/// The Jacobian of a period map at `base` (compact state) by central differences, column `j`
/// with the step `steps[j]`; the columns run on the sweep engine's threads. The one difference
/// Jacobian of a map: the stability check of the monodromy
/// ([`map_jacobian`], adaptive map) and the switched devices' monodromy in a sensitivity
/// (fixed-grid map).
///
/// # Errors
/// The first failed evaluation of `map`.
pub(crate) fn difference_jacobian(
    base: &DVector<f64>,
    steps: &[f64],
    map: &(dyn Fn(&DVector<f64>) -> Result<DVector<f64>> + Sync),
) -> Result<DMatrix<f64>> {
    let columns = super::rows::run_parts(base.len(), |j| {
        let shifted = |sign: f64| {
            let mut v = base.clone();
            v[j] += sign * steps[j];
            map(&v)
        };
        Ok((shifted(1.0)? - shifted(-1.0)?) / (2.0 * steps[j]))
    })?;
    Ok(DMatrix::from_columns(&columns))
}

/// Finds the periodic orbit of a driven device on the section `t ≡ t0 (mod T)`.
///
/// Warm-up: up to `warmup_cycles` cycles of simulation at the options' tolerances (stopping at
/// the last good state if an integration fails). Then the engine's frozen-grid Newton
/// (as [`crate::SteadyState::Shooting`]): one adaptive period with the
/// variational equations at `rtol / 100` picks the steps from `t0` to `t0 + T`, every Newton
/// trial retraces them (a map smooth in `y`, so Newton converges to round-off), Broyden
/// updates the Jacobian between exact ones, and the step solves `(DP − I)Δ = −F` by SVD in the
/// least-squares sense with the neutral directions left out, so a multiplier 1 (e.g. K2 = 0
/// with the linear drivetrain, where every constant `q2` is an orbit) does not break it. The
/// monodromy is the variational period of the converged orbit on that grid (the exact
/// derivative of the map whose fixed point it is). If Newton fails, cycle-to-cycle simulation
/// continues from the warm-up's state (this converges only to a stable orbit).
///
/// # Errors
/// [`Error::Constraint`] without an actuator; [`Error::InvalidParameter`] for bad options;
/// [`Error::Integration`] when an integration fails or no method converges (with the best
/// state and its residual), or the wall budget is spent; [`Error::Cancelled`].
pub fn periodic_orbit(device: &Device, options: &ShootingOptions) -> Result<PeriodicOrbit> {
    // The per-point wall budget of `simulate` bounds a pathological orbit search too (an outer
    // run's earlier deadline or cancel flag still applies).
    let _budget = budget::Budget::new(Some(crate::simulate::DEFAULT_MAX_WALL_MS), None).enter();
    let drive = drive_period(device)?;
    let integrator = options.validate(drive)?;
    // The section map covers the orbit's cycles.
    let period = drive * options.orbit_cycles.unwrap_or(1) as f64;
    let n = device.n_dof();
    let t0 = options.t0;
    let mut y = match options.initial {
        Some(y) => y,
        None => device.state_from(device.spec().constraints.particular(), &Vec6::zeros())?,
    };
    y = y.without_work();
    let mut cycles = 0;
    let mut py = stroboscopic_map(device, &integrator, t0, period, &y)?;
    let mut res = residual_norm(n, &y, &py);
    while cycles < options.warmup_cycles && res > options.warmup_tol && res > options.tol {
        // A warm-up that runs away (an unstable orbit driven out of the linkage's reach) hands
        // Newton its last good state instead of failing.
        let Ok(next) = stroboscopic_map(device, &integrator, t0, period, &py) else {
            break;
        };
        (y, py) = (py, next);
        res = residual_norm(n, &y, &py);
        cycles += 1;
    }
    let orbit =
        |state: State, residual: f64, newton_iterations: usize, cycles: usize| PeriodicOrbit {
            state,
            t0,
            period,
            residual,
            newton_iterations,
            cycles_simulated: cycles,
            method: OrbitMethod::Newton,
            monodromy: None,
            monodromy_offset: f64::NAN,
        };
    if res <= options.tol {
        return Ok(orbit(y, res, 0, cycles));
    }
    let plain = integrator.with_work(false);
    let mut iterations = 0;
    // The frozen-grid Newton from `y`, its monodromy the variational period of the converged
    // orbit on that grid (the exact derivative of the map whose fixed point it is).
    let grid_orbit =
        |y: &State, guess: Option<&DMatrix<f64>>, before: usize| -> Result<Option<PeriodicOrbit>> {
            // The final period integrates the variational equations: the monodromy at the
            // orbit it accepts comes with it.
            let mut finish = |grid: &[f64], y: &State| -> Result<crate::shooting::grid::Finished> {
                plain
                    .flow_with_sensitivity_on_grid(device, grid, y)
                    .map(|(end, monodromy)| (end, Some(monodromy)))
            };
            let guess = guess.map(|jacobian| crate::shooting::grid::Guess {
                jacobian,
                grid: None,
                contraction: None,
            });
            let Some(shot) = crate::shooting::grid::shoot(
                device,
                &integrator,
                period,
                t0,
                y,
                guess,
                options.tol,
                options.tol,
                options.max_newton,
                &mut finish,
            )?
            else {
                return Ok(None);
            };
            let monodromy = shot.jacobian_at_orbit.then_some(shot.jacobian);
            let iterations = before + shot.iterations;
            Ok(Some(PeriodicOrbit {
                monodromy_offset: if monodromy.is_some() { 0.0 } else { f64::NAN },
                monodromy,
                ..orbit(shot.state.without_work(), shot.residual, iterations, cycles)
            }))
        };
    if options.max_newton > 0 {
        if let Some(found) = grid_orbit(&y, None, 0)? {
            return Ok(found);
        }
        // Too far for full Newton steps (measured: the unstable orbit of a cut wing at K2 = 1
        // after a warm-up that ran away): a damped Newton on the adaptive map brings the state
        // into the frozen-grid Newton's basin, which then finishes.
        let near = damped_newton(
            device,
            &integrator,
            t0,
            period,
            &y,
            &py,
            BASIN_TOL.max(options.tol),
            options,
        )?;
        iterations = near.iterations;
        if near.residual < res {
            // Its Jacobian saves the frozen-grid Newton the variational period.
            let guess = near.jacobian.as_ref();
            if let Some(found) = grid_orbit(&near.state, guess, iterations)? {
                return Ok(found);
            }
        }
        (y, py, res) = (near.state, near.image, near.residual);
    }
    // Fallback: plain cycle-to-cycle simulation.
    for _ in 0..options.fallback_cycles {
        y = py;
        py = stroboscopic_map(device, &integrator, t0, period, &y)?;
        res = residual_norm(n, &y, &py);
        cycles += 1;
        if res <= options.tol {
            return Ok(PeriodicOrbit {
                state: y,
                t0,
                period,
                residual: res,
                newton_iterations: iterations,
                cycles_simulated: cycles,
                method: OrbitMethod::Simulation,
                monodromy: None,
                monodromy_offset: f64::NAN,
            });
        }
    }
    Err(Error::Integration {
        time: t0,
        state: y.to_vec(),
        reason: format!(
            "no periodic orbit: frozen-grid Newton ({iterations} steps allowed) and {cycles} \
             simulated cycles \
             left the residual at {res:e} > tol = {:e}",
            options.tol
        ),
    })
}

/// Residual below which [`periodic_orbit`] hands a damped Newton's state to the frozen-grid
/// Newton (its full steps then contract: the residual is far below the orbit's scale).
const BASIN_TOL: f64 = 1e-6;

/// A damped Newton's last state.
struct Damped {
    state: State,
    /// `P(state)` on the adaptive map.
    image: State,
    residual: f64,
    iterations: usize,
    /// The last Jacobian of the map (at a state near `state`).
    jacobian: Option<DMatrix<f64>>,
}

/// Chord Newton with step halving on the adaptive map from `y` (`py = P(y)`) until the
/// residual is below `until`, a step fails or `max_newton` steps: the globalisation of
/// [`periodic_orbit`] far from the orbit. The exact derivative of the computed map (forward
/// sensitivities, one augmented period) is reused while it keeps the residual falling fast;
/// a trial costs one plain period; a stalled step re-evaluates it at the current iterate.
///
/// # Errors
/// A spent budget or cancel; [`Error::Singular`] for a non-finite Jacobian.
#[allow(clippy::too_many_arguments)]
fn damped_newton(
    device: &Device,
    integrator: &RungeKutta,
    t0: f64,
    period: f64,
    y: &State,
    py: &State,
    until: f64,
    options: &ShootingOptions,
) -> Result<Damped> {
    let n = device.n_dof();
    let (mut y, mut py) = (*y, *py);
    let mut res = residual_norm(n, &y, &py);
    let mut iterations = 0;
    let sensitivity = |y: &State| -> Result<(State, DMatrix<f64>)> {
        let (py, phi) = integrator.with_work(false).flow_with_sensitivity(
            device,
            t0,
            &y.without_work(),
            t0 + period,
        )?;
        Ok((py.without_work(), phi))
    };
    let mut jacobian: Option<(DMatrix<f64>, State)> = None;
    match sensitivity(&y) {
        Ok((p, phi)) => {
            py = p;
            res = residual_norm(n, &y, &py);
            jacobian = Some((phi, y));
        }
        Err(e) if crate::shooting::newton::out_of_budget(&e) => return Err(e),
        Err(_) => {}
    }
    while res > until && iterations < options.max_newton {
        let Some((jac, at)) = jacobian.clone() else {
            break;
        };
        let fresh = at == y;
        iterations += 1;
        let a = jac - DMatrix::<f64>::identity(2 * n, 2 * n);
        let f = compact_state(n, &py) - compact_state(n, &y);
        let delta = crate::shooting::newton::least_squares_step(a, &f).ok_or_else(|| {
            Error::Singular("Newton step of the shooting method: non-finite Jacobian".into())
        })?;
        let mut lambda = 1.0;
        let mut accepted = false;
        for _ in 0..if fresh { 8 } else { 1 } {
            let trial = expand_state(n, &(compact_state(n, &y) + &delta * lambda));
            // A trial step may leave the linkage's reach: treat it as a failed step.
            match stroboscopic_map(device, integrator, t0, period, &trial) {
                Ok(pt) => {
                    let rt = residual_norm(n, &trial, &pt);
                    // A stale Jacobian must still contract fast; a fresh one only needs descent.
                    if rt < if fresh { res } else { 0.3 * res } {
                        (y, py, res) = (trial, pt, rt);
                        accepted = true;
                        break;
                    }
                }
                Err(e) if crate::shooting::newton::out_of_budget(&e) => return Err(e),
                Err(_) => {}
            }
            lambda *= 0.5;
        }
        if accepted {
            continue;
        }
        if fresh {
            break;
        }
        match sensitivity(&y) {
            Ok((p, phi)) => {
                py = p;
                res = residual_norm(n, &y, &py);
                jacobian = Some((phi, y));
            }
            Err(e) if crate::shooting::newton::out_of_budget(&e) => return Err(e),
            Err(_) => break,
        }
    }
    Ok(Damped {
        state: y,
        image: py,
        residual: res,
        iterations,
        jacobian: jacobian.map(|(j, _)| j),
    })
}
