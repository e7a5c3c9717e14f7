//! What is integrated ([`OdeSystem`]) and what integrates it ([`Integrator`]).

use paritysim_error::Result;

use super::{MAX_DOF, MAX_SWITCHES, Sides, State};

/// A first-order system `ẏ = f(t, y)` whose evaluation can fail.
pub trait OdeSystem {
    /// Writes `f(t, y)` into `dydt` (coordinates' derivative in `coords`, rates' derivative
    /// in `rates`, powers in the work fields).
    ///
    /// # Errors
    /// Any model error; the integrator reports it with the time and state.
    fn rhs(&self, t: f64, y: &State, dydt: &mut State) -> Result<()>;

    /// Number of active coordinates `n` (the rest of `coords` and `rates` stays zero).
    fn n_active(&self) -> usize {
        MAX_DOF
    }

    /// Number of switching functions (at most [`MAX_SWITCHES`]; 0, the default: smooth). With
    /// switching functions the adaptive integrator locates their roots and holds the branch
    /// between them ([`Self::rhs_on`]; the module `events`); fixed-grid runs do too, cutting
    /// a grid step at a root inside it.
    fn n_switches(&self) -> usize {
        0
    }

    /// Writes the switching functions `g(t, y)` into `g[..n_switches]`.
    ///
    /// # Errors
    /// Any model error.
    fn switches(&self, _t: f64, _y: &State, _g: &mut [f64; MAX_SWITCHES]) -> Result<()> {
        Ok(())
    }

    /// [`Self::rhs`] on the smooth branch `sides` names (also slightly past its surface).
    ///
    /// # Errors
    /// As [`Self::rhs`].
    fn rhs_on(&self, t: f64, y: &State, _sides: Sides, dydt: &mut State) -> Result<()> {
        self.rhs(t, y, dydt)
    }

    /// [`Self::rhs_on`] of several states at once (e.g. in SIMD lanes: the central
    /// differences of the variational equations evaluate `2n` of them per stage); `None`
    /// (the default) when the system has no such form, and the caller evaluates them one by
    /// one. Each result must be [`Self::rhs_on`]'s bit for bit; a failure names the first
    /// failing state (its index) with [`Self::rhs_on`]'s error.
    fn rhs_on_batch(
        &self,
        _t: f64,
        _sides: Sides,
        _ys: &[State],
        _out: &mut [State],
    ) -> Option<std::result::Result<(), (usize, paritysim_error::Error)>> {
        None
    }

    /// The variational equations' right-hand side `dphi = J(t, y) phi` from an analytic
    /// Jacobian `J = ∂f/∂y` of the `2n` entries `[coords (n), rates (n)]`, `phi` and `dphi`
    /// `2n × 2n` by columns; `None` (the default) when the system has none for this `n`: the
    /// variational equations then form `J phi` by central differences of [`Self::rhs`].
    ///
    /// # Errors
    /// Any model error (as [`Self::rhs`]).
    fn variational(
        &self,
        _t: f64,
        _y: &State,
        _n: usize,
        _phi: &[f64],
        _dphi: &mut [f64],
    ) -> Option<Result<()>> {
        None
    }

    /// The right-hand side `f = [coords', rates']` (`2n` entries) at `(t, y)` and the
    /// variational equations' `dphi = J phi` in one evaluation, on the branch `sides` held
    /// by event location (`None`: the state's own sides; `f` as [`Self::rhs_on`] /
    /// [`Self::rhs`] give it); `None` (the default) when the system has no such form here:
    /// the variational equations then call [`Self::rhs_on`] and [`Self::variational`].
    ///
    /// # Errors
    /// Any model error (as [`Self::rhs`]).
    #[allow(clippy::too_many_arguments)]
    fn variational_with_rhs(
        &self,
        _t: f64,
        _y: &State,
        _sides: Option<Sides>,
        _n: usize,
        _f: &mut [f64],
        _phi: &[f64],
        _dphi: &mut [f64],
    ) -> Option<Result<()>> {
        None
    }
}

/// Explicit Runge-Kutta pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Method {
    /// Dormand-Prince 8(5,3) (the default).
    #[default]
    Dop853,
    /// Dormand-Prince 5(4).
    Dopri5,
}

/// Counters of one integration.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct IntegrationStats {
    /// Right-hand side evaluations.
    pub rhs_calls: usize,
    /// Accepted steps.
    pub accepted: usize,
    /// Rejected steps.
    pub rejected: usize,
    /// Accepted steps on which the dense output was prepared (a sample fell inside).
    pub dense_steps: usize,
    /// Fixed-grid steps whose local error estimate exceeded the tolerances (always 0 for
    /// adaptive runs, which reject such steps): 0 means the grid still suits the solution.
    pub over_tolerance: usize,
    /// Accepted steps cut short at a root of a switching function (see [`ArraySystem`](super::ArraySystem)).
    pub events: usize,
}

/// Receives the samples of an integration: `(index in times, time, state)`.
pub type Sink<'a> = dyn FnMut(usize, f64, &State) -> Result<()> + 'a;

/// Integrates an [`OdeSystem`] and samples it at requested times.
pub trait Integrator: Send + Sync {
    /// Integrates from `(t0, y0)` to `t_end`, calls `sink` at each of `times` (sorted, within
    /// `[t0, t_end]`) in order, and returns the state at `t_end`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`](paritysim_error::Error::InvalidParameter) for `t_end <= t0` or times out of order or range;
    /// [`Error::Integration`](paritysim_error::Error::Integration) carrying the time and state of the failure (step-size underflow,
    /// step limit, non-finite state, a model error raised inside the right-hand side, or the
    /// wall-time budget of the thread's [`budget::Budget`](super::budget::Budget)); [`Error::Cancelled`](paritysim_error::Error::Cancelled) when the
    /// budget's cancel flag is set; whatever `sink` returns.
    fn integrate_with(
        &self,
        system: &dyn OdeSystem,
        t0: f64,
        y0: &State,
        t_end: f64,
        times: &[f64],
        sink: &mut Sink<'_>,
    ) -> Result<State>;

    /// [`Self::integrate_with`] collecting the samples.
    ///
    /// # Errors
    /// As [`Self::integrate_with`].
    fn integrate(
        &self,
        system: &dyn OdeSystem,
        t0: f64,
        y0: &State,
        t_end: f64,
        times: &[f64],
    ) -> Result<Vec<State>> {
        let mut out = Vec::with_capacity(times.len());
        self.integrate_with(system, t0, y0, t_end, times, &mut |_, _, y| {
            out.push(*y);
            Ok(())
        })?;
        Ok(out)
    }

    /// The state at `t_end` (no samples).
    ///
    /// # Errors
    /// As [`Self::integrate_with`].
    fn advance(&self, system: &dyn OdeSystem, t0: f64, y0: &State, t_end: f64) -> Result<State> {
        self.integrate_with(system, t0, y0, t_end, &[], &mut |_, _, _| Ok(()))
    }
}
