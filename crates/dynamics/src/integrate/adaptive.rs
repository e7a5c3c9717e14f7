//! The adaptive integration loop (Hairer's `DP86CO` / `DOPCOR`): step-size control, event
//! location and sampling.

use paritysim_error::Result;

use super::switched::Branch;
use super::{
    IntegrationStats, MAX_SWITCHES, Method, Rhs, Sink, State, Stepper, Tolerances, budget, dop853,
    dopri5, events, integration_error,
};

/// Safety factor of the step-size controller.
pub(super) const SAFE: f64 = 0.9;

/// Hairer's step-size control after an attempt of size `h` with scaled error `err`, written
/// once for the scalar loop ([`AdaptiveRun::attempt`]) and the SIMD lanes
/// (`lane_control::Adaptive`): `Some(h_new)` when the step is accepted (`fac_old` updated; the
/// caller then caps `h_new`), `None` when it is rejected (`h` shrunk, `rejected_last` set; a
/// non-finite error shrinks hard).
#[inline]
pub(super) fn step_size<const M: usize, S: Stepper<M>>(
    err: f64,
    h: &mut f64,
    fac_old: &mut f64,
    rejected_last: &mut bool,
) -> Option<f64> {
    let fac_lo = 1.0 / S::FAC_MAX;
    let fac_hi = 1.0 / S::FAC_MIN;
    if !err.is_finite() {
        *rejected_last = true;
        *h *= S::FAC_MIN;
        return None;
    }
    let fac11 = err.powf(S::EXPONENT);
    if err <= 1.0 {
        // Lund stabilisation (PI control): divide by the previous error's factor.
        let fac = (fac11 / fac_old.powf(S::BETA) / SAFE).clamp(fac_lo, fac_hi);
        *fac_old = err.max(1e-4);
        Some(*h / fac)
    } else {
        *rejected_last = true;
        *h /= fac_hi.min(fac11 / SAFE);
        None
    }
}

/// Hairer's initial step size (`HINIT`): one extra evaluation.
pub(super) fn initial_step<const M: usize>(
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
pub(super) fn drive_method<const M: usize>(
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
    with_stepper!(method, M, |stepper| drive(
        stepper, rhs, tol, max_steps, t0, y0, t_end, times, sink, on_step
    ))
}

/// The integration loop shared by both pairs (Hairer's `DP86CO` / `DOPCOR`).
#[allow(clippy::too_many_arguments)]
pub(super) fn drive<const M: usize, S: Stepper<M>>(
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
    let stats = IntegrationStats::default();
    let y = y0;
    let t = t0;
    let mut next = 0;
    if next < times.len() && times[next] <= t0 {
        let state = rhs.expand(&y);
        while next < times.len() && times[next] <= t0 {
            super::stepper::emit(rhs, sink, (next, times[next]), &y, &state)?;
            next += 1;
        }
    }
    // Switching functions: their sides at the start name the branch.
    let n_switches = rhs.n_switches().min(MAX_SWITCHES);
    let branch = Branch::start(rhs, n_switches, t, &y)?;
    let mut f0 = [0.0; M];
    rhs.eval(t, &y, &mut f0)?;
    let h_max = t_end - t0;
    let h = initial_step(rhs, S::ORDER, tol, t0, &y, &f0, h_max)?;
    let mut run = AdaptiveRun {
        t,
        y,
        f0,
        h,
        fac_old: 1e-4,
        rejected_last: false,
        redone_at: None,
        branch,
        stats,
    };
    loop {
        if let Attempt::Finished = run.attempt(
            stepper,
            rhs,
            tol,
            max_steps,
            (t_end, h_max),
            (times, &mut next, sink),
            on_step,
        )? {
            return Ok((run.y, run.stats));
        }
    }
}

/// What one attempt of [`AdaptiveRun::attempt`] led to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Attempt {
    /// Rejected, or redone on the far side of a switch at its start: the next attempt retries.
    Retry,
    /// Accepted: the run moved to the step's end (or to a root inside it).
    Accepted,
    /// The last step was accepted: the run is at `t_end`.
    Finished,
}

/// The state of [`drive`] between attempts (Hairer's `DP86CO` / `DOPCOR` loop variables).
pub(super) struct AdaptiveRun<const M: usize> {
    pub(super) t: f64,
    pub(super) y: [f64; M],
    pub(super) f0: [f64; M],
    pub(super) h: f64,
    pub(super) fac_old: f64,
    pub(super) rejected_last: bool,
    /// Where a step was last redone on the far side of a switch (once per start).
    pub(super) redone_at: Option<f64>,
    pub(super) branch: Branch,
    pub(super) stats: IntegrationStats,
}

impl<const M: usize> AdaptiveRun<M> {
    /// One attempt of the loop of [`drive`] (step-size control, event location, sampling).
    ///
    /// # Errors
    /// The step limit, a step-size underflow, a spent budget, a failing model, whatever
    /// `sink` returns.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn attempt<S: Stepper<M>>(
        &mut self,
        stepper: &mut S,
        rhs: &mut dyn Rhs<M>,
        tol: &Tolerances,
        max_steps: usize,
        (t_end, h_max): (f64, f64),
        (times, next, sink): (&[f64], &mut usize, &mut Sink<'_>),
        on_step: &mut dyn FnMut(f64, &State),
    ) -> Result<Attempt> {
        let Self {
            t,
            y,
            f0,
            h,
            fac_old,
            rejected_last,
            redone_at,
            branch,
            stats,
        } = self;
        let mut f1 = [0.0; M];
        let attempts = stats.accepted + stats.rejected;
        if attempts >= max_steps {
            return Err(integration_error(
                *t,
                &rhs.expand(y),
                format!(
                    "more than {max_steps} steps in one integration (the step budget \
                     `options.max_steps`)"
                ),
            ));
        }
        if attempts % budget::CHECK_EVERY == 0 {
            if let Err(stop) = budget::check_current() {
                return Err(budget::stop_error(stop, *t, rhs.expand(y).to_vec()));
            }
        }
        if 0.1 * h.abs() <= t.abs() * f64::EPSILON || !h.is_finite() {
            return Err(integration_error(*t, &rhs.expand(y), "step size underflow"));
        }
        let last = *t + 1.01 * *h >= t_end;
        if last {
            *h = t_end - *t;
        }
        let err = stepper.attempt(rhs, *t, y, f0, *h, tol)?;
        // A non-finite trial (e.g. a state thrown out of range) shrinks hard and retries.
        if let Some(mut h_new) = step_size::<M, S>(err, h, fac_old, rejected_last) {
            let t_new = if last { t_end } else { *t + *h };
            stepper.new_derivative(rhs, t_new, &mut f1)?;
            let y1 = *stepper.y1();
            let event = if branch.n > 0 {
                branch.first_switch(
                    stepper,
                    rhs,
                    (*t, y, f0),
                    (t_new, &y1, &f1),
                    *h,
                    true,
                    events::ROOT_TOLERANCE,
                    stats,
                )?
            } else {
                None
            };
            if let Some(found) = &event {
                if found.at_start && *redone_at != Some(*t) {
                    // The step began on the wrong branch (a switch sitting at zero there):
                    // take the far side and redo it.
                    *redone_at = Some(*t);
                    branch.take(rhs, found.sides, *t, y, f0)?;
                    stats.rejected += 1;
                    return Ok(Attempt::Retry);
                }
            }
            stats.accepted += 1;
            let (state, cut) = branch.advance(
                stepper,
                rhs,
                (t, y, f0),
                (t_new, &y1, &mut f1),
                *h,
                event,
                (times, next, sink),
                stats,
            )?;
            on_step(*t, &state);
            if last && !cut {
                return Ok(Attempt::Finished);
            }
            h_new = h_new.min(h_max);
            if *rejected_last {
                h_new = h_new.min(*h);
            }
            *rejected_last = false;
            *h = h_new;
            Ok(Attempt::Accepted)
        } else {
            stats.rejected += 1;
            Ok(Attempt::Retry)
        }
    }
}
