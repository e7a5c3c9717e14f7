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
use paritysim_error::Result;

use super::newton::{
    GRID_TOLERANCE_FACTOR, REPICK_RESIDUAL, Trial, broyden_update, least_squares_step,
    out_of_budget, residual, trial,
};
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
        let Some(Trial {
            delta,
            step,
            contraction,
            y_new,
            last,
        }) = trial(
            n,
            &y,
            (&jac, &eye, &f),
            (last_step, fresh, guess_contraction),
            tol,
        )
        else {
            return Ok(None);
        };
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
        broyden_update(&mut jac, &eye, &delta, (&f, &f_new));
        fresh = false;
        (y, f, res) = (y_new, f_new, res_new);
        last_step = Some(step);
    }
    Ok(None)
}
