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

use nalgebra::DMatrix;
use paritysim_error::Result;

use super::machine::{GridNewton, Limits, Reply, Request, Start, Verdict};
use super::newton::{GRID_TOLERANCE_FACTOR, out_of_budget};
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
    let y = y0.without_work();
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
    let (mapped, jacobian, grid, exact) = match first {
        Ok(v) => v,
        Err(e) if out_of_budget(&e) => return Err(e),
        Err(_) => return Ok(None),
    };
    let start = Start {
        y,
        mapped,
        jacobian,
        exact,
        grid: grid.into(),
        picked_here,
        guess_contraction,
    };
    let limits = Limits {
        tol,
        accept_tol,
        max_newton,
    };
    let (mut machine, mut verdict) = GridNewton::start(n, start, limits);
    // The scalar executor: each requested period at once.
    loop {
        let request = match verdict {
            Verdict::Run(request) => request,
            Verdict::GaveUp => return Ok(None),
            Verdict::Converged(accepted) => {
                return Ok(Some(GridOrbit {
                    state: accepted.state,
                    residual: accepted.residual,
                    jacobian: machine.jacobian,
                    periods: machine.periods - 1,
                    iterations: machine.iterations,
                    grid: machine.grid.to_vec(),
                    jacobian_at_orbit: accepted.jacobian_at_orbit,
                    contraction: Some(accepted.contraction),
                }));
            }
        };
        let grid = &machine.grid;
        let reply = match request {
            // `finish` failing is the recorded window's error: report it.
            Request::Trial { y, last: true } => {
                let (mapped, exact) = finish(grid, &y)?;
                Reply::Mapped(mapped, exact)
            }
            Request::Trial { y, last: false } => {
                match rk.integrate_on_grid(device, grid, &y, &[], &mut |_, _, _| Ok(())) {
                    Ok(mapped) => Reply::Mapped(mapped, None),
                    Err(e) if out_of_budget(&e) => return Err(e),
                    Err(_) => Reply::Failed,
                }
            }
            Request::Linearise { y } => match rk.flow_with_sensitivity_on_grid(device, grid, &y) {
                Ok((_, jacobian)) => Reply::Linearised(jacobian),
                Err(e) if out_of_budget(&e) => return Err(e),
                Err(_) => Reply::Failed,
            },
            Request::Pick { y } => match chooser.advance_with_steps(device, t0, &y, t_end) {
                Ok((mapped, picked)) => Reply::Picked(mapped, picked),
                Err(e) if out_of_budget(&e) => return Err(e),
                Err(_) => Reply::Failed,
            },
        };
        verdict = machine.resume(reply);
    }
}
