//! The shooting machine: Newton on the frozen-grid period map as a state machine that asks
//! for one period at a time ([`Request`]) and is told how it ended ([`Reply`]).
//!
//! Written once, run by two executors: the scalar one ([`super::grid::shoot`]) integrates each
//! request at once; the SIMD-lane scheduler (`crate::lanes`) integrates the requests of four
//! points side by side. Both therefore take the same Newton steps, Broyden updates,
//! re-linearisations, re-picks and acceptance decisions (the caller drives the step, as
//! MuJoCo's `mj_step1`/`mj_step2` or diffsol's `step()`).

use std::rc::Rc;

use nalgebra::{DMatrix, DVector};

use super::newton::{Trial, broyden_update, least_squares_step, residual, trial};
use crate::integrate::State;

/// The period the machine needs integrated next, from the start state `y` on the machine's
/// grid ([`GridNewton::grid`]).
#[derive(Clone, Debug)]
pub(crate) enum Request {
    /// One fixed-grid period of the map (no error control); `last`: the final, recorded one.
    Trial { y: State, last: bool },
    /// One fixed-grid period with the variational equations: the exact Jacobian at `y`.
    Linearise { y: State },
    /// One adaptive period at the grid tolerances that picks a new grid.
    Pick { y: State },
}

/// How a requested period ended.
#[derive(Clone, Debug)]
pub(crate) enum Reply {
    /// A trial's end state `P(y)`, with the map's exact Jacobian at `y` when the (recorded)
    /// period integrated the variational equations.
    Mapped(State, Option<DMatrix<f64>>),
    /// The Jacobian of a [`Request::Linearise`].
    Linearised(DMatrix<f64>),
    /// A [`Request::Pick`]'s end state and the steps it took (the new grid).
    Picked(State, Vec<f64>),
    /// The period failed (the model's domain left, a step limit): Newton gives up.
    Failed,
}

/// What the machine says after a reply.
#[derive(Clone, Debug)]
pub(crate) enum Verdict {
    /// Integrate this period next.
    Run(Request),
    /// The orbit: accepted after its last (recorded) trial.
    Converged(Accepted),
    /// No convergence within the Newton limit, a singular step, a failed period, or an exact
    /// Jacobian that no longer descends: the caller's fallback takes over.
    GaveUp,
}

/// An accepted orbit.
#[derive(Clone, Debug)]
pub(crate) struct Accepted {
    /// The state on the section (the last trial's start).
    pub(crate) state: State,
    /// `‖P(y) − y‖∞ / (1 + ‖y‖∞)` of the last trial.
    pub(crate) residual: f64,
    /// Whether the Jacobian is the exact derivative of the map at `state` (the last trial
    /// integrated the variational equations).
    pub(crate) jacobian_at_orbit: bool,
    /// The contraction Newton's model predicted for the last step.
    pub(crate) contraction: f64,
}

/// What the machine waits for.
#[derive(Clone, Debug)]
enum Pending {
    Trial {
        y_new: State,
        delta: DVector<f64>,
        step: f64,
        contraction: f64,
        last: bool,
    },
    /// A re-linearisation; then the iterate becomes `candidate` `(y, f, residual)` when given.
    Linearise {
        candidate: Option<(State, DVector<f64>, f64)>,
    },
    /// The grid picked again at the converged `y_new`.
    Repick {
        y_new: State,
    },
    Nothing,
}

/// Newton's state on the frozen-grid map of `n` coordinates (see the module).
#[derive(Clone, Debug)]
pub(crate) struct GridNewton {
    n: usize,
    /// The current iterate, its residual vector and norm.
    y: State,
    f: DVector<f64>,
    res: f64,
    /// The Jacobian model of the map, and whether it is exact at `y`.
    pub(crate) jacobian: DMatrix<f64>,
    fresh: bool,
    eye: DMatrix<f64>,
    /// The step grid of the map.
    pub(crate) grid: Rc<[f64]>,
    /// Whether the grid was picked far from the orbit and is to be picked again once Newton
    /// converges on it ([`super::newton::REPICK_RESIDUAL`]).
    repick: bool,
    last_step: Option<f64>,
    /// The contraction a guessed Jacobian achieved in its own pass (predicts the first error).
    guess_contraction: Option<f64>,
    /// Newton steps taken, and periods integrated (the first map included).
    pub(crate) iterations: usize,
    pub(crate) periods: usize,
    tol: f64,
    accept_tol: f64,
    max_newton: usize,
    pending: Pending,
}

/// The machine's tolerances: Newton's (`tol`, [`super::newton::newton_tolerance`]), the
/// residual a neutral orbit is accepted at (`accept_tol`, the run's `steady_tol`) and the
/// Newton limit.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Limits {
    pub(crate) tol: f64,
    pub(crate) accept_tol: f64,
    pub(crate) max_newton: usize,
}

/// Where Newton starts: the iterate `y`, its first map `P(y)` on `grid`, the Jacobian model
/// (`exact` when it is the variational equations' at `y`), whether `grid` was picked here
/// from `y` (then it is picked again if `y` was far from the orbit) and the contraction a
/// guessed Jacobian achieved before.
pub(crate) struct Start {
    pub(crate) y: State,
    pub(crate) mapped: State,
    pub(crate) jacobian: DMatrix<f64>,
    pub(crate) exact: bool,
    pub(crate) grid: Rc<[f64]>,
    pub(crate) picked_here: bool,
    pub(crate) guess_contraction: Option<f64>,
}

impl GridNewton {
    /// The machine on `n` coordinates from `start`, and its first request.
    pub(crate) fn start(n: usize, start: Start, limits: Limits) -> (Self, Verdict) {
        let m = 2 * n;
        let (f, res) = residual(n, &start.y, &start.mapped);
        let mut machine = Self {
            n,
            y: start.y,
            f,
            res,
            jacobian: start.jacobian,
            fresh: start.exact,
            eye: DMatrix::identity(m, m),
            grid: start.grid,
            repick: start.picked_here && res > super::newton::REPICK_RESIDUAL,
            last_step: None,
            guess_contraction: start.guess_contraction,
            iterations: 0,
            periods: 1,
            tol: limits.tol,
            accept_tol: limits.accept_tol,
            max_newton: limits.max_newton,
            pending: Pending::Nothing,
        };
        let verdict = machine.iterate();
        (machine, verdict)
    }

    /// The next Newton trial from the current iterate.
    fn iterate(&mut self) -> Verdict {
        if self.iterations >= self.max_newton {
            return Verdict::GaveUp;
        }
        self.iterations += 1;
        let Some(Trial {
            delta,
            step,
            contraction,
            y_new,
            last,
        }) = trial(
            self.n,
            &self.y,
            (&self.jacobian, &self.eye, &self.f),
            (self.last_step, self.fresh, self.guess_contraction),
            self.tol,
        )
        else {
            return Verdict::GaveUp;
        };
        if last && self.repick {
            // Converged on a grid picked far from the orbit: the grid again, from here;
            // Newton goes on on it with the Jacobian it has.
            self.repick = false;
            self.pending = Pending::Repick { y_new };
            return Verdict::Run(Request::Pick { y: y_new });
        }
        self.pending = Pending::Trial {
            y_new,
            delta,
            step,
            contraction,
            last,
        };
        Verdict::Run(Request::Trial { y: y_new, last })
    }

    /// Re-linearise at `at` on the grid; then `candidate` becomes the iterate when given.
    fn linearise(&mut self, at: State, candidate: Option<(State, DVector<f64>, f64)>) -> Verdict {
        self.pending = Pending::Linearise { candidate };
        Verdict::Run(Request::Linearise { y: at })
    }

    /// Continues after the requested period ended with `reply`.
    pub(crate) fn resume(&mut self, reply: Reply) -> Verdict {
        match (
            std::mem::replace(&mut self.pending, Pending::Nothing),
            reply,
        ) {
            (_, Reply::Failed) | (Pending::Nothing, _) => Verdict::GaveUp,
            (Pending::Repick { y_new }, Reply::Picked(mapped, grid)) => {
                self.periods += 1;
                self.grid = grid.into();
                (self.f, self.res) = residual(self.n, &y_new, &mapped);
                self.y = y_new;
                self.iterate()
            }
            (Pending::Linearise { candidate }, Reply::Linearised(jacobian)) => {
                self.jacobian = jacobian;
                self.periods += 1;
                self.fresh = true;
                self.last_step = None;
                if let Some((y, f, res)) = candidate {
                    (self.y, self.f, self.res) = (y, f, res);
                }
                self.iterate()
            }
            (
                Pending::Trial {
                    y_new,
                    delta,
                    step,
                    contraction,
                    last,
                },
                Reply::Mapped(mapped, exact),
            ) => self.after_trial((y_new, delta, step, contraction, last), &mapped, exact),
            // A reply of another kind than the request.
            _ => Verdict::GaveUp,
        }
    }

    /// The rest of Newton's loop after a trial from `y_new` mapped to `mapped`.
    fn after_trial(
        &mut self,
        (y_new, delta, step, contraction, last): (State, DVector<f64>, f64, f64, bool),
        mapped: &State,
        exact: Option<DMatrix<f64>>,
    ) -> Verdict {
        self.periods += 1;
        let n = self.n;
        let (f_new, res_new) = residual(n, &y_new, mapped);
        let exact = exact.filter(|j| j.shape() == (2 * n, 2 * n));
        let at_orbit = exact.is_some();
        if let Some(j) = exact {
            // The final period's own variational equations: the exact Jacobian at `y_new`.
            self.jacobian = j;
            self.fresh = true;
            self.last_step = None;
        }
        let tol = self.tol;
        if last && res_new > tol && res_new <= self.accept_tol && !self.fresh {
            // Re-linearise at the candidate, then decide with the exact Jacobian.
            return self.linearise(y_new, Some((y_new, f_new, res_new)));
        }
        // Only an exact Jacobian tells a neutral direction from a stale model's small step
        // (measured: a neighbour's Broyden-updated Jacobian accepted a residual of 2.5e-9
        // with the state 4e-7 off the orbit).
        let neutral = || {
            res_new <= self.accept_tol
                && least_squares_step(&self.jacobian - &self.eye, &f_new)
                    .is_some_and(|d| d.amax() / (1.0 + y_new.compact(n).amax()) <= tol)
        };
        if last && (res_new <= tol || neutral()) {
            return Verdict::Converged(Accepted {
                state: y_new,
                residual: res_new,
                jacobian_at_orbit: at_orbit,
                contraction,
            });
        }
        if at_orbit {
            // Not accepted, but linearised at `y_new`: Newton goes on from there.
            (self.y, self.f, self.res) = (y_new, f_new, res_new);
            return self.iterate();
        }
        if res_new >= self.res || res_new.is_nan() {
            if self.fresh {
                return Verdict::GaveUp;
            }
            // A stale (neighbour's or updated) Jacobian that no longer descends: the exact
            // one at the current iterate, on the same grid.
            return self.linearise(self.y, None);
        }
        broyden_update(&mut self.jacobian, &self.eye, &delta, (&self.f, &f_new));
        self.fresh = false;
        (self.y, self.f, self.res) = (y_new, f_new, res_new);
        self.last_step = Some(step);
        self.iterate()
    }
}
