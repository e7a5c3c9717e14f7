//! Steps of a piecewise-smooth right-hand side, shared by the adaptive loop (`adaptive.rs`) and
//! fixed grids (`fixed_grid.rs`): find the first switch inside a computed step (module
//! `events`), then either finish the step or cut it at the root and go on from there on the new
//! branch. Without switching functions ([`Branch::n`] = 0) only [`Branch::advance`] applies.

use paritysim_error::Result;

use super::events::{self, Event};
use super::{IntegrationStats, MAX_SWITCHES, Rhs, Sides, Sink, State, Stepper, sample_step};

/// The branch an integration holds, and its switching functions at the current step's ends.
pub(super) struct Branch {
    /// Number of switching functions (0: a smooth right-hand side).
    pub(super) n: usize,
    sides: Sides,
    g0: [f64; MAX_SWITCHES],
    g1: [f64; MAX_SWITCHES],
}

impl Branch {
    /// The sides of the `n` switching functions at the integration's start `(t, y)`, passed on
    /// to `rhs`.
    ///
    /// # Errors
    /// A failing switching function.
    pub(super) fn start<const M: usize>(
        rhs: &mut dyn Rhs<M>,
        n: usize,
        t: f64,
        y: &[f64; M],
    ) -> Result<Self> {
        let mut branch = Self {
            n,
            sides: Sides::default(),
            g0: [0.0; MAX_SWITCHES],
            g1: [0.0; MAX_SWITCHES],
        };
        if n > 0 {
            rhs.switches(t, y, &mut branch.g0)?;
            branch.sides = Sides::of(&branch.g0[..n]);
            rhs.set_sides(branch.sides);
        }
        Ok(branch)
    }

    /// The first switch inside the computed step `[t, t_new]` (size `h`) from `(y, f0)` to `(y1, f1)`,
    /// located on its dense output (prepared here) to `root_tolerance × h`; `None` when no
    /// switching function ends across the held sides, or when `search` is false.
    ///
    /// # Errors
    /// A failing switching function or right-hand side.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn first_switch<const M: usize, S: Stepper<M>>(
        &mut self,
        stepper: &mut S,
        rhs: &mut dyn Rhs<M>,
        (t, y, f0): (f64, &[f64; M], &[f64; M]),
        (t_new, y1, f1): (f64, &[f64; M], &[f64; M]),
        h: f64,
        search: bool,
        root_tolerance: f64,
        stats: &mut IntegrationStats,
    ) -> Result<Option<Event<M>>> {
        rhs.switches(t_new, y1, &mut self.g1)?;
        if !(search && (0..self.n).any(|i| events::crossed(self.sides, i, self.g1[i]))) {
            return Ok(None);
        }
        stepper.prepare_dense(rhs, t, y, f0, f1, h)?;
        stats.dense_steps += 1;
        events::locate(
            stepper,
            rhs,
            self.n,
            self.sides,
            t,
            h,
            &self.g0,
            &self.g1,
            root_tolerance,
        )
        .map(Some)
    }

    /// Takes `sides` at `(t, y)` and re-evaluates `f` there on them.
    ///
    /// # Errors
    /// A failing right-hand side.
    pub(super) fn take<const M: usize>(
        &mut self,
        rhs: &mut dyn Rhs<M>,
        sides: Sides,
        t: f64,
        y: &[f64; M],
        f: &mut [f64; M],
    ) -> Result<()> {
        self.sides = sides;
        rhs.set_sides(sides);
        rhs.eval(t, y, f)
    }

    /// Samples the accepted step `[t, t + h]` (ending at `(t_new, y1, f1)`) and moves
    /// `(t, y, f0)` to where it ends: the root of `event` inside it, with the new branch taken
    /// (returns `true`), or the step's end (`false`; a grazing switch there hands over its
    /// sides). Also returns the state there.
    ///
    /// # Errors
    /// A non-finite state, a failing right-hand side, or whatever `sink` returns.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn advance<const M: usize, S: Stepper<M>>(
        &mut self,
        stepper: &mut S,
        rhs: &mut dyn Rhs<M>,
        (t, y, f0): (&mut f64, &mut [f64; M], &mut [f64; M]),
        (t_new, y1, f1): (f64, &[f64; M], &mut [f64; M]),
        h: f64,
        event: Option<Event<M>>,
        (times, next, sink): (&[f64], &mut usize, &mut Sink<'_>),
        stats: &mut IntegrationStats,
    ) -> Result<(State, bool)> {
        match event {
            Some(ev) if !ev.at_start && ev.t < t_new => {
                // Cut at the root; go on from there on the new branch.
                let state = sample_step(
                    stepper,
                    rhs,
                    *t,
                    y,
                    f0,
                    f1,
                    h,
                    (ev.t, &ev.y),
                    true,
                    times,
                    next,
                    sink,
                    stats,
                )?;
                stats.events += 1;
                (*y, *t, self.g0) = (ev.y, ev.t, ev.g);
                self.take(rhs, ev.sides, *t, y, f0)?;
                Ok((state, true))
            }
            other => {
                let state = sample_step(
                    stepper,
                    rhs,
                    *t,
                    y,
                    f0,
                    f1,
                    h,
                    (t_new, y1),
                    other.is_some(),
                    times,
                    next,
                    sink,
                    stats,
                )?;
                if let Some(ev) = other {
                    // Not bracketed (grazing) or at the end: go on from the end's sides.
                    self.take(rhs, ev.sides, t_new, y1, f1)?;
                }
                (*y, *f0, self.g0, *t) = (*y1, *f1, self.g1, t_new);
                Ok((state, false))
            }
        }
    }
}
