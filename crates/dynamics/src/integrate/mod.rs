//! Our own Dormand–Prince integrators (DOP853 and DOPRI5 with Hairer's dense output and step
//! control), sampling the solution at requested times through a callback.
//!
//! * The integrator works on a compact array of `2n` entries (`n` coordinates, `n` rates) and,
//!   only when asked for, the two work integrals. The work integrals ride along on the same
//!   stages but take no part in the error control (they never shorten a step).
//! * Dense output is prepared only on steps where a sample falls (DOP853's three extra stages
//!   are not computed on the other steps); a sample at a step's end is the step's value.
//! * `differential-equations` 0.7.0 is kept as a dev-dependency to cross-check steps; its
//!   DOP853 interpolant is O(h⁵) (see docs/findings.md), ours is Hairer's CONTD8.

pub mod budget;
mod dop853;
mod dopri5;
mod events;
#[cfg(test)]
mod tests;
mod variational;

/// DOP853 on fixed grids for several problems in SIMD lanes.
pub(crate) use dop853::lanes;

use paritysim_error::{Error, Result, check_positive};

pub(crate) use events::WithoutEvents;
pub use events::{MAX_SWITCHES, Sides};

/// Largest number of integrated coordinates.
pub const MAX_DOF: usize = 6;

/// Checks an integration window: finite `t0 < t_end`, sample `times` sorted within it.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `t_end` or `times[i]`.
fn check_window(t0: f64, t_end: f64, times: &[f64]) -> Result<()> {
    if t_end.is_nan() || t_end <= t0 || !t0.is_finite() || !t_end.is_finite() {
        return Err(Error::invalid("t_end", t_end, format!("> t0 = {t0}")));
    }
    if let Some(i) = (0..times.len())
        .find(|&i| !(times[i] >= t0 && times[i] <= t_end) || (i > 0 && times[i] < times[i - 1]))
    {
        return Err(Error::invalid(
            format!("times[{i}]"),
            times[i],
            format!("sorted and within [{t0}, {t_end}]"),
        ));
    }
    Ok(())
}

/// Integrator state: integrated coordinates and their rates (entries past the system's
/// [`OdeSystem::n_active`] stay zero) and the two work integrals.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct State {
    /// Integrated coordinates (null-space coordinates `x`, drivetrain coordinates `q`, or `p`).
    pub coords: [f64; MAX_DOF],
    /// Their rates.
    pub rates: [f64; MAX_DOF],
    /// Actuator work `∫ F q̇1 dt` (µJ); integrated only when asked for.
    pub work_actuator: f64,
    /// Aerodynamic work `∫ τ_aero · ṗ dt` (µJ); integrated only when asked for.
    pub work_aero: f64,
}

impl State {
    /// The state as a flat list `[coords, rates, work_actuator, work_aero]` (error reports).
    pub fn to_vec(&self) -> Vec<f64> {
        let mut v = Vec::with_capacity(2 * MAX_DOF + 2);
        v.extend_from_slice(&self.coords);
        v.extend_from_slice(&self.rates);
        v.push(self.work_actuator);
        v.push(self.work_aero);
        v
    }

    /// Whether every entry is finite.
    pub fn is_finite(&self) -> bool {
        self.coords.iter().chain(&self.rates).all(|v| v.is_finite())
            && self.work_actuator.is_finite()
            && self.work_aero.is_finite()
    }

    /// The first `n` coordinates and rates as one vector `[coords, rates]` (shooting).
    pub fn compact(&self, n: usize) -> nalgebra::DVector<f64> {
        nalgebra::DVector::from_fn(2 * n, |i, _| {
            if i < n {
                self.coords[i]
            } else {
                self.rates[i - n]
            }
        })
    }

    /// The state of a [`Self::compact`] vector (work integrals zero).
    pub fn from_compact(n: usize, v: &nalgebra::DVector<f64>) -> Self {
        let mut y = Self::default();
        for i in 0..n {
            y.coords[i] = v[i];
            y.rates[i] = v[n + i];
        }
        y
    }

    /// The state with both work integrals set to zero.
    pub fn without_work(mut self) -> Self {
        self.work_actuator = 0.0;
        self.work_aero = 0.0;
        self
    }
}

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
    /// Accepted steps cut short at a root of a switching function (see [`ArraySystem`]).
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
    /// [`Error::InvalidParameter`] for `t_end <= t0` or times out of order or range;
    /// [`Error::Integration`] carrying the time and state of the failure (step-size underflow,
    /// step limit, non-finite state, a model error raised inside the right-hand side, or the
    /// wall-time budget of the thread's [`budget::Budget`]); [`Error::Cancelled`] when the
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

/// Adaptive Dormand–Prince integrator with relative and absolute tolerances.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RungeKutta {
    method: Method,
    rtol: f64,
    atol: f64,
    max_steps: usize,
    work: bool,
}

impl RungeKutta {
    /// `rtol`, `atol` in (0, 1); `max_steps` > 0 per call. Work integrals are integrated
    /// (see [`Self::with_work`]).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the bad field.
    pub fn new(method: Method, rtol: f64, atol: f64, max_steps: usize) -> Result<Self> {
        for (name, v) in [("rtol", rtol), ("atol", atol)] {
            check_positive(name, v)?;
            if v >= 1.0 {
                return Err(Error::invalid(name, v, "in (0, 1)"));
            }
        }
        if max_steps == 0 {
            return Err(Error::invalid("max_steps", 0, "> 0"));
        }
        Ok(Self {
            method,
            rtol,
            atol,
            max_steps,
            work: true,
        })
    }

    /// Whether the work integrals are integrated (otherwise they stay at their initial values;
    /// they never take part in the error control).
    pub fn with_work(mut self, work: bool) -> Self {
        self.work = work;
        self
    }

    /// The same integrator with both tolerances scaled by `factor` (in (0, 1]).
    pub fn tightened(mut self, factor: f64) -> Self {
        let factor = factor.clamp(f64::MIN_POSITIVE, 1.0);
        self.rtol *= factor;
        self.atol *= factor;
        self
    }

    /// The same integrator with `rtol` and `atol` multiplied by `factor >= 1`, `rtol` at most
    /// 1e-3 (a loose pass whose accuracy does not matter, e.g. a warm-up).
    pub(crate) fn loosened(mut self, factor: f64) -> Self {
        let factor = factor.max(1.0).min(1e-3 / self.rtol).max(1.0);
        self.rtol *= factor;
        self.atol *= factor;
        self
    }

    /// The method.
    pub fn method(&self) -> Method {
        self.method
    }

    /// [`Integrator::integrate_with`] that also returns the step counters.
    ///
    /// # Errors
    /// As [`Integrator::integrate_with`].
    pub fn integrate_counted(
        &self,
        system: &dyn OdeSystem,
        t0: f64,
        y0: &State,
        t_end: f64,
        times: &[f64],
        sink: &mut Sink<'_>,
    ) -> Result<(State, IntegrationStats)> {
        self.dispatch(system, t0, y0, t_end, None, times, sink, &mut |_, _| {})
    }

    /// The state at `t_end` and the times of the accepted steps (ending with `t_end`): the grid
    /// [`Self::integrate_on_grid`] retraces.
    ///
    /// # Errors
    /// As [`Integrator::integrate_with`].
    pub fn advance_with_steps(
        &self,
        system: &dyn OdeSystem,
        t0: f64,
        y0: &State,
        t_end: f64,
    ) -> Result<(State, Vec<f64>)> {
        let mut grid = vec![t0];
        let (y, _) = self.dispatch(
            system,
            t0,
            y0,
            t_end,
            None,
            &[],
            &mut |_, _, _| Ok(()),
            &mut |t, _| grid.push(t),
        )?;
        Ok((y, grid))
    }

    /// Integrates on the fixed steps between consecutive `grid` times (no error control, no
    /// rejected step: e.g. the grid an adaptive run chose, see [`Self::advance_with_steps`]),
    /// sampling `times` (within the grid's span) through `sink`. On a fixed grid the flow is a
    /// smooth function of `y0`: Newton on it converges to round-off.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a grid that is not increasing or has fewer than two
    /// times, or samples outside it; otherwise as [`Integrator::integrate_with`].
    pub fn integrate_on_grid(
        &self,
        system: &dyn OdeSystem,
        grid: &[f64],
        y0: &State,
        times: &[f64],
        sink: &mut Sink<'_>,
    ) -> Result<State> {
        self.integrate_on_grid_counted(system, grid, y0, times, sink)
            .map(|(y, _)| y)
    }

    /// [`Self::integrate_on_grid`] with the step counters; `over_tolerance` counts the steps
    /// whose local error estimate exceeds this integrator's tolerances.
    ///
    /// # Errors
    /// As [`Self::integrate_on_grid`].
    pub fn integrate_on_grid_counted(
        &self,
        system: &dyn OdeSystem,
        grid: &[f64],
        y0: &State,
        times: &[f64],
        sink: &mut Sink<'_>,
    ) -> Result<(State, IntegrationStats)> {
        check_grid(grid)?;
        let (t0, t_end) = (grid[0], grid[grid.len() - 1]);
        self.dispatch(
            system,
            t0,
            y0,
            t_end,
            Some(grid),
            times,
            sink,
            &mut |_, _| {},
        )
    }

    /// Checks the interval and samples, then runs [`Self::solve`] on the array size of the
    /// system (adaptive, or on `grid`).
    #[allow(clippy::too_many_arguments)]
    fn dispatch(
        &self,
        system: &dyn OdeSystem,
        t0: f64,
        y0: &State,
        t_end: f64,
        grid: Option<&[f64]>,
        times: &[f64],
        sink: &mut Sink<'_>,
        on_step: &mut dyn FnMut(f64, &State),
    ) -> Result<(State, IntegrationStats)> {
        check_window(t0, t_end, times)?;
        // Smaller arrays make every stage cheaper; unused slots would only be zeros.
        let n = match system.n_active() {
            0..=2 => 2,
            3..=4 => 4,
            _ => 6,
        };
        macro_rules! go {
            ($m:literal) => {
                self.solve::<$m>(system, n, t0, y0, t_end, grid, times, sink, on_step)
            };
        }
        match (n, self.work) {
            (2, false) => go!(4),
            (2, true) => go!(6),
            (4, false) => go!(8),
            (4, true) => go!(10),
            (_, false) => go!(12),
            (_, true) => go!(14),
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn solve<const M: usize>(
        &self,
        system: &dyn OdeSystem,
        n: usize,
        t0: f64,
        y0: &State,
        t_end: f64,
        grid: Option<&[f64]>,
        times: &[f64],
        sink: &mut Sink<'_>,
        on_step: &mut dyn FnMut(f64, &State),
    ) -> Result<(State, IntegrationStats)> {
        debug_assert_eq!(n, Adapter::active::<M>());
        let mut rhs = Adapter {
            system,
            template: *y0,
            calls: 0,
            sides: None,
        };
        let tol = Tolerances {
            rtol: self.rtol,
            atol: self.atol,
            controlled: 2 * n,
        };
        let c0 = compress::<M>(n, y0);
        let (y, mut stats) = match grid {
            None => drive_method(
                self.method,
                &mut rhs,
                &tol,
                self.max_steps,
                t0,
                c0,
                t_end,
                times,
                sink,
                on_step,
            )?,
            Some(grid) => drive_method_on_grid(self.method, &mut rhs, &tol, grid, c0, times, sink)?,
        };
        stats.rhs_calls = rhs.calls;
        Ok((Rhs::<M>::expand(&rhs, &y), stats))
    }
}

impl Integrator for RungeKutta {
    fn integrate_with(
        &self,
        system: &dyn OdeSystem,
        t0: f64,
        y0: &State,
        t_end: f64,
        times: &[f64],
        sink: &mut Sink<'_>,
    ) -> Result<State> {
        self.integrate_counted(system, t0, y0, t_end, times, sink)
            .map(|(y, _)| y)
    }
}

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

/// [`OdeSystem`] on the compact layout `[coords (n), rates (n), work (0 or 2)]`.
struct Adapter<'a> {
    system: &'a dyn OdeSystem,
    /// Supplies the entries the compact state does not carry (work integrals when not
    /// integrated).
    template: State,
    calls: usize,
    /// The branch held by event location (None: the state's own sides, e.g. on fixed grids).
    sides: Option<Sides>,
}

impl Adapter<'_> {
    /// The active coordinates `n` of an `M`-entry array (`2n` or `2n + 2` entries with
    /// `n ∈ {2, 4, 6}`, see [`RungeKutta::dispatch`]): a constant, so the copies in and out
    /// of [`State`] compile to a few moves instead of `memcpy` calls.
    #[inline(always)]
    const fn active<const M: usize>() -> usize {
        2 * (M / 4)
    }
}

impl<const M: usize> Rhs<M> for Adapter<'_> {
    #[inline]
    fn eval(&mut self, t: f64, c: &[f64; M], dcdt: &mut [f64; M]) -> Result<()> {
        self.calls += 1;
        let y = Rhs::<M>::expand(self, c);
        let mut dydt = State::default();
        let evaluated = match self.sides {
            None => self.system.rhs(t, &y, &mut dydt),
            Some(sides) => self.system.rhs_on(t, &y, sides, &mut dydt),
        };
        if let Err(e) = evaluated {
            return Err(integration_error(t, &y, format!("the model failed: {e}")));
        }
        let n = Self::active::<M>();
        dcdt[..n].copy_from_slice(&dydt.coords[..n]);
        dcdt[n..2 * n].copy_from_slice(&dydt.rates[..n]);
        if M > 2 * n {
            dcdt[2 * n] = dydt.work_actuator;
            dcdt[2 * n + 1] = dydt.work_aero;
        }
        Ok(())
    }

    #[inline]
    fn expand(&self, c: &[f64; M]) -> State {
        let n = Self::active::<M>();
        let mut y = State::default();
        y.coords[..n].copy_from_slice(&c[..n]);
        y.rates[..n].copy_from_slice(&c[n..2 * n]);
        if M > 2 * n {
            y.work_actuator = c[2 * n];
            y.work_aero = c[2 * n + 1];
        } else {
            y.work_actuator = self.template.work_actuator;
            y.work_aero = self.template.work_aero;
        }
        y
    }

    fn n_switches(&self) -> usize {
        self.system.n_switches().min(MAX_SWITCHES)
    }

    fn switches(&mut self, t: f64, c: &[f64; M], g: &mut [f64; MAX_SWITCHES]) -> Result<()> {
        let y = Rhs::<M>::expand(self, c);
        self.system
            .switches(t, &y, g)
            .map_err(|e| integration_error(t, &y, format!("the model failed: {e}")))
    }

    fn set_sides(&mut self, sides: Sides) {
        self.sides = Some(sides);
    }
}

fn compress<const M: usize>(n: usize, y: &State) -> [f64; M] {
    let mut c = [0.0; M];
    c[..n].copy_from_slice(&y.coords[..n]);
    c[n..2 * n].copy_from_slice(&y.rates[..n]);
    if M > 2 * n {
        c[2 * n] = y.work_actuator;
        c[2 * n + 1] = y.work_aero;
    }
    c
}

fn integration_error(time: f64, state: &State, reason: impl Into<String>) -> Error {
    Error::Integration {
        time,
        state: state.to_vec(),
        reason: reason.into(),
    }
}

/// Safety factor of the step-size controller.
const SAFE: f64 = 0.9;

/// Hairer's initial step size (`HINIT`): one extra evaluation.
fn initial_step<const M: usize>(
    rhs: &mut dyn Rhs<M>,
    order: i32,
    tol: &Tolerances,
    t0: f64,
    y0: &[f64; M],
    f0: &[f64; M],
    h_max: f64,
) -> Result<f64> {
    let (mut dnf, mut dny) = (0.0, 0.0);
    for i in 0..tol.controlled {
        let sk = tol.atol + tol.rtol * y0[i].abs();
        dnf += (f0[i] / sk).powi(2);
        dny += (y0[i] / sk).powi(2);
    }
    let mut h = if dnf <= 1e-10 || dny <= 1e-10 {
        1e-6
    } else {
        (dny / dnf).sqrt() * 0.01
    };
    h = h.min(h_max);
    let mut y1 = [0.0; M];
    for i in 0..M {
        y1[i] = y0[i] + h * f0[i];
    }
    let mut f1 = [0.0; M];
    rhs.eval(t0 + h, &y1, &mut f1)?;
    let mut der2: f64 = 0.0;
    for i in 0..tol.controlled {
        let sk = tol.atol + tol.rtol * y0[i].abs();
        der2 += ((f1[i] - f0[i]) / sk).powi(2);
    }
    let der2 = der2.sqrt() / h;
    let der12 = der2.abs().max(dnf.sqrt());
    let h1 = if der12 <= 1e-15 {
        (h * 1e-3).max(1e-6)
    } else {
        (0.01 / der12).powf(1.0 / order as f64)
    };
    Ok((100.0 * h).min(h1).min(h_max))
}

/// [`drive`] with the stepper of `method`.
#[allow(clippy::too_many_arguments)]
fn drive_method<const M: usize>(
    method: Method,
    rhs: &mut dyn Rhs<M>,
    tol: &Tolerances,
    max_steps: usize,
    t0: f64,
    y0: [f64; M],
    t_end: f64,
    times: &[f64],
    sink: &mut Sink<'_>,
    on_step: &mut dyn FnMut(f64, &State),
) -> Result<([f64; M], IntegrationStats)> {
    match method {
        Method::Dop853 => drive(
            &mut dop853::Dop853::<M>::new(),
            rhs,
            tol,
            max_steps,
            t0,
            y0,
            t_end,
            times,
            sink,
            on_step,
        ),
        Method::Dopri5 => drive(
            &mut dopri5::Dopri5::<M>::new(),
            rhs,
            tol,
            max_steps,
            t0,
            y0,
            t_end,
            times,
            sink,
            on_step,
        ),
    }
}

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
    match method {
        Method::Dop853 => drive_on_grid(
            &mut dop853::Dop853::<M>::new(),
            rhs,
            tol,
            grid,
            y0,
            times,
            sink,
        ),
        Method::Dopri5 => drive_on_grid(
            &mut dopri5::Dopri5::<M>::new(),
            rhs,
            tol,
            grid,
            y0,
            times,
            sink,
        ),
    }
}

/// Emits the samples that fall inside the accepted step `[t, t_stop)` (`t_stop <= t + h`) from
/// its interpolant (prepared here, unless `dense_ready`, only when one does), then those at
/// `t_stop` from `y_stop`, the step's value there.
#[allow(clippy::too_many_arguments)]
fn sample_step<const M: usize, S: Stepper<M>>(
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
            sink(*next, times[*next], &state)?;
            *next += 1;
        }
    }
    let state = rhs.expand(y_stop);
    if !state.is_finite() {
        return Err(integration_error(t_stop, &state, "non-finite state"));
    }
    while *next < times.len() && times[*next] <= t_stop {
        sink(*next, times[*next], &state)?;
        *next += 1;
    }
    Ok(state)
}

/// Fixed steps between consecutive `grid` times; the error estimate is not used.
fn drive_on_grid<const M: usize, S: Stepper<M>>(
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
            sink(next, times[next], &state)?;
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
const MAX_EVENTS_PER_STEP: usize = 8;

/// [`drive_on_grid`] for a right-hand side with switching functions: each grid step on the
/// branch of its start, cut at the first root inside it (located on the step's dense output,
/// as the adaptive loop does) and finished on the new branch. The roots then move smoothly
/// with the initial state, so the frozen map stays smooth and follows the true map: a branch
/// held over a whole step (read half a step in) integrated the steps next to a moved root on
/// a continued branch (measured on the §2.5 Dual PARITY: the grid map's orbit 9.5e-5 off the
/// true map's, the root 4e-4 ms from its node).
#[allow(clippy::too_many_arguments)]
fn drive_on_grid_events<const M: usize, S: Stepper<M>>(
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
    let mut g0 = [0.0; MAX_SWITCHES];
    let mut g1 = [0.0; MAX_SWITCHES];
    rhs.switches(grid[0], &y, &mut g0)?;
    let mut sides = Sides::of(&g0[..n_switches]);
    rhs.set_sides(sides);
    let mut f0 = [0.0; M];
    let mut f1 = [0.0; M];
    rhs.eval(grid[0], &y, &mut f0)?;
    for (k, pair) in grid.windows(2).enumerate() {
        let (mut t, t_new) = (pair[0], pair[1]);
        if k % budget::CHECK_EVERY == 0 {
            if let Err(stop) = budget::check_current() {
                return Err(budget::stop_error(stop, t, rhs.expand(&y).to_vec()));
            }
        }
        let mut redone = false;
        for sub in 0.. {
            let h = t_new - t;
            let err = stepper.attempt(rhs, t, &y, &f0, h, tol)?;
            if !err.is_finite() {
                return Err(integration_error(
                    t,
                    &rhs.expand(&y),
                    "non-finite state on a fixed step",
                ));
            }
            stepper.new_derivative(rhs, t_new, &mut f1)?;
            let y1 = *stepper.y1();
            rhs.switches(t_new, &y1, &mut g1)?;
            let mut event = None;
            if sub < MAX_EVENTS_PER_STEP
                && (0..n_switches).any(|i| events::crossed(sides, i, g1[i]))
            {
                stepper.prepare_dense(rhs, t, &y, &f0, &f1, h)?;
                stats.dense_steps += 1;
                let found = events::locate(
                    stepper,
                    rhs,
                    n_switches,
                    sides,
                    t,
                    h,
                    &g0,
                    &g1,
                    events::GRID_ROOT_TOLERANCE,
                )?;
                if found.at_start && !redone {
                    // The step began on the wrong branch (a root at its start): redo it on
                    // the far side.
                    redone = true;
                    sides = found.sides;
                    rhs.set_sides(sides);
                    rhs.eval(t, &y, &mut f0)?;
                    continue;
                }
                event = Some(found);
            }
            if err > 1.0 {
                stats.over_tolerance += 1;
            }
            stats.accepted += 1;
            match event {
                Some(ev) if !ev.at_start && ev.t < t_new => {
                    // Cut at the root; the rest of the grid step on the new branch.
                    sample_step(
                        stepper,
                        rhs,
                        t,
                        &y,
                        &f0,
                        &f1,
                        h,
                        (ev.t, &ev.y),
                        true,
                        times,
                        &mut next,
                        sink,
                        &mut stats,
                    )?;
                    stats.events += 1;
                    (y, t, g0, sides) = (ev.y, ev.t, ev.g, ev.sides);
                    rhs.set_sides(sides);
                    rhs.eval(t, &y, &mut f0)?;
                    redone = false;
                }
                other => {
                    sample_step(
                        stepper,
                        rhs,
                        t,
                        &y,
                        &f0,
                        &f1,
                        h,
                        (t_new, &y1),
                        other.is_some(),
                        times,
                        &mut next,
                        sink,
                        &mut stats,
                    )?;
                    if let Some(ev) = other {
                        // Not bracketed (grazing) or at the end: go on from the end's sides.
                        sides = ev.sides;
                        rhs.set_sides(sides);
                        rhs.eval(t_new, &y1, &mut f1)?;
                    }
                    (y, f0, g0) = (y1, f1, g1);
                    break;
                }
            }
        }
    }
    Ok((y, stats))
}

/// The integration loop shared by both pairs (Hairer's `DP86CO` / `DOPCOR`).
#[allow(clippy::too_many_arguments)]
fn drive<const M: usize, S: Stepper<M>>(
    stepper: &mut S,
    rhs: &mut dyn Rhs<M>,
    tol: &Tolerances,
    max_steps: usize,
    t0: f64,
    y0: [f64; M],
    t_end: f64,
    times: &[f64],
    sink: &mut Sink<'_>,
    on_step: &mut dyn FnMut(f64, &State),
) -> Result<([f64; M], IntegrationStats)> {
    let mut stats = IntegrationStats::default();
    let mut y = y0;
    let mut t = t0;
    let mut next = 0;
    if next < times.len() && times[next] <= t0 {
        let state = rhs.expand(&y);
        while next < times.len() && times[next] <= t0 {
            sink(next, times[next], &state)?;
            next += 1;
        }
    }
    // Switching functions: their sides at the start name the branch.
    let n_switches = rhs.n_switches().min(MAX_SWITCHES);
    let mut g0 = [0.0; MAX_SWITCHES];
    let mut g1 = [0.0; MAX_SWITCHES];
    let mut sides = Sides::default();
    let mut redone_at = None;
    if n_switches > 0 {
        rhs.switches(t, &y, &mut g0)?;
        sides = Sides::of(&g0[..n_switches]);
        rhs.set_sides(sides);
    }
    let mut f0 = [0.0; M];
    rhs.eval(t, &y, &mut f0)?;
    let h_max = t_end - t0;
    let mut h = initial_step(rhs, S::ORDER, tol, t0, &y, &f0, h_max)?;
    let fac_lo = 1.0 / S::FAC_MAX;
    let fac_hi = 1.0 / S::FAC_MIN;
    let mut fac_old: f64 = 1e-4;
    let mut rejected_last = false;
    let mut f1 = [0.0; M];
    loop {
        let attempts = stats.accepted + stats.rejected;
        if attempts >= max_steps {
            return Err(integration_error(
                t,
                &rhs.expand(&y),
                format!(
                    "more than {max_steps} steps in one integration (the step budget \
                     `options.max_steps`)"
                ),
            ));
        }
        if attempts % budget::CHECK_EVERY == 0 {
            if let Err(stop) = budget::check_current() {
                return Err(budget::stop_error(stop, t, rhs.expand(&y).to_vec()));
            }
        }
        if 0.1 * h.abs() <= t.abs() * f64::EPSILON || !h.is_finite() {
            return Err(integration_error(t, &rhs.expand(&y), "step size underflow"));
        }
        let last = t + 1.01 * h >= t_end;
        if last {
            h = t_end - t;
        }
        let err = stepper.attempt(rhs, t, &y, &f0, h, tol)?;
        if !err.is_finite() {
            // A non-finite trial (e.g. a state thrown out of range): shrink hard and retry.
            stats.rejected += 1;
            rejected_last = true;
            h *= S::FAC_MIN;
            continue;
        }
        let fac11 = err.powf(S::EXPONENT);
        if err <= 1.0 {
            // Lund stabilisation (PI control): divide by the previous error's factor.
            let fac = (fac11 / fac_old.powf(S::BETA) / SAFE).clamp(fac_lo, fac_hi);
            let mut h_new = h / fac;
            fac_old = err.max(1e-4);
            let t_new = if last { t_end } else { t + h };
            stepper.new_derivative(rhs, t_new, &mut f1)?;
            let y1 = *stepper.y1();
            let mut event = None;
            if n_switches > 0 {
                rhs.switches(t_new, &y1, &mut g1)?;
                if (0..n_switches).any(|i| events::crossed(sides, i, g1[i])) {
                    stepper.prepare_dense(rhs, t, &y, &f0, &f1, h)?;
                    stats.dense_steps += 1;
                    let found = events::locate(
                        stepper,
                        rhs,
                        n_switches,
                        sides,
                        t,
                        h,
                        &g0,
                        &g1,
                        events::ROOT_TOLERANCE,
                    )?;
                    if found.at_start && redone_at != Some(t) {
                        // The step began on the wrong branch (a switch sitting at zero there):
                        // take the far side and redo it.
                        redone_at = Some(t);
                        sides = found.sides;
                        rhs.set_sides(sides);
                        rhs.eval(t, &y, &mut f0)?;
                        stats.rejected += 1;
                        continue;
                    }
                    event = Some(found);
                }
            }
            stats.accepted += 1;
            match event {
                Some(ev) if !ev.at_start && ev.t < t_new => {
                    // Cut the step at the first switch and restart there on the new branch.
                    let state = sample_step(
                        stepper,
                        rhs,
                        t,
                        &y,
                        &f0,
                        &f1,
                        h,
                        (ev.t, &ev.y),
                        true,
                        times,
                        &mut next,
                        sink,
                        &mut stats,
                    )?;
                    stats.events += 1;
                    y = ev.y;
                    t = ev.t;
                    g0 = ev.g;
                    sides = ev.sides;
                    rhs.set_sides(sides);
                    rhs.eval(t, &y, &mut f0)?;
                    on_step(t, &state);
                }
                other => {
                    let dense_ready = other.is_some();
                    let state = sample_step(
                        stepper,
                        rhs,
                        t,
                        &y,
                        &f0,
                        &f1,
                        h,
                        (t_new, &y1),
                        dense_ready,
                        times,
                        &mut next,
                        sink,
                        &mut stats,
                    )?;
                    if let Some(ev) = other {
                        // A switch that could not be bracketed (grazing): continue on its end side.
                        sides = ev.sides;
                        rhs.set_sides(sides);
                        rhs.eval(t_new, &y1, &mut f1)?;
                    }
                    y = y1;
                    f0 = f1;
                    g0 = g1;
                    t = t_new;
                    on_step(t, &state);
                    if last {
                        return Ok((y, stats));
                    }
                }
            }
            h_new = h_new.min(h_max);
            if rejected_last {
                h_new = h_new.min(h);
            }
            rejected_last = false;
            h = h_new;
        } else {
            stats.rejected += 1;
            rejected_last = true;
            h /= fac_hi.min(fac11 / SAFE);
        }
    }
}

/// Receives the samples of [`integrate_array`]: `(index in times, time, state)`.
pub type ArraySink<'a, const M: usize> = dyn FnMut(usize, f64, &[f64; M]) -> Result<()> + 'a;

/// The right-hand side of [`integrate_array`]: writes `f(t, y)`.
pub type ArrayRhs<'a, const M: usize> = dyn FnMut(f64, &[f64; M], &mut [f64; M]) -> Result<()> + 'a;

/// A plain array system `ẏ = f(t, y)` of `M` entries for [`integrate_system`], optionally
/// piecewise smooth: [`Self::n_switches`] switching functions `g_i(t, y)` whose sign changes
/// mark where the right-hand side jumps or kinks, and [`Self::rhs`] evaluating the smooth
/// branch named by [`Sides`] (also slightly past the switching surface: the integrator cuts
/// each step at the first sign change, see the module `events`).
pub trait ArraySystem<const M: usize> {
    /// Writes `f(t, y)` on the branch `sides` (ignored without switching functions).
    ///
    /// # Errors
    /// Any model error; the integrator reports it with the time and state.
    fn rhs(&mut self, t: f64, y: &[f64; M], sides: Sides, dydt: &mut [f64; M]) -> Result<()>;

    /// Number of switching functions, at most [`MAX_SWITCHES`] (0: smooth, the default).
    fn n_switches(&self) -> usize {
        0
    }

    /// Writes `g(t, y)` into `g[..n_switches]`.
    ///
    /// # Errors
    /// Any model error.
    fn switches(&mut self, _t: f64, _y: &[f64; M], _g: &mut [f64; MAX_SWITCHES]) -> Result<()> {
        Ok(())
    }
}

/// A closure as a smooth [`ArraySystem`].
struct Smooth<'a, 'f, const M: usize>(&'a mut ArrayRhs<'f, M>);

impl<const M: usize> ArraySystem<M> for Smooth<'_, '_, M> {
    #[inline]
    fn rhs(&mut self, t: f64, y: &[f64; M], _: Sides, dydt: &mut [f64; M]) -> Result<()> {
        (self.0)(t, y, dydt)
    }
}

/// Integrates a plain array system `ẏ = f(t, y)` of `M` entries with the same Dormand–Prince
/// pairs, step control, dense output and budget checks as [`RungeKutta`] (for models whose
/// state does not fit [`State`], e.g. the free-flying airframe of `paritysim-flight`). Every
/// entry takes part in the error norm. Samples at `times` (sorted, within `[t0, t_end]`) go
/// to `sink`; returns the state at `t_end`.
///
/// # Errors
/// [`Error::InvalidParameter`] for bad tolerances, `t_end <= t0` or times out of order;
/// [`Error::Integration`] (time and the first 12 entries of the state) for step-size
/// underflow, the step limit, a failing right-hand side or the thread's wall-time budget;
/// [`Error::Cancelled`]; whatever `sink` returns.
#[allow(clippy::too_many_arguments)]
pub fn integrate_array<const M: usize>(
    method: Method,
    rtol: f64,
    atol: f64,
    max_steps: usize,
    f: &mut ArrayRhs<'_, M>,
    t0: f64,
    y0: &[f64; M],
    t_end: f64,
    times: &[f64],
    sink: &mut ArraySink<'_, M>,
) -> Result<([f64; M], IntegrationStats)> {
    integrate_system(
        method,
        rtol,
        atol,
        max_steps,
        &mut Smooth(f),
        t0,
        y0,
        t_end,
        times,
        sink,
    )
}

/// [`integrate_array`] on an [`ArraySystem`]: with switching functions, every step ends at
/// the first sign change inside it (located on the dense output) and the integration
/// restarts there on the new branch with the step size kept; `IntegrationStats::events`
/// counts those steps.
///
/// # Errors
/// As [`integrate_array`]; a failing switching function as a failing right-hand side.
#[allow(clippy::too_many_arguments)]
pub fn integrate_system<const M: usize>(
    method: Method,
    rtol: f64,
    atol: f64,
    max_steps: usize,
    system: &mut dyn ArraySystem<M>,
    t0: f64,
    y0: &[f64; M],
    t_end: f64,
    times: &[f64],
    sink: &mut ArraySink<'_, M>,
) -> Result<([f64; M], IntegrationStats)> {
    RungeKutta::new(method, rtol, atol, max_steps)?;
    check_window(t0, t_end, times)?;
    let n_switches = system.n_switches();
    if n_switches > MAX_SWITCHES {
        return Err(Error::invalid(
            "n_switches",
            n_switches,
            format!("at most {MAX_SWITCHES}"),
        ));
    }
    // The stepper hands samples over as `State`s: the array rides alongside in `last`.
    let last = std::cell::RefCell::new([0.0; M]);
    let mut rhs = ArrayAdapter {
        system,
        last: &last,
        calls: 0,
        sides: Sides::default(),
    };
    let tol = Tolerances {
        rtol,
        atol,
        controlled: M,
    };
    let mut state_sink = |i: usize, t: f64, _: &State| -> Result<()> {
        let y = *last.borrow();
        if y.iter().any(|v| !v.is_finite()) {
            return Err(Error::Integration {
                time: t,
                state: y.to_vec(),
                reason: "non-finite state".into(),
            });
        }
        sink(i, t, &y)
    };
    let (y, mut stats) = drive_method(
        method,
        &mut rhs,
        &tol,
        max_steps,
        t0,
        *y0,
        t_end,
        times,
        &mut state_sink,
        &mut |_, _| {},
    )?;
    stats.rhs_calls = rhs.calls;
    Ok((y, stats))
}

/// [`Rhs`] of a plain array system; `expand` keeps the array in `last` for the sink.
struct ArrayAdapter<'a, const M: usize> {
    system: &'a mut dyn ArraySystem<M>,
    last: &'a std::cell::RefCell<[f64; M]>,
    calls: usize,
    sides: Sides,
}

fn model_error(t: f64, y: &[f64], e: Error) -> Error {
    match e {
        e @ (Error::Integration { .. } | Error::Cancelled) => e,
        e => Error::Integration {
            time: t,
            state: y.to_vec(),
            reason: format!("the model failed: {e}"),
        },
    }
}

impl<const M: usize> Rhs<M> for ArrayAdapter<'_, M> {
    #[inline]
    fn eval(&mut self, t: f64, y: &[f64; M], dydt: &mut [f64; M]) -> Result<()> {
        self.calls += 1;
        self.system
            .rhs(t, y, self.sides, dydt)
            .map_err(|e| model_error(t, y, e))
    }

    fn expand(&self, c: &[f64; M]) -> State {
        *self.last.borrow_mut() = *c;
        let mut y = State::default();
        let k = M.min(MAX_DOF);
        y.coords[..k].copy_from_slice(&c[..k]);
        if M > MAX_DOF {
            let r = (M - MAX_DOF).min(MAX_DOF);
            y.rates[..r].copy_from_slice(&c[MAX_DOF..MAX_DOF + r]);
        }
        y
    }

    fn n_switches(&self) -> usize {
        self.system.n_switches()
    }

    fn switches(&mut self, t: f64, y: &[f64; M], g: &mut [f64; MAX_SWITCHES]) -> Result<()> {
        self.system
            .switches(t, y, g)
            .map_err(|e| model_error(t, y, e))
    }

    fn set_sides(&mut self, sides: Sides) {
        self.sides = sides;
    }
}
