//! The compact right-hand side ([`Rhs`]) and embedded pair ([`Stepper`]) the loops drive, and
//! the sampling of an accepted step's dense output.

use paritysim_error::Result;

use super::{IntegrationStats, MAX_SWITCHES, Sides, Sink, State, integration_error};

/// Tolerances of the error norm; entries `controlled..` (the work integrals) are not measured.
pub(crate) struct Tolerances {
    pub(crate) rtol: f64,
    pub(crate) atol: f64,
    pub(crate) controlled: usize,
}

/// A compact right-hand side `ẏ = f(t, y)` on `M` entries.
pub(crate) trait Rhs<const M: usize> {
    fn eval(&mut self, t: f64, y: &[f64; M], dydt: &mut [f64; M]) -> Result<()>;
    /// The full state of a compact one.
    fn expand(&self, c: &[f64; M]) -> State;
    /// Number of switching functions (0: a smooth right-hand side, no event location).
    fn n_switches(&self) -> usize {
        0
    }
    /// Writes the switching functions `g(t, y)` into `g[..n_switches]`.
    fn switches(&mut self, _t: f64, _y: &[f64; M], _g: &mut [f64; MAX_SWITCHES]) -> Result<()> {
        Ok(())
    }
    /// The branch the following evaluations take.
    fn set_sides(&mut self, _sides: Sides) {}
    /// Sees the whole integrated vector of each sample before the sink gets its state (the
    /// variational equations' `Φ` at the recorded times); nothing by default.
    fn observe_sample(&mut self, _c: &[f64; M]) {}
}

/// Hands sample `i` (the integrated vector `c`, expanded to `state`) to
/// [`Rhs::observe_sample`], then to `sink`.
pub(super) fn emit<const M: usize>(
    rhs: &mut dyn Rhs<M>,
    sink: &mut Sink<'_>,
    (i, t): (usize, f64),
    c: &[f64; M],
    state: &State,
) -> Result<()> {
    rhs.observe_sample(c);
    sink(i, t, state)
}

/// An explicit embedded pair with dense output.
pub(crate) trait Stepper<const M: usize> {
    /// Order used by the initial step-size guess.
    const ORDER: i32;
    /// Exponent of the error in the step-size factor (Hairer's `EXPO1`).
    const EXPONENT: f64;
    /// Lund stabilisation (PI control) exponent on the previous error.
    const BETA: f64;
    /// Smallest and largest step-size ratio `h_new / h`.
    const FAC_MIN: f64;
    /// See [`Self::FAC_MIN`].
    const FAC_MAX: f64;

    /// One trial step of size `h` from `(t, y)` with `f0 = f(t, y)`; returns the scaled error
    /// (accept when ≤ 1) and keeps the stages.
    fn attempt(
        &mut self,
        rhs: &mut dyn Rhs<M>,
        t: f64,
        y: &[f64; M],
        f0: &[f64; M],
        h: f64,
        tol: &Tolerances,
    ) -> Result<f64>;
    /// The new state of the last trial step.
    fn y1(&self) -> &[f64; M];
    /// `f(t_new, y1)` after an accepted step.
    fn new_derivative(&mut self, rhs: &mut dyn Rhs<M>, t_new: f64, f1: &mut [f64; M])
    -> Result<()>;
    /// Prepares the interpolant of the accepted step `[t, t + h]`.
    fn prepare_dense(
        &mut self,
        rhs: &mut dyn Rhs<M>,
        t: f64,
        y: &[f64; M],
        f0: &[f64; M],
        f1: &[f64; M],
        h: f64,
    ) -> Result<()>;
    /// The interpolant at `t + s h`.
    fn dense(&self, s: f64, out: &mut [f64; M]);
}

/// Emits the samples that fall inside the accepted step `[t, t_stop)` (`t_stop <= t + h`) from
/// its interpolant (prepared here, unless `dense_ready`, only when one does), then those at
/// `t_stop` from `y_stop`, the step's value there.
#[allow(clippy::too_many_arguments)]
pub(super) fn sample_step<const M: usize, S: Stepper<M>>(
    stepper: &mut S,
    rhs: &mut dyn Rhs<M>,
    t: f64,
    y: &[f64; M],
    f0: &[f64; M],
    f1: &[f64; M],
    h: f64,
    (t_stop, y_stop): (f64, &[f64; M]),
    dense_ready: bool,
    times: &[f64],
    next: &mut usize,
    sink: &mut Sink<'_>,
    stats: &mut IntegrationStats,
) -> Result<State> {
    if *next < times.len() && times[*next] < t_stop {
        if !dense_ready {
            stepper.prepare_dense(rhs, t, y, f0, f1, h)?;
            stats.dense_steps += 1;
        }
        let mut sample = [0.0; M];
        while *next < times.len() && times[*next] < t_stop {
            stepper.dense((times[*next] - t) / h, &mut sample);
            let state = rhs.expand(&sample);
            if !state.is_finite() {
                return Err(integration_error(times[*next], &state, "non-finite state"));
            }
            emit(rhs, sink, (*next, times[*next]), &sample, &state)?;
            *next += 1;
        }
    }
    let state = rhs.expand(y_stop);
    if !state.is_finite() {
        return Err(integration_error(t_stop, &state, "non-finite state"));
    }
    while *next < times.len() && times[*next] <= t_stop {
        emit(rhs, sink, (*next, times[*next]), y_stop, &state)?;
        *next += 1;
    }
    Ok(state)
}
