//! [`RungeKutta`]: the adaptive or fixed-grid Dormand–Prince integrator of [`OdeSystem`]s,
//! and the adapter between [`State`] and the compact arrays the steppers work on.

use paritysim_error::{Error, Result, check_positive};

use super::{
    IntegrationStats, Integrator, MAX_SWITCHES, Method, OdeSystem, Rhs, Sides, Sink, State,
    Tolerances, check_grid, check_window, drive_method, drive_method_on_grid, integration_error,
};

/// Adaptive Dormand–Prince integrator with relative and absolute tolerances.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RungeKutta {
    pub(super) method: Method,
    pub(super) rtol: f64,
    pub(super) atol: f64,
    pub(super) max_steps: usize,
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
    pub(super) fn solve<const M: usize>(
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

/// [`OdeSystem`] on the compact layout `[coords (n), rates (n), work (0 or 2)]`.
pub(super) struct Adapter<'a> {
    system: &'a dyn OdeSystem,
    /// Supplies the entries the compact state does not carry (work integrals when not
    /// integrated).
    template: State,
    calls: usize,
    /// The branch held by event location (None: the state's own sides, e.g. on fixed grids).
    sides: Option<Sides>,
}

impl<'a> Adapter<'a> {
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

pub(super) fn compress<const M: usize>(n: usize, y: &State) -> [f64; M] {
    let mut c = [0.0; M];
    c[..n].copy_from_slice(&y.coords[..n]);
    c[n..2 * n].copy_from_slice(&y.rates[..n]);
    if M > 2 * n {
        c[2 * n] = y.work_actuator;
        c[2 * n + 1] = y.work_aero;
    }
    c
}
