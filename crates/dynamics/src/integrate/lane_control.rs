//! The step-size control of an adaptive SIMD lane: the loop of `drive` (integrate/adaptive.rs)
//! after one attempt, per lane, with its operations (so a lane's accepted steps are the scalar
//! run's), for `dop853_lanes`.

use super::dop853::Dop853;

/// The step control of an adaptive lane (`drive` in integrate/adaptive.rs, per lane).
#[derive(Clone, Debug, Default)]
pub(crate) struct Adaptive {
    pub(crate) t: f64,
    pub(crate) t_end: f64,
    pub(crate) h: f64,
    pub(crate) fac_old: f64,
    pub(crate) rejected_last: bool,
    pub(crate) attempts: usize,
    pub(crate) max_steps: usize,
    /// The current attempt is the last step (ends at `t_end`).
    pub(crate) last: bool,
    pub(crate) steps: Vec<f64>,
}

/// What an adaptive lane's attempt led to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Control {
    Accepted,
    Rejected,
    /// The last step was accepted.
    Finished,
    /// The scalar integration errs here (step limit, step-size underflow, a failing model).
    Failed,
}

impl Adaptive {
    /// `drive`'s step control after an attempt with scaled error `err` (`given_up`: the
    /// limits were hit before it; `failed`: a stage's evaluation failed; `completes`: the new
    /// derivative and state of an accepted step are valid).
    pub(crate) fn control(
        &mut self,
        err: f64,
        given_up: bool,
        failed: bool,
        completes: impl FnOnce() -> bool,
    ) -> Control {
        if given_up || failed {
            return Control::Failed;
        }
        self.attempts += 1;
        let controlled = super::adaptive::step_size::<4, Dop853<4>>(
            err,
            &mut self.h,
            &mut self.fac_old,
            &mut self.rejected_last,
        );
        if let Some(mut h_new) = controlled {
            if !completes() {
                return Control::Failed;
            }
            let t_new = if self.last {
                self.t_end
            } else {
                self.t + self.h
            };
            self.t = t_new;
            self.steps.push(t_new);
            if self.last {
                return Control::Finished;
            }
            h_new = h_new.min(self.t_end - self.steps[0]);
            if self.rejected_last {
                h_new = h_new.min(self.h);
            }
            self.rejected_last = false;
            self.h = h_new;
            Control::Accepted
        } else {
            Control::Rejected
        }
    }
}
