//! Plain array systems ([`ArraySystem`], [`integrate_array`]): models whose state does not fit
//! [`State`], on the same pairs, step control and dense output.

use paritysim_error::{Error, Result};

use super::{
    IntegrationStats, MAX_DOF, MAX_SWITCHES, Method, Rhs, RungeKutta, Sides, State, Tolerances,
    check_window, drive_method,
};

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
