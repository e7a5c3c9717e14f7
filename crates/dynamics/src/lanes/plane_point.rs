//! One continued shooting point of a §3.4 stroke-plane device in a lane: the state machine of
//! `simulate::shooting_steady_state` and `grid_shooting::shoot` for a switched device that
//! starts from a converged neighbour (see the module `lanes`).
//!
//! Its Newton trials and the recorded window (fixed-grid periods, most of the point's work)
//! run in the lane. The adaptive periods that pick a grid and the variational periods (an
//! exact Jacobian) run in place on the scalar path, with the scalar functions themselves, while
//! the other lanes wait: they are one period in several and the lanes integrate fixed grids
//! only (docs/findings.md §24).

use std::rc::Rc;

use nalgebra::{DMatrix, DVector};
use paritysim_error::Result;

use super::SWITCHED_COMPLETED_IN_LANES;
use super::plane_rhs;
use crate::device::Device;
use crate::grid_shooting::{REPICK_RESIDUAL, least_squares_step};
use crate::integrate::budget::Budget;
use crate::integrate::lanes::{LaneOutcome, LaneProblem, SampleBlock};
use crate::integrate::{Method, RungeKutta, State};
use crate::metrics::{MetricsAccumulator, StrokeNeeds};
use crate::simulate::{
    BROYDEN_VERDICT_CHECKED_BELOW, SimulationOptions, SteadyState, UNSTABLE_MARGIN,
};
use crate::sweep::PointOutput;
use crate::trajectory::{PlaneSample, Sample};

/// Newton steps of the shooting (as `simulate` gives `grid_shooting::shoot`).
const MAX_NEWTON: usize = 20;

/// What a lane point does next.
pub(super) enum PlaneStep<const M: usize> {
    /// Integrate this period in its lane.
    Integrate(LaneProblem<M>),
    /// Converged: the point's output.
    Done(Box<PointOutput>),
    /// Leave the straight path: rerun the point on the scalar path.
    Scalar,
}

/// The period a point waits for.
enum Pending {
    /// The adaptive period that picks the grid from the start (a switched device does not
    /// reuse its neighbour's: `shooting_steady_state`).
    Pick,
    /// The adaptive period that picks the grid again at the converged `y_new` (the grid was
    /// picked far from the orbit: `grid_shooting::REPICK_RESIDUAL`).
    Repick { y_new: State },
    /// A Newton trial from `y_new`; `last`: the recorded window.
    Trial {
        y_new: State,
        delta: DVector<f64>,
        step: f64,
        last: bool,
    },
}

/// One continued point of a switched device (see the module), its lanes' compact states of `M`
/// entries.
pub(super) struct PlanePoint<'a, const M: usize> {
    pub(super) device: &'a Device,
    /// Integrated coordinates (Newton's unknowns are `2n`).
    n: usize,
    metric_names: &'a [String],
    samples_per_cycle: usize,
    needs: StrokeNeeds,
    period: f64,
    limits: super::Limits,
    /// The run's integrator (no work integrals), for the variational periods.
    rk: RungeKutta,
    pub(super) grid: Rc<[f64]>,
    /// The drive at the grid's stage times (`None` after the grid changes).
    forcing: Option<Rc<[[f64; 2]]>>,
    times: Rc<[f64]>,
    jac: DMatrix<f64>,
    fresh: bool,
    repick: bool,
    eye: DMatrix<f64>,
    y: State,
    f: DVector<f64>,
    res: f64,
    last_step: Option<f64>,
    iterations: usize,
    periods: usize,
    pending: Option<Pending>,
    metrics: MetricsAccumulator,
    cancel: Option<crate::integrate::budget::CancelFlag>,
    pub(super) deadline: Option<(std::time::Instant, f64)>,
}

impl<'a, const M: usize> PlanePoint<'a, M> {
    /// The point and its first lane period, or `None` when it does not qualify: a continued
    /// shooting point of a device with stroke-plane lanes, reading metrics that need no work
    /// integral, one plain recorded cycle, DOP853.
    pub(super) fn new(
        device: &'a Device,
        options: &SimulationOptions,
        metric_names: &'a [String],
        times_cache: &mut Option<(f64, usize, Rc<[f64]>)>,
    ) -> Option<(Self, PlaneStep<M>)> {
        if plane_rhs::layout(device) != Some(M) {
            return None;
        }
        let n = device.n_dof();
        let period = device.period()?;
        let needs = StrokeNeeds::of(Some(metric_names));
        let plain = options.steady_state == SteadyState::Shooting
            && options.method == Method::Dop853
            && options.record_cycles == 1
            && options.perturbation.is_none()
            && !needs.work;
        if !plain || crate::simulate::validate(options).is_err() {
            return None;
        }
        let (p0, pd0) = options.initial?;
        let jac = options.shooting_jacobian.clone()?;
        if jac.shape() != (2 * n, 2 * n)
            || options.samples_per_cycle > crate::simulate::MAX_RECORDED_SAMPLES
        {
            return None;
        }
        let rk = RungeKutta::new(
            options.method,
            options.rtol,
            options.atol,
            options.max_steps,
        )
        .ok()?
        .with_work(false);
        let y = device.state_from(&p0, &pd0).ok()?.without_work();
        let n_samples = options.samples_per_cycle;
        let times = super::cached_window_times(times_cache, period, n_samples);
        let mut point = Self {
            device,
            n,
            metric_names,
            samples_per_cycle: n_samples,
            needs,
            period,
            limits: super::Limits::of(options),
            rk,
            grid: Rc::from([0.0, period]),
            forcing: None,
            times,
            jac,
            fresh: false,
            repick: false,
            eye: DMatrix::identity(2 * n, 2 * n),
            y,
            f: DVector::zeros(2 * n),
            res: f64::NAN,
            last_step: None,
            iterations: 0,
            periods: 0,
            pending: None,
            metrics: MetricsAccumulator::new(device, Some(period)),
            cancel: options.cancel.clone(),
            deadline: crate::integrate::budget::deadline(options.max_wall_ms),
        };
        // A switched device does not reuse its neighbour's grid: an adaptive period picks
        // one (`chooser.advance_with_steps`, in the lane).
        point.pending = Some(Pending::Pick);
        let first = point.adaptive_grid_period(&point.y);
        Some((point, first))
    }

    /// One adaptive period from `y` at the grid tolerances that picks a grid
    /// (`chooser.advance_with_steps`, in the lane).
    fn adaptive_grid_period(&self, y: &State) -> PlaneStep<M> {
        PlaneStep::Integrate(LaneProblem {
            grid: Rc::from([0.0, self.period]),
            adaptive: Some(self.limits.max_steps),
            y0: plane_rhs::compact(y),
            times: Rc::from([]),
            tol: self.limits.grid,
        })
    }

    /// Runs `work` on the scalar path in place, under the point's budget (what is left of its
    /// `max_wall_ms`, and its cancel).
    fn inline<T>(&self, work: impl FnOnce(&Self) -> Result<T>) -> Result<T> {
        let left = self
            .deadline
            .map(|(end, _)| end.saturating_duration_since(std::time::Instant::now()))
            .map(|d| (d.as_secs_f64() * 1e3).max(f64::MIN_POSITIVE));
        let _budget = Budget::new(left, self.cancel.clone()).enter();
        work(self)
    }

    /// The drive table of the current grid.
    pub(super) fn forcing(&mut self) -> Rc<[[f64; 2]]> {
        if let Some(table) = &self.forcing {
            return table.clone();
        }
        let table = plane_rhs::forcing(self.device, &self.grid);
        self.forcing = Some(table.clone());
        table
    }

    /// The exact Jacobian of the grid map at `at` (`rk.flow_with_sensitivity_on_grid`, in
    /// place).
    fn exact_jacobian(&self, at: &State) -> Result<DMatrix<f64>> {
        self.inline(|p| {
            p.rk.flow_with_sensitivity_on_grid(p.device, &p.grid, at)
                .map(|(_, j)| j)
        })
    }

    /// The next Newton trial from the current iterate (the head of `shoot`'s loop), or the
    /// grid picked again first.
    fn iterate(&mut self) -> PlaneStep<M> {
        if self.iterations >= MAX_NEWTON {
            return PlaneStep::Scalar;
        }
        self.iterations += 1;
        let model = (&self.jac, &self.eye, &self.f);
        let (n, tol) = (self.n, self.limits.tol);
        let trial = super::newton_trial(n, &self.y, model, self.last_step, self.fresh, tol);
        let Some((delta, step, y_new, last)) = trial else {
            return PlaneStep::Scalar;
        };
        if last && self.repick {
            // Converged on a grid picked far from the orbit: the grid again, from here.
            self.repick = false;
            let next = self.adaptive_grid_period(&y_new);
            self.pending = Some(Pending::Repick { y_new });
            return next;
        }
        if last {
            // A fresh window (a refused earlier window's samples are not kept).
            self.metrics = MetricsAccumulator::new(self.device, Some(self.period));
        }
        let problem = LaneProblem {
            grid: self.grid.clone(),
            adaptive: None,
            y0: plane_rhs::compact(&y_new),
            times: if last {
                self.times.clone()
            } else {
                Rc::from([])
            },
            tol: self.limits.newton,
        };
        self.pending = Some(Pending::Trial {
            y_new,
            delta,
            step,
            last,
        });
        PlaneStep::Integrate(problem)
    }

    /// Feeds recorded samples to the metrics in order, as the scalar window's sink does
    /// (`PlaneSample`, or the general sample outside the closed form); `false`: the scalar
    /// path would fail here.
    pub(super) fn sample(&mut self, block: &SampleBlock<M>) -> bool {
        for j in 0..block.count {
            let c: [f64; M] = std::array::from_fn(|i| block.y[i].to_array()[j]);
            let (i, t, state) = (block.first + j, block.t[j], plane_rhs::expand(&c));
            let closing = i == self.samples_per_cycle;
            match PlaneSample::new(self.device, t, &state, self.needs) {
                Some(Ok(sample)) => self.metrics.add_plane(&sample, closing),
                Some(Err(_)) => return false,
                None => match Sample::new(self.device, t, &state) {
                    Ok(sample) => self.metrics.add(&sample, closing),
                    Err(_) => return false,
                },
            }
        }
        true
    }

    /// Continues after the lane's period ended with `outcome` (the rest of `shoot`'s loop).
    pub(super) fn resume(&mut self, outcome: LaneOutcome<M>) -> PlaneStep<M> {
        let (Some(pending), LaneOutcome::Done { y, steps, .. }) = (self.pending.take(), outcome)
        else {
            return PlaneStep::Scalar;
        };
        let (y_new, delta, step, last) = match pending {
            Pending::Pick => {
                self.grid = steps.into();
                self.forcing = None;
                self.periods = 1;
                (self.f, self.res) = super::residual(self.n, &self.y, &plane_rhs::expand(&y));
                self.repick = self.res > REPICK_RESIDUAL;
                return self.iterate();
            }
            Pending::Repick { y_new } => {
                self.grid = steps.into();
                self.forcing = None;
                self.periods += 1;
                (self.f, self.res) = super::residual(self.n, &y_new, &plane_rhs::expand(&y));
                self.y = y_new;
                return self.iterate();
            }
            Pending::Trial {
                y_new,
                delta,
                step,
                last,
            } => (y_new, delta, step, last),
        };
        self.periods += 1;
        let (f_new, res_new) = super::residual(self.n, &y_new, &plane_rhs::expand(&y));
        let tol = self.limits.tol;
        if last && res_new > tol && res_new <= self.limits.accept_tol && !self.fresh {
            // Re-linearise at the candidate, then decide with the exact Jacobian.
            let Ok(jac) = self.exact_jacobian(&y_new) else {
                return PlaneStep::Scalar;
            };
            self.jac = jac;
            self.periods += 1;
            self.fresh = true;
            self.last_step = None;
            (self.y, self.f, self.res) = (y_new, f_new, res_new);
            return self.iterate();
        }
        let neutral = || {
            res_new <= self.limits.accept_tol
                && least_squares_step(&self.jac - &self.eye, &f_new)
                    .is_some_and(|d| d.amax() / (1.0 + y_new.compact(self.n).amax()) <= tol)
        };
        if last && (res_new <= tol || neutral()) {
            return self.done(y_new, res_new);
        }
        if res_new >= self.res || res_new.is_nan() {
            if self.fresh {
                return PlaneStep::Scalar;
            }
            // A stale Jacobian that no longer descends: the exact one at the iterate.
            let Ok(jac) = self.exact_jacobian(&self.y.clone()) else {
                return PlaneStep::Scalar;
            };
            self.jac = jac;
            self.periods += 1;
            self.fresh = true;
            self.last_step = None;
            return self.iterate();
        }
        super::broyden_update(&mut self.jac, &self.eye, &delta, (&self.f, &f_new));
        self.fresh = false;
        (self.y, self.f, self.res) = (y_new, f_new, res_new);
        self.last_step = Some(step);
        self.iterate()
    }

    /// The converged point as `simulate` and `run_point` report it, after the stability
    /// verdict of `shooting_steady_state` (a marginal one from a Broyden-updated Jacobian
    /// checked with the variational equations at the orbit).
    fn done(&mut self, state: State, residual: f64) -> PlaneStep<M> {
        let mut multipliers = crate::floquet::eigenvalues(&self.jac).unwrap_or_default();
        let largest = multipliers.first().map_or(0.0, |m| m.norm());
        if largest > 1.0 + UNSTABLE_MARGIN && largest < BROYDEN_VERDICT_CHECKED_BELOW {
            match self.exact_jacobian(&state) {
                Ok(jac) => self.jac = jac,
                // A spent budget or a cancel: the scalar run reports it.
                Err(e) if crate::grid_shooting::out_of_budget(&e) => return PlaneStep::Scalar,
                Err(_) => {}
            }
            multipliers = crate::floquet::eigenvalues(&self.jac).unwrap_or_default();
        }
        if multipliers
            .first()
            .is_some_and(|m| m.norm() > 1.0 + UNSTABLE_MARGIN)
        {
            return PlaneStep::Scalar;
        }
        SWITCHED_COMPLETED_IN_LANES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        PlaneStep::Done(
            super::Converged {
                device: self.device,
                metric_names: self.metric_names,
                samples_per_cycle: self.samples_per_cycle,
                period: self.period,
                metrics: self.metrics.finish(),
                cycles_run: self.periods - 1,
                residual,
                state,
                multipliers,
                jacobian: self.jac.clone(),
                grid: self.grid.to_vec(),
            }
            .output(),
        )
    }
}
