//! Fixed steps on a given grid (no error control; the grids shooting freezes), with steps cut
//! at the roots of switching functions.

use paritysim_error::{Error, Result};

use super::switched::Branch;
use super::{
    IntegrationStats, MAX_SWITCHES, Method, Rhs, Sink, Stepper, Tolerances, budget, dop853, dopri5,
    events, integration_error, sample_step,
};

/// A step grid: at least two finite, strictly increasing times.
pub(crate) fn check_grid(grid: &[f64]) -> Result<()> {
    if grid.len() < 2 {
        return Err(Error::invalid("grid", grid.len(), "at least two times"));
    }
    if let Some(i) = (1..grid.len()).find(|&i| grid[i] <= grid[i - 1] || !grid[i].is_finite()) {
        return Err(Error::invalid(
            format!("grid[{i}]"),
            grid[i],
            format!("finite and > grid[{}] = {}", i - 1, grid[i - 1]),
        ));
    }
    Ok(())
}

/// [`drive_on_grid`] with the stepper of `method`.
pub(crate) fn drive_method_on_grid<const M: usize>(
    method: Method,
    rhs: &mut dyn Rhs<M>,
    tol: &Tolerances,
    grid: &[f64],
    y0: [f64; M],
    times: &[f64],
    sink: &mut Sink<'_>,
) -> Result<([f64; M], IntegrationStats)> {
    with_stepper!(method, M, |stepper| drive_on_grid(
        stepper, rhs, tol, grid, y0, times, sink
    ))
}

/// Fixed steps between consecutive `grid` times; the error estimate is not used.
pub(super) fn drive_on_grid<const M: usize, S: Stepper<M>>(
    stepper: &mut S,
    rhs: &mut dyn Rhs<M>,
    tol: &Tolerances,
    grid: &[f64],
    y0: [f64; M],
    times: &[f64],
    sink: &mut Sink<'_>,
) -> Result<([f64; M], IntegrationStats)> {
    let mut stats = IntegrationStats::default();
    let mut y = y0;
    let mut next = 0;
    let t0 = grid[0];
    if next < times.len() && times[next] <= t0 {
        let state = rhs.expand(&y);
        while next < times.len() && times[next] <= t0 {
            super::stepper::emit(rhs, sink, (next, times[next]), &y, &state)?;
            next += 1;
        }
    }
    let n_switches = rhs.n_switches().min(MAX_SWITCHES);
    if n_switches > 0 {
        return drive_on_grid_events(stepper, rhs, tol, grid, y, times, next, sink, n_switches);
    }
    let mut f0 = [0.0; M];
    let mut f1 = [0.0; M];
    rhs.eval(t0, &y, &mut f0)?;
    for (k, pair) in grid.windows(2).enumerate() {
        let (t, t_new) = (pair[0], pair[1]);
        if k % budget::CHECK_EVERY == 0 {
            if let Err(stop) = budget::check_current() {
                return Err(budget::stop_error(stop, t, rhs.expand(&y).to_vec()));
            }
        }
        let h = t_new - t;
        let err = stepper.attempt(rhs, t, &y, &f0, h, tol)?;
        if !err.is_finite() {
            return Err(integration_error(
                t,
                &rhs.expand(&y),
                "non-finite state on a fixed step",
            ));
        }
        if err > 1.0 {
            stats.over_tolerance += 1;
        }
        stats.accepted += 1;
        stepper.new_derivative(rhs, t_new, &mut f1)?;
        let y1 = *stepper.y1();
        sample_step(
            stepper,
            rhs,
            t,
            &y,
            &f0,
            &f1,
            h,
            (t_new, &y1),
            false,
            times,
            &mut next,
            sink,
            &mut stats,
        )?;
        y = y1;
        f0 = f1;
    }
    Ok((y, stats))
}

/// Most sub-steps of one grid step (each ends at a root of a switching function).
pub(super) const MAX_EVENTS_PER_STEP: usize = 8;

/// [`drive_on_grid`] for a right-hand side with switching functions: each grid step on the
/// branch of its start, cut at the first root inside it (located on the step's dense output,
/// as the adaptive loop does) and finished on the new branch. The roots then move smoothly
/// with the initial state, so the frozen map stays smooth and follows the true map: a branch
/// held over a whole step (read half a step in) integrated the steps next to a moved root on
/// a continued branch (measured on the §2.5 Dual PARITY: the grid map's orbit 9.5e-5 off the
/// true map's, the root 4e-4 ms from its node).
#[allow(clippy::too_many_arguments)]
pub(super) fn drive_on_grid_events<const M: usize, S: Stepper<M>>(
    stepper: &mut S,
    rhs: &mut dyn Rhs<M>,
    tol: &Tolerances,
    grid: &[f64],
    y0: [f64; M],
    times: &[f64],
    mut next: usize,
    sink: &mut Sink<'_>,
    n_switches: usize,
) -> Result<([f64; M], IntegrationStats)> {
    let mut stats = IntegrationStats::default();
    let mut y = y0;
    let mut branch = Branch::start(rhs, n_switches, grid[0], &y)?;
    let mut f0 = [0.0; M];
    rhs.eval(grid[0], &y, &mut f0)?;
    for (k, pair) in grid.windows(2).enumerate() {
        if k % budget::CHECK_EVERY == 0 {
            if let Err(stop) = budget::check_current() {
                return Err(budget::stop_error(stop, pair[0], rhs.expand(&y).to_vec()));
            }
        }
        grid_step_with_events(
            stepper,
            rhs,
            tol,
            &mut branch,
            (pair[0], pair[1]),
            (&mut y, &mut f0),
            (times, &mut next, sink),
            &mut stats,
        )?;
    }
    Ok((y, stats))
}

/// One grid step `[t, t_new]` of [`drive_on_grid_events`] from `(y, f0)` on `branch`, cut at
/// the first root inside it and finished on the new branch; `(y, f0)` become the state and
/// derivative at `t_new`.
#[allow(clippy::too_many_arguments)]
fn grid_step_with_events<const M: usize, S: Stepper<M>>(
    stepper: &mut S,
    rhs: &mut dyn Rhs<M>,
    tol: &Tolerances,
    branch: &mut Branch,
    (t_start, t_new): (f64, f64),
    (y, f0): (&mut [f64; M], &mut [f64; M]),
    (times, next, sink): (&[f64], &mut usize, &mut Sink<'_>),
    stats: &mut IntegrationStats,
) -> Result<()> {
    let mut t = t_start;
    let mut f1 = [0.0; M];
    let mut redone = false;
    for sub in 0.. {
        let h = t_new - t;
        let err = stepper.attempt(rhs, t, y, f0, h, tol)?;
        if !err.is_finite() {
            return Err(integration_error(
                t,
                &rhs.expand(y),
                "non-finite state on a fixed step",
            ));
        }
        stepper.new_derivative(rhs, t_new, &mut f1)?;
        let y1 = *stepper.y1();
        let event = branch.first_switch(
            stepper,
            rhs,
            (t, y, f0),
            (t_new, &y1, &f1),
            h,
            sub < MAX_EVENTS_PER_STEP,
            events::GRID_ROOT_TOLERANCE,
            stats,
        )?;
        if let Some(found) = &event {
            if found.at_start && !redone {
                // The step began on the wrong branch (a root at its start): redo it on
                // the far side.
                redone = true;
                branch.take(rhs, found.sides, t, y, f0)?;
                continue;
            }
        }
        if err > 1.0 {
            stats.over_tolerance += 1;
        }
        stats.accepted += 1;
        let (_, cut) = branch.advance(
            stepper,
            rhs,
            (&mut t, y, f0),
            (t_new, &y1, &mut f1),
            h,
            event,
            (times, next, sink),
            stats,
        )?;
        if !cut {
            break;
        }
        // Cut at a root: the rest of the grid step on the new branch.
        redone = false;
    }
    Ok(())
}
