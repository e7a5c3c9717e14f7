//! One shooting point in a lane: the state machine of `simulate::shooting_steady_state` and
//! `shooting::grid::shoot` that hands out one period at a time (see the module `lanes`).

use std::rc::Rc;

use nalgebra::{DMatrix, DVector};

use super::linear_stroke::LinearStroke;
use crate::device::Device;
use crate::integrate::lanes::{LaneOutcome, LaneProblem, SampleBlock};
use crate::integrate::{Method, RungeKutta, State};
use crate::metrics::{MetricsAccumulator, StrokeBlock};
use crate::shooting::newton::{self, REPICK_RESIDUAL};
use crate::simulate::{SimulationOptions, SteadyState, UNSTABLE_MARGIN};
use crate::sweep::PointOutput;

/// The fixed-grid period a lane point waits for.
#[derive(Clone, Debug)]
enum Pending {
    /// The neighbour's grid from the start state, its error estimates counted.
    Map,
    /// The adaptive period that picks a new grid (the neighbour's no longer suits).
    Pick,
    /// A cold point's transient warm-up period.
    WarmUp,
    /// A cold point's variational period.
    Sensitivity,
    /// The variational equations on the grid (an exact Jacobian); then the iterate becomes
    /// `candidate` `(y, f, residual)` when given.
    Relinearise {
        candidate: Option<(State, DVector<f64>, f64)>,
    },
    /// The adaptive period that picks the grid again at the converged `y_new` (the grid was
    /// picked far from the orbit: `shooting::grid::REPICK_RESIDUAL`).
    Repick { y_new: State },
    /// A Newton trial from `y_new`; `last`: the recorded window.
    Trial {
        y_new: State,
        delta: DVector<f64>,
        step: f64,
        last: bool,
    },
}

/// What a lane point does next.
pub(super) enum Next {
    /// Integrate this period in its lane.
    Integrate(LaneProblem<4>),
    /// Integrate this period with the variational equations in its lane.
    Sensitivity(LaneProblem<20>),
    /// Converged: the point's output.
    Done(Box<PointOutput>),
    /// Leave the straight path: rerun the point on the scalar path.
    Scalar,
}

/// One shooting point in a lane: `simulate::shooting_steady_state` and `shooting::grid::shoot`
/// as a state machine that hands out one period at a time (see the module).
pub(super) struct LanePoint<'a> {
    device: &'a Device,
    pub(super) model: LinearStroke<'a>,
    metric_names: &'a [String],
    samples_per_cycle: usize,
    period: f64,
    limits: super::Limits,
    pub(super) grid: Rc<[f64]>,
    /// The actuator force at the grid's stage times (`None` until asked, and after the grid
    /// changes).
    pub(super) forcing: Option<Rc<[f64]>>,
    times: Rc<[f64]>,
    jac: DMatrix<f64>,
    /// Whether `jac` is an exact Jacobian at `y` (after a re-linearisation).
    fresh: bool,
    /// Whether the grid was picked far from the orbit and is to be picked again once Newton
    /// converges on it (`shooting::grid::REPICK_RESIDUAL`).
    repick: bool,
    /// Warm-up periods of a cold point: at most `min_cycles`.
    min_cycles: usize,
    warm_cycles: usize,
    eye: DMatrix<f64>,
    y: State,
    f: DVector<f64>,
    res: f64,
    last_step: Option<f64>,
    iterations: usize,
    periods: usize,
    pending: Pending,
    metrics: MetricsAccumulator,
    with_force: bool,
    /// The wall-time deadline of `options.max_wall_ms` from the point's start.
    pub(super) deadline: Option<(std::time::Instant, f64)>,
}

/// The compact `[q1, q2, q̇1, q̇2]` of a two-DOF state.
fn compact4(y: &State) -> [f64; 4] {
    [y.coords[0], y.coords[1], y.rates[0], y.rates[1]]
}

/// The state of a compact one (work integrals zero, as the shooting's states).
fn expand4(c: &[f64; 4]) -> State {
    let mut y = State::default();
    y.coords[..2].copy_from_slice(&c[..2]);
    y.rates[..2].copy_from_slice(&c[2..]);
    y
}

/// `(P(y) − y, ‖P(y) − y‖∞ / (1 + ‖y‖∞))` on the two drivetrain coordinates.
fn residual(y: &State, py: &State) -> (DVector<f64>, f64) {
    newton::residual(2, y, py)
}

impl<'a> LanePoint<'a> {
    /// The point and its first period, or `None` when it does not qualify (see the module).
    pub(super) fn new(
        device: &'a Device,
        options: &SimulationOptions,
        metric_names: &'a [String],
        times_cache: &mut Option<(f64, usize, Rc<[f64]>)>,
    ) -> Option<(Self, Next)> {
        let model = LinearStroke::of(device)?;
        let period = device.period()?;
        let stroke_metrics = metric_names
            .iter()
            .all(|m| crate::metrics::is_stroke_metric(m));
        let plain = options.steady_state == SteadyState::Shooting
            && options.method == Method::Dop853
            && options.record_cycles == 1
            && options.perturbation.is_none()
            && stroke_metrics;
        if !plain || crate::simulate::validate(options).is_err() {
            return None;
        }
        // A continued point (a neighbour's state, Jacobian and grid) or a cold one (the spec's
        // own start: warm-up, then the variational period).
        let cold = options.initial.is_none();
        let (p0, pd0, jac, grid) = if cold {
            if options.shooting_jacobian.is_some() || options.shooting_grid.is_some() {
                return None;
            }
            let p0 = *device.spec().constraints.particular();
            let identity = DMatrix::identity(4, 4);
            (
                p0,
                paritysim_constraints::Vec6::zeros(),
                identity,
                vec![0.0, period],
            )
        } else {
            let (p0, pd0) = options.initial?;
            let jac = options.shooting_jacobian.clone()?;
            let grid = options.shooting_grid.clone()?;
            if jac.shape() != (4, 4) || grid.first() != Some(&0.0) || grid.last() != Some(&period) {
                return None;
            }
            crate::integrate::check_grid(&grid).ok()?;
            (p0, pd0, jac, grid)
        };
        // What `simulate` checks before running (it would fail on the scalar path).
        RungeKutta::new(
            options.method,
            options.rtol,
            options.atol,
            options.max_steps,
        )
        .ok()?;
        if options.samples_per_cycle > crate::simulate::MAX_RECORDED_SAMPLES {
            return None;
        }
        let y = device.state_from(&p0, &pd0).ok()?.without_work();
        let min_cycles = options.min_cycles;
        let n_samples = options.samples_per_cycle;
        // The recorded window's sample times, as `record_window` makes them.
        let times = super::cached_window_times(times_cache, period, n_samples);
        let point = Self {
            device,
            model,
            metric_names,
            samples_per_cycle: n_samples,
            period,
            limits: super::Limits::of(options),
            grid: grid.into(),
            forcing: None,
            times,
            jac,
            fresh: false,
            repick: false,
            min_cycles,
            warm_cycles: 0,
            eye: DMatrix::identity(4, 4),
            y,
            f: DVector::zeros(4),
            res: f64::NAN,
            last_step: None,
            iterations: 0,
            periods: 0,
            pending: Pending::Map,
            metrics: MetricsAccumulator::new(device, Some(period)),
            with_force: metric_names.iter().any(|m| m == "actuator_force_peak"),
            deadline: crate::integrate::budget::deadline(options.max_wall_ms),
        };
        let mut point = point;
        let first = if !cold {
            Next::Integrate(point.problem(&point.y, false))
        } else if min_cycles > 0 {
            point.warm_up()
        } else {
            point.sensitivity()
        };
        Some((point, first))
    }

    /// One transient warm-up period from the current state (`transient.advance` over one
    /// period: far from the orbit Newton's model is poor, so the fast modes settle first).
    fn warm_up(&mut self) -> Next {
        self.pending = Pending::WarmUp;
        Next::Integrate(LaneProblem {
            grid: Rc::from([0.0, self.period]),
            adaptive: Some(self.limits.max_steps),
            y0: compact4(&self.y),
            times: Rc::from([]),
            tol: self.limits.newton,
        })
    }

    /// The adaptive period with the variational equations that picks the grid and gives the
    /// exact Jacobian (`chooser.flow_with_sensitivity_and_steps`).
    fn sensitivity(&mut self) -> Next {
        self.pending = Pending::Sensitivity;
        let mut c0 = [0.0; 20];
        c0[..4].copy_from_slice(&compact4(&self.y));
        for j in 0..4 {
            c0[4 + j * 4 + j] = 1.0;
        }
        Next::Sensitivity(LaneProblem {
            grid: Rc::from([0.0, self.period]),
            adaptive: Some(self.limits.max_steps),
            y0: c0,
            times: Rc::from([]),
            tol: self.limits.grid,
        })
    }

    /// Continues after the variational period ended with `outcome`.
    pub(super) fn resume_sensitivity(&mut self, outcome: LaneOutcome<20>) -> Next {
        let LaneOutcome::Done { y: c, steps, .. } = outcome else {
            return Next::Scalar;
        };
        if let Pending::Relinearise { candidate } =
            std::mem::replace(&mut self.pending, Pending::Map)
        {
            self.jac = DMatrix::from_fn(4, 4, |i, j| c[4 + j * 4 + i]);
            self.periods += 1;
            self.fresh = true;
            self.last_step = None;
            if let Some((y, f, res)) = candidate {
                (self.y, self.f, self.res) = (y, f, res);
            }
            return self.iterate();
        }
        let py = expand4(&[c[0], c[1], c[2], c[3]]);
        self.jac = DMatrix::from_fn(4, 4, |i, j| c[4 + j * 4 + i]);
        self.grid = steps.into();
        self.forcing = None;
        self.fresh = true;
        self.periods = 1;
        (self.f, self.res) = residual(&self.y, &py);
        self.repick = self.res > REPICK_RESIDUAL;
        self.iterate()
    }

    /// The fixed-grid period from `y` (`record`: with the window's samples).
    fn problem(&self, y: &State, record: bool) -> LaneProblem<4> {
        LaneProblem {
            grid: self.grid.clone(),
            adaptive: None,
            y0: compact4(y),
            times: if record {
                self.times.clone()
            } else {
                Rc::from([])
            },
            tol: match self.pending {
                Pending::Map | Pending::Pick | Pending::Repick { .. } | Pending::Sensitivity => {
                    self.limits.grid
                }
                Pending::Trial { .. } | Pending::WarmUp | Pending::Relinearise { .. } => {
                    self.limits.newton
                }
            },
        }
    }

    /// Feeds recorded samples to the metrics in order, as the scalar window's sink does
    /// (`StrokeSample::of_stroke_device`, then the accumulator); `false`: the scalar path
    /// would fail here.
    pub(super) fn sample(&mut self, block: &SampleBlock) -> bool {
        let (inside, stroke, roll) = self.model.stroke_samples(&block.y);
        let all = (1u32 << block.count) - 1;
        if inside & all != all {
            return false;
        }
        let mut actuator_force = [0.0; 4];
        if self.with_force {
            for (f, &t) in actuator_force.iter_mut().zip(&block.t).take(block.count) {
                *f = self.model.force(t);
            }
        }
        self.metrics.add_stroke_block(&StrokeBlock {
            count: block.count,
            closing: block.first + block.count - 1 == self.samples_per_cycle,
            time: block.t,
            stroke: [stroke[0].to_array(), stroke[1].to_array()],
            roll_aero: [roll[0].to_array(), roll[1].to_array()],
            actuator_force,
            q2: block.y[1].to_array(),
        });
        true
    }

    /// The next Newton trial from the current iterate (the head of `shoot`'s loop).
    fn iterate(&mut self) -> Next {
        if self.iterations >= newton::MAX_NEWTON {
            return Next::Scalar;
        }
        self.iterations += 1;
        let model = (&self.jac, &self.eye, &self.f);
        let trial = newton::trial(
            2,
            &self.y,
            model,
            (self.last_step, self.fresh, None),
            self.limits.tol,
        );
        let Some(newton::Trial {
            delta,
            step,
            y_new,
            last,
            ..
        }) = trial
        else {
            return Next::Scalar;
        };
        if last && self.repick {
            self.repick = false;
            self.pending = Pending::Repick { y_new };
            return Next::Integrate(self.adaptive_grid_period(&y_new));
        }
        self.pending = Pending::Trial {
            y_new,
            delta,
            step,
            last,
        };
        if last {
            // A fresh window (a refused earlier window's samples are not kept).
            self.metrics = MetricsAccumulator::new(self.device, Some(self.period));
        }
        Next::Integrate(self.problem(&y_new, last))
    }

    /// Continues after the lane's period ended with `outcome` (the rest of `shoot`'s loop).
    pub(super) fn resume(&mut self, outcome: LaneOutcome<4>) -> Next {
        match (std::mem::replace(&mut self.pending, Pending::Map), outcome) {
            (Pending::WarmUp, LaneOutcome::Done { y, .. }) => {
                let next = expand4(&y);
                let change = crate::simulate::state_change(&next, &self.y);
                self.y = next.without_work();
                self.warm_cycles += 1;
                if self.warm_cycles < self.min_cycles && change >= 1e-3 {
                    self.warm_up()
                } else {
                    self.sensitivity()
                }
            }
            // A failing warm-up period ends the warm-up (the shooting decides).
            (Pending::WarmUp, LaneOutcome::Failed) => self.sensitivity(),
            (Pending::Sensitivity | Pending::Relinearise { .. }, _) => Next::Scalar,
            (
                Pending::Map,
                LaneOutcome::Done {
                    y,
                    over_tolerance: 0,
                    ..
                },
            ) => {
                self.periods = 1;
                (self.f, self.res) = residual(&self.y, &expand4(&y));
                self.iterate()
            }
            (Pending::Map, _) => {
                // The neighbour's grid no longer suits: one adaptive period picks another
                // (`chooser.advance_with_steps`, in the lane).
                self.pending = Pending::Pick;
                Next::Integrate(self.adaptive_grid_period(&self.y.clone()))
            }
            (Pending::Pick, LaneOutcome::Done { y, steps, .. }) => {
                self.grid = steps.into();
                self.forcing = None;
                self.periods = 1;
                (self.f, self.res) = residual(&self.y, &expand4(&y));
                self.repick = self.res > REPICK_RESIDUAL;
                self.iterate()
            }
            (Pending::Repick { y_new }, LaneOutcome::Done { y, steps, .. }) => {
                self.grid = steps.into();
                self.forcing = None;
                self.periods += 1;
                (self.f, self.res) = residual(&y_new, &expand4(&y));
                self.y = y_new;
                self.iterate()
            }
            (Pending::Pick | Pending::Repick { .. }, LaneOutcome::Failed) => Next::Scalar,
            (Pending::Trial { .. }, LaneOutcome::Failed) => Next::Scalar,
            (
                Pending::Trial {
                    y_new,
                    delta,
                    step,
                    last,
                },
                LaneOutcome::Done { y, .. },
            ) => {
                self.periods += 1;
                let (f_new, res_new) = residual(&y_new, &expand4(&y));
                let tol = self.limits.tol;
                if last && res_new > tol && res_new <= self.limits.accept_tol && !self.fresh {
                    // Re-linearise at the candidate, then decide with the exact Jacobian.
                    return self.relinearise(&y_new, Some((y_new, f_new, res_new)));
                }
                let neutral = || {
                    res_new <= self.limits.accept_tol
                        && newton::least_squares_step(&self.jac - &self.eye, &f_new)
                            .is_some_and(|d| d.amax() / (1.0 + y_new.compact(2).amax()) <= tol)
                };
                if last && (res_new <= tol || neutral()) {
                    return self.done(y_new, res_new);
                }
                if res_new >= self.res || res_new.is_nan() {
                    // A stale Jacobian that no longer descends: the exact one at the iterate.
                    if self.fresh {
                        return Next::Scalar;
                    }
                    return self.relinearise(&self.y.clone(), None);
                }
                newton::broyden_update(&mut self.jac, &self.eye, &delta, (&self.f, &f_new));
                self.fresh = false;
                (self.y, self.f, self.res) = (y_new, f_new, res_new);
                self.last_step = Some(step);
                self.iterate()
            }
        }
    }

    /// One adaptive period from `y` at the grid tolerances that picks a grid
    /// (`chooser.advance_with_steps`, in the lane).
    fn adaptive_grid_period(&self, y: &State) -> LaneProblem<4> {
        LaneProblem {
            grid: Rc::from([0.0, self.period]),
            adaptive: Some(self.limits.max_steps),
            y0: compact4(y),
            times: Rc::from([]),
            tol: self.limits.grid,
        }
    }

    /// The exact Jacobian at `at` on the grid (`rk.flow_with_sensitivity_on_grid`, in the
    /// lane), then the iterate `candidate` when given.
    fn relinearise(&mut self, at: &State, candidate: Option<(State, DVector<f64>, f64)>) -> Next {
        self.pending = Pending::Relinearise { candidate };
        let mut c0 = [0.0; 20];
        c0[..4].copy_from_slice(&compact4(at));
        for j in 0..4 {
            c0[4 + j * 4 + j] = 1.0;
        }
        Next::Sensitivity(LaneProblem {
            grid: self.grid.clone(),
            adaptive: None,
            y0: c0,
            times: Rc::from([]),
            tol: self.limits.newton,
        })
    }

    /// The converged point as `simulate` and `run_point` report it.
    fn done(&mut self, state: State, residual: f64) -> Next {
        let multipliers = crate::floquet::eigenvalues(&self.jac).unwrap_or_default();
        if multipliers
            .first()
            .is_some_and(|m| m.norm() > 1.0 + UNSTABLE_MARGIN)
        {
            return Next::Scalar;
        }
        Next::Done(
            super::Converged {
                device: self.device,
                metric_names: self.metric_names,
                samples_per_cycle: self.samples_per_cycle,
                period: self.period,
                metrics: self.metrics.finish(),
                cycles_run: self.warm_cycles + self.periods - 1,
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
