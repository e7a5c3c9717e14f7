//! The periodic steady state of [`crate::SteadyState::Shooting`]: Newton on the stroboscopic
//! map retraced on a frozen step grid.
//!
//! Why a frozen grid: an adaptive integrator's map `P(y)` is only piecewise smooth in `y` (the
//! step sequence jumps when `y` changes), so Newton stalls near `rtol` (measured: at rtol 1e-8
//! on the §3.3 device the residual halved per iteration from 9e-9 and the transient fallback
//! took over, leaving the state 5e-6 off the orbit of a slow whippletree mode, μ = 0.98). On the
//! steps the first adaptive period chose, `P` is a fixed explicit Runge–Kutta map, smooth in
//! `y`: Newton converges to round-off in one or two steps, without rejected steps or error
//! estimates, and the orbit is the fixed point of exactly the map the recorded window retraces.
//!
//! Per point: one adaptive period (with the variational equations unless a converged
//! neighbour's Jacobian is given), Newton steps with Broyden updates of the Jacobian, each
//! trial one fixed-grid period; the last trial is the recorded window itself (`finish`), started
//! once the predicted error of the next iterate (step × observed contraction) is below `tol`.
//! The residual of that recorded period is reported.

use nalgebra::{DMatrix, DVector};
use paritysim_error::{Error, Result};

use crate::device::Device;
use crate::integrate::{RungeKutta, State};

/// A periodic orbit found on a frozen grid.
#[derive(Clone, Debug)]
pub(crate) struct GridOrbit {
    /// The state on the section (work integrals zero).
    pub state: State,
    /// `‖P(y) − y‖∞ / (1 + ‖y‖∞)` of the final period.
    pub residual: f64,
    /// The last Jacobian estimate of the map (exact or Broyden-updated): the next point's
    /// guess in a continuation chain, and its eigenvalues the Floquet multipliers.
    pub jacobian: DMatrix<f64>,
    /// Period integrations before the final one.
    pub periods: usize,
    /// Newton steps taken (each a trial period).
    pub iterations: usize,
    /// The step grid (from the section time `t0` to `t0 + period`).
    pub grid: Vec<f64>,
    /// Whether `jacobian` is the exact derivative of the grid map at `state` (the final
    /// period integrated the variational equations, see [`Finished`]).
    pub jacobian_at_orbit: bool,
    /// The contraction of the error Newton's model predicted for its last step (the step's
    /// size over the previous one's, the step itself after a fresh Jacobian: the quadratic
    /// model): how good `jacobian` is as another pass's Newton model.
    pub contraction: Option<f64>,
}

/// What the final period of [`shoot`] returns: its end state, and the Jacobian of the grid map
/// at its start when that period integrated the variational equations (the exact monodromy
/// at the accepted orbit, at the cost of one variational period instead of a plain one and a
/// separate variational one).
pub(crate) type Finished = (State, Option<DMatrix<f64>>);

/// A starting model for [`shoot`]'s Newton: a Jacobian of the map (a converged neighbour's,
/// or an earlier pass's), optionally the grid it was taken on (kept while its error estimates
/// stay within tolerance) and the contraction its Newton steps achieved
/// ([`GridOrbit::contraction`]), which predicts this pass's first error.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Guess<'a> {
    pub jacobian: &'a DMatrix<f64>,
    pub grid: Option<&'a [f64]>,
    pub contraction: Option<f64>,
}

/// `(P(y) − y, ‖P(y) − y‖∞ / (1 + ‖y‖∞))`.
fn residual(n: usize, y: &State, py: &State) -> (DVector<f64>, f64) {
    let (yv, pv) = (y.compact(n), py.compact(n));
    let f = pv - &yv;
    let r = f.amax() / (1.0 + yv.amax());
    (f, r)
}

/// Whether a failed trial is the run's end rather than Newton's: a cancel, or the run's
/// budget (wall time) spent, which the transient fallback would only exceed further.
pub(crate) fn out_of_budget(e: &Error) -> bool {
    matches!(e, Error::Cancelled) || crate::integrate::budget::check_current().is_err()
}

/// Singular values of `DP − I` below this fraction of the largest are a neutral direction
/// (a multiplier within it of 1: a mode that needs more than a million periods to decay, which
/// no transient resolves either), left where it is by the Newton step.
///
/// Why not round-off (the former cutoff `1e-10`): `DP` comes from variational equations
/// integrated at the grid tolerance (`rtol / 100`, 1e-10 by default) or from Broyden updates,
/// so an exact multiplier 1 shows up as a singular value of about that size. Measured on two
/// identical §3.4 rotating wings (linear differential, K2 = 0: the differential stroke offset
/// is cyclic): the neutral singular value was 2.2e-10 against a cutoff of 1.5e-10, the step
/// divided the residual's round-off antisymmetric part (4e-15) by it and moved the orbit
/// 7e-4 rad along the neutral family: a valid but asymmetric orbit (docs/findings.md §10).
pub(crate) const NEUTRAL_SINGULAR_TOL: f64 = 1e-6;

/// The least-squares Newton step `Δ` of `(DP − I) Δ = −f` with the neutral directions
/// ([`NEUTRAL_SINGULAR_TOL`]) left out: the minimum-norm solution, which does not move the
/// state along a family of orbits (a symmetric start stays symmetric). `None` when the SVD
/// fails (a non-finite Jacobian).
pub(crate) fn least_squares_step(
    jac_minus_eye: DMatrix<f64>,
    f: &DVector<f64>,
) -> Option<DVector<f64>> {
    if jac_minus_eye.iter().chain(f.iter()).any(|v| !v.is_finite()) {
        return None;
    }
    let svd = jac_minus_eye.svd(true, true);
    let cutoff = NEUTRAL_SINGULAR_TOL * svd.singular_values.max().max(f64::MIN_POSITIVE);
    svd.solve(&(-f), cutoff).ok()
}

/// Tolerances of the adaptive period that picks the grid, relative to the run's: the fixed-grid
/// maps then need no rejected steps and the orbit and its recorded window are accurate to about
/// the run's `rtol` (on the §3.3 grid at rtol 1e-8, the grid at the run's own tolerance left
/// torques 3.5e-7 off the rtol-1e-12 reference, amplified by slow multipliers up to 0.98).
pub(crate) const GRID_TOLERANCE_FACTOR: f64 = 1e-2;

/// A grid picked by an adaptive period from a start whose first residual exceeds this is
/// picked again at the converged state before the recorded period.
///
/// Why: the drag's `φ̇|φ̇|` (and a blade element's `sgn`) is not smooth at stroke reversal, so
/// the steps the adaptive period took around the *start's* reversals are the grid's truncation
/// error on an orbit whose reversals lie elsewhere. Measured on the §3.3 device in a 4 × 4
/// sweep (chained starts 1.2e-3 to 1.4e-2 off their orbit, Newton converged to residuals of
/// 7e-11): τR peak off the rtol-1e-12 reference by up to 5.8e-7 (a direct run: 1.1e-9). Warmed-up
/// cold starts and fine sweeps' neighbours begin closer (first residuals 1e-5 to 1e-4).
pub(crate) const REPICK_RESIDUAL: f64 = 1e-3;

/// Newton on the frozen-grid map from `y0` on the section `t = t0` (mod the period), to a state whose predicted
/// error (relative to `1 + ‖y‖∞`) is below `tol`; `finish(grid, y)` integrates the final
/// period (recording it) and returns its end state, with the map's Jacobian at its start when it
/// integrated the variational equations (Newton then goes on from it if the period is not
/// accepted). The final period is accepted when its
/// residual is below `tol`, or below `accept_tol` with a negligible further Newton step (the
/// residual then lies along a neutral direction: a cyclic coordinate such as `q2` at K2 = 0
/// drifting by a constant per period). `Ok(None)` when Newton does not converge within
/// `max_newton` steps or a trial leaves the model's domain (the caller falls back to the
/// transient).
///
/// # Errors
/// Only from `finish` (e.g. a failing recorded sample) or a cancelled run.
#[allow(clippy::too_many_arguments)]
pub(crate) fn shoot(
    device: &Device,
    integrator: &RungeKutta,
    period: f64,
    t0: f64,
    y0: &State,
    guess: Option<Guess<'_>>,
    tol: f64,
    accept_tol: f64,
    max_newton: usize,
    finish: &mut dyn FnMut(&[f64], &State) -> Result<Finished>,
) -> Result<Option<GridOrbit>> {
    let rk = integrator.with_work(false);
    let chooser = rk.tightened(GRID_TOLERANCE_FACTOR);
    let n = device.n_dof();
    let m = 2 * n;
    let mut y = y0.without_work();
    let guess = guess.filter(|g| g.jacobian.shape() == (m, m));
    let guess_contraction = guess.and_then(|g| g.contraction);
    let guess_grid = guess.and_then(|g| g.grid);
    let guess = guess.map(|g| g.jacobian);
    // A neighbour's grid is kept while every step's error estimate stays within the grid
    // tolerances: the first map then costs one fixed-grid period instead of an adaptive one.
    let t_end = t0 + period;
    let inherited = match (guess, guess_grid) {
        (Some(j), Some(grid)) if grid.first() == Some(&t0) && grid.last() == Some(&t_end) => {
            match chooser.integrate_on_grid_counted(device, grid, &y, &[], &mut |_, _, _| Ok(())) {
                Ok((py, stats)) if stats.over_tolerance == 0 => {
                    Some(Ok((py, j.clone(), grid.to_vec(), false)))
                }
                Err(e) if out_of_budget(&e) => Some(Err(e)),
                _ => None,
            }
        }
        _ => None,
    };
    // Otherwise the grid is picked by an adaptive period from `y`.
    let picked_here = inherited.is_none();
    let first = match (inherited, guess) {
        (Some(done), _) => done,
        (None, Some(j)) => chooser
            .advance_with_steps(device, t0, &y, t_end)
            .map(|(py, grid)| (py, j.clone(), grid, false)),
        (None, None) => chooser
            .flow_with_sensitivity_and_steps(device, t0, &y, t_end)
            .map(|(py, j, grid)| (py, j, grid, true)),
    };
    let (py, mut jac, mut grid, mut fresh) = match first {
        Ok(v) => v,
        Err(e) if out_of_budget(&e) => return Err(e),
        Err(_) => return Ok(None),
    };
    let mut periods = 1;
    let (mut f, mut res) = residual(n, &y, &py);
    let mut repick = picked_here && res > REPICK_RESIDUAL;
    let eye = DMatrix::<f64>::identity(m, m);
    let mut last_step: Option<f64> = None;
    let mut iterations = 0;
    let newton_step = |jac: &DMatrix<f64>, f: &DVector<f64>| least_squares_step(jac - &eye, f);
    while iterations < max_newton {
        iterations += 1;
        let Some(delta) = newton_step(&jac, &f) else {
            return Ok(None);
        };
        let scale = 1.0 + y.compact(n).amax();
        let step = delta.amax() / scale;
        // The next iterate's error: the step times the contraction seen so far (Newton's
        // quadratic model after a fresh Jacobian; unknown, so 1, after a neighbour's).
        let contraction = match last_step {
            Some(s) => step / s,
            None if fresh => step,
            None => guess_contraction.unwrap_or(1.0),
        }
        .min(1.0);
        let y_new = State::from_compact(n, &(y.compact(n) + &delta));
        let last = contraction * step <= tol || step <= 1e-3 * tol;
        if last && repick {
            // Converged on a grid picked far from the orbit: the grid again, from here
            // ([`REPICK_RESIDUAL`]); Newton goes on on it with the Jacobian it has.
            repick = false;
            let (p_new, picked) = match chooser.advance_with_steps(device, t0, &y_new, t_end) {
                Ok(v) => v,
                Err(e) if out_of_budget(&e) => return Err(e),
                Err(_) => return Ok(None),
            };
            periods += 1;
            grid = picked;
            (f, res) = residual(n, &y_new, &p_new);
            y = y_new;
            continue;
        }
        let trial = if last {
            finish(&grid, &y_new)
        } else {
            rk.integrate_on_grid(device, &grid, &y_new, &[], &mut |_, _, _| Ok(()))
                .map(|p| (p, None))
        };
        let (p_new, exact) = match trial {
            Ok(p) => p,
            Err(e) if out_of_budget(&e) => return Err(e),
            // `finish` failing is the recorded window's error: report it.
            Err(e) if last => return Err(e),
            Err(_) => return Ok(None),
        };
        periods += 1;
        let (f_new, res_new) = residual(n, &y_new, &p_new);
        let exact = exact.filter(|j| j.shape() == (m, m));
        let at_orbit = exact.is_some();
        if let Some(j) = exact {
            // The final period's own variational equations: the exact Jacobian at `y_new`.
            jac = j;
            fresh = true;
            last_step = None;
        }
        // Only an exact Jacobian tells a neutral direction from a stale model's small step
        // (measured: a neighbour's Broyden-updated Jacobian accepted a residual of 2.5e-9
        // with the state 4e-7 off the orbit).
        let neutral = || {
            res_new <= accept_tol
                && newton_step(&jac, &f_new)
                    .is_some_and(|d| d.amax() / (1.0 + y_new.compact(n).amax()) <= tol)
        };
        if last && res_new > tol && res_new <= accept_tol && !fresh {
            // Re-linearise at the candidate, then decide with the exact Jacobian.
            match rk.flow_with_sensitivity_on_grid(device, &grid, &y_new) {
                Ok((_, j)) => jac = j,
                Err(e) if out_of_budget(&e) => return Err(e),
                Err(_) => return Ok(None),
            }
            periods += 1;
            fresh = true;
            last_step = None;
            (y, f, res) = (y_new, f_new, res_new);
            continue;
        }
        if last && (res_new <= tol || neutral()) {
            return Ok(Some(GridOrbit {
                state: y_new,
                residual: res_new,
                jacobian: jac,
                periods: periods - 1,
                iterations,
                grid,
                jacobian_at_orbit: at_orbit,
                contraction: Some(contraction),
            }));
        }
        if at_orbit {
            // Not accepted, but linearised at `y_new`: Newton goes on from there.
            (y, f, res) = (y_new, f_new, res_new);
            continue;
        }
        if res_new >= res || res_new.is_nan() {
            if fresh {
                return Ok(None);
            }
            // A stale (neighbour's or updated) Jacobian that no longer descends: the exact
            // one at the current iterate, on the same grid.
            match rk.flow_with_sensitivity_on_grid(device, &grid, &y) {
                Ok((_, j)) => jac = j,
                Err(e) if out_of_budget(&e) => return Err(e),
                Err(_) => return Ok(None),
            }
            periods += 1;
            fresh = true;
            last_step = None;
            continue;
        }
        // Good Broyden: the secant condition on the step just taken.
        let s_dot = delta.dot(&delta);
        if s_dot > 0.0 {
            let mismatch = (&f_new - &f) - (&jac - &eye) * &delta;
            jac += mismatch * delta.transpose() / s_dot;
        }
        fresh = false;
        (y, f, res) = (y_new, f_new, res_new);
        last_step = Some(step);
    }
    Ok(None)
}
