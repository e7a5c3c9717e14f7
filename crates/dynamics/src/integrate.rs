//! Our small `Integrator` trait over the `differential-equations` crate (exact version pin).
//!
//! The state is a fixed-size array (no heap allocation in the right-hand side):
//! `[x (6), ẋ (6), actuator work, aerodynamic work]`, unused coordinates held at zero.

use std::cell::RefCell;

use differential_equations::prelude::{ExplicitRungeKutta, IVP, ODE};
use paritysim_error::{Error, Result, check_positive};

/// Length of the integrator state.
pub const STATE_LEN: usize = 14;
/// Integrator state.
pub type State = [f64; STATE_LEN];

/// A first-order system `ẏ = f(t, y)` whose evaluation can fail.
pub trait OdeSystem {
    /// Writes `f(t, y)` into `dydt`.
    fn rhs(&self, t: f64, y: &State, dydt: &mut State) -> Result<()>;

    /// Number of active coordinates `n` (slots `0..n`, `6..6+n`, 12 and 13 are used; the rest
    /// stay zero). The integrator then works on a compact state of `2n + 2` entries.
    fn n_active(&self) -> usize {
        6
    }
}

impl OdeSystem for crate::device::Device {
    fn rhs(&self, t: f64, y: &State, dydt: &mut State) -> Result<()> {
        crate::device::Device::rhs(self, t, y, dydt)
    }

    fn n_active(&self) -> usize {
        self.n_dof()
    }
}

/// Full state from a compact one (`n` coordinates, then `n` rates, then the two work integrals).
#[inline]
fn expand<const M: usize>(n: usize, c: &[f64; M]) -> State {
    let mut y = [0.0; STATE_LEN];
    y[..n].copy_from_slice(&c[..n]);
    y[6..6 + n].copy_from_slice(&c[n..2 * n]);
    y[12] = c[2 * n];
    y[13] = c[2 * n + 1];
    y
}

#[inline]
fn compress<const M: usize>(n: usize, y: &State) -> [f64; M] {
    let mut c = [0.0; M];
    c[..n].copy_from_slice(&y[..n]);
    c[n..2 * n].copy_from_slice(&y[6..6 + n]);
    c[2 * n] = y[12];
    c[2 * n + 1] = y[13];
    c
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

/// Integrates an [`OdeSystem`] and samples it at requested times.
pub trait Integrator: Send + Sync {
    /// Integrates from `(t0, y0)` to `t_end` and returns the state at each of `times`
    /// (sorted, within `[t0, t_end]`).
    ///
    /// # Errors
    /// [`Error::Integration`] carrying the time and state of the failure (step-size underflow,
    /// step limit, non-finite state, or a model error raised inside the right-hand side).
    fn integrate(
        &self,
        system: &dyn OdeSystem,
        t0: f64,
        y0: &State,
        t_end: f64,
        times: &[f64],
    ) -> Result<Vec<State>>;
}

/// Adaptive Runge-Kutta integrator with relative and absolute tolerances.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RungeKutta {
    method: Method,
    rtol: f64,
    atol: f64,
    max_steps: usize,
}

impl RungeKutta {
    /// `rtol`, `atol` in (0, 1); `max_steps` > 0 per call.
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
        })
    }
}

struct Adapter<'a> {
    system: &'a dyn OdeSystem,
    n: usize,
    failure: RefCell<Option<(f64, State, Error)>>,
}

impl<const M: usize> ODE<f64, [f64; M]> for Adapter<'_> {
    fn diff(&self, t: f64, c: &[f64; M], dcdt: &mut [f64; M]) {
        let y = expand(self.n, c);
        let mut dydt = [0.0; STATE_LEN];
        match self.system.rhs(t, &y, &mut dydt) {
            Ok(()) => *dcdt = compress(self.n, &dydt),
            Err(e) => {
                let mut slot = self.failure.borrow_mut();
                if slot.is_none() {
                    *slot = Some((t, y, e));
                }
                // Poison the step so the solver rejects it and stops.
                dcdt.fill(f64::NAN);
            }
        }
    }
}

fn integration_error(time: f64, state: &State, reason: impl Into<String>) -> Error {
    Error::Integration {
        time,
        state: state.to_vec(),
        reason: reason.into(),
    }
}

impl RungeKutta {
    /// Integrates on a compact state of `M = 2n + 2` entries.
    fn solve<const M: usize>(
        &self,
        system: &dyn OdeSystem,
        n: usize,
        t0: f64,
        y0: &State,
        t_end: f64,
        times: &[f64],
    ) -> Result<Vec<State>> {
        let adapter = Adapter {
            system,
            n,
            failure: RefCell::new(None),
        };
        let c0: [f64; M] = compress(n, y0);
        let problem = IVP::ode(&adapter, t0, t_end, c0).t_eval(times);
        let solved = match self.method {
            Method::Dop853 => problem
                .method(
                    ExplicitRungeKutta::dop853()
                        .rtol(self.rtol)
                        .atol(self.atol)
                        .max_steps(self.max_steps),
                )
                .solve(),
            Method::Dopri5 => problem
                .method(
                    ExplicitRungeKutta::dopri5()
                        .rtol(self.rtol)
                        .atol(self.atol)
                        .max_steps(self.max_steps),
                )
                .solve(),
        };
        if let Some((t, y, e)) = adapter.failure.into_inner() {
            return Err(integration_error(t, &y, format!("the model failed: {e}")));
        }
        let solution = solved.map_err(|e| {
            use differential_equations::error::Error as DeError;
            match e {
                DeError::StepSize { t, y } => {
                    integration_error(t, &expand(n, &y), "step size underflow")
                }
                DeError::MaxSteps { t, y } => integration_error(
                    t,
                    &expand(n, &y),
                    format!("more than {} steps", self.max_steps),
                ),
                DeError::Stiffness { t, y } => {
                    integration_error(t, &expand(n, &y), "stiffness detected")
                }
                other => integration_error(t0, y0, format!("{other:?}")),
            }
        })?;
        if solution.y.len() != times.len() {
            return Err(integration_error(
                t0,
                y0,
                format!(
                    "solver returned {} samples for {} requested times",
                    solution.y.len(),
                    times.len()
                ),
            ));
        }
        let mut out = Vec::with_capacity(times.len());
        for (t, c) in solution.t.iter().zip(&solution.y) {
            let y = expand(n, c);
            if y.iter().any(|v| !v.is_finite()) {
                return Err(integration_error(*t, &y, "non-finite state"));
            }
            out.push(y);
        }
        Ok(out)
    }
}

impl Integrator for RungeKutta {
    fn integrate(
        &self,
        system: &dyn OdeSystem,
        t0: f64,
        y0: &State,
        t_end: f64,
        times: &[f64],
    ) -> Result<Vec<State>> {
        if t_end.is_nan() || t_end <= t0 {
            return Err(Error::invalid("t_end", t_end, format!("> t0 = {t0}")));
        }
        // Smaller states make every Runge-Kutta stage cheaper; unused slots would only be zeros.
        match system.n_active() {
            0..=2 => self.solve::<6>(system, 2, t0, y0, t_end, times),
            3..=4 => self.solve::<10>(system, 4, t0, y0, t_end, times),
            _ => self.solve::<14>(system, 6, t0, y0, t_end, times),
        }
    }
}
