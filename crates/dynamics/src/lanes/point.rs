//! One shooting point in a lane: the lanes as an executor of the shooting machine
//! (`shooting::machine`), one period at a time (see the module `lanes`).

use std::rc::Rc;

use nalgebra::DMatrix;

use super::linear_stroke::LinearStroke;
use crate::device::Device;
use crate::integrate::lanes::{LaneOutcome, LaneProblem, SampleBlock};
use crate::integrate::{Method, RungeKutta, State};
use crate::metrics::{MetricsAccumulator, StrokeBlock};
use crate::shooting::machine::{GridNewton, Limits, Reply, Request, Start, Verdict};
use crate::shooting::newton;
use crate::simulate::{SimulationOptions, SteadyState, UNSTABLE_MARGIN};
use crate::sweep::PointOutput;

/// The period a lane point waits for.
#[derive(Clone, Debug)]
enum Pending {
    /// A cold point's transient warm-up period.
    WarmUp,
    /// A cold point's variational period (picks the grid, gives the exact Jacobian).
    Sensitivity,
    /// The neighbour's grid from the start state, its error estimates counted.
    Map,
    /// The adaptive period that picks a new grid (the neighbour's no longer suits).
    Pick,
    /// A period the shooting machine requested (`pick`: an adaptive one that picks a grid).
    Newton { pick: bool },
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

/// One shooting point in a lane: the warm-up and first map of `simulate`'s shooting, then the
/// shooting machine ([`GridNewton`]) with the lanes as its executor, one period at a time
/// (see the module).
pub(super) struct LanePoint<'a> {
    device: &'a Device,
    pub(super) model: LinearStroke<'a>,
    metric_names: &'a [String],
    samples_per_cycle: usize,
    period: f64,
    limits: super::Limits,
    /// The step grid (the neighbour's, then the machine's).
    pub(super) grid: Rc<[f64]>,
    /// The actuator force at the grid's stage times (`None` until asked, and after the grid
    /// changes).
    pub(super) forcing: Option<Rc<[f64]>>,
    times: Rc<[f64]>,
    /// The neighbour's Jacobian (a continued point), until the machine starts.
    guess: DMatrix<f64>,
    /// Warm-up periods of a cold point: at most `min_cycles`.
    min_cycles: usize,
    warm_cycles: usize,
    y: State,
    machine: Option<GridNewton>,
    pending: Pending,
    metrics: MetricsAccumulator,
    with_force: bool,
    /// The wall-time deadline of `options.max_wall_ms` from the point's start.
    pub(super) deadline: Option<(std::time::Instant, f64)>,
}

/// The compact `[q1, q2, q̇1, q̇2]` of a two-DOF state.
pub(super) fn compact4(y: &State) -> [f64; 4] {
    [y.coords[0], y.coords[1], y.rates[0], y.rates[1]]
}

/// The state of a compact one (work integrals zero, as the shooting's states).
pub(super) fn expand4(c: &[f64; 4]) -> State {
    let mut y = State::default();
    y.coords[..2].copy_from_slice(&c[..2]);
    y.rates[..2].copy_from_slice(&c[2..]);
    y
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
            if device.has_soft_direction() {
                // The scalar path checks a soft point's multipliers at its orbit
                // (simulate/shooting.rs): one rule, so the lanes leave such points to it.
                return None;
            }
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
            guess: jac,
            min_cycles,
            warm_cycles: 0,
            y,
            machine: None,
            pending: Pending::Map,
            metrics: MetricsAccumulator::new(device, Some(period)),
            with_force: metric_names.iter().any(|m| m == "actuator_force_peak"),
            deadline: crate::integrate::budget::deadline(options.max_wall_ms),
        };
        let mut point = point;
        let first = if !cold {
            Next::Integrate(point.problem(&point.y, false, point.limits.grid))
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
        let jacobian = DMatrix::from_fn(4, 4, |i, j| c[4 + j * 4 + i]);
        match std::mem::replace(&mut self.pending, Pending::Map) {
            Pending::Newton { .. } => self.reply(Reply::Linearised(jacobian)),
            Pending::Sensitivity => {
                let mapped = expand4(&[c[0], c[1], c[2], c[3]]);
                self.start_machine(mapped, jacobian, true, steps.into(), true)
            }
            _ => Next::Scalar,
        }
    }

    /// The fixed-grid period from `y` (`record`: with the window's samples) at `tol`.
    fn problem(
        &self,
        y: &State,
        record: bool,
        tol: crate::integrate::lanes::LaneTolerances,
    ) -> LaneProblem<4> {
        LaneProblem {
            grid: self.grid.clone(),
            adaptive: None,
            y0: compact4(y),
            times: if record {
                self.times.clone()
            } else {
                Rc::from([])
            },
            tol,
        }
    }

    /// Feeds recorded samples to the metrics in order ([`feed_samples`]).
    pub(super) fn sample(&mut self, block: &SampleBlock) -> bool {
        feed_samples(
            &self.model,
            &mut self.metrics,
            block,
            self.samples_per_cycle,
            self.with_force,
        )
    }

    /// Starts the shooting machine from the first map `mapped` of the iterate on `grid`.
    fn start_machine(
        &mut self,
        mapped: State,
        jacobian: DMatrix<f64>,
        exact: bool,
        grid: Rc<[f64]>,
        picked_here: bool,
    ) -> Next {
        if !Rc::ptr_eq(&grid, &self.grid) {
            self.forcing = None;
        }
        self.grid = grid.clone();
        let start = Start {
            y: self.y,
            mapped,
            jacobian,
            exact,
            grid,
            picked_here,
            guess_contraction: None,
        };
        let limits = Limits {
            tol: self.limits.tol,
            accept_tol: self.limits.accept_tol,
            max_newton: newton::MAX_NEWTON,
        };
        let (machine, verdict) = GridNewton::start(2, start, limits);
        self.machine = Some(machine);
        self.follow(verdict)
    }

    /// Hands the machine `reply`; a grid it picked replaces the lane's.
    fn reply(&mut self, reply: Reply) -> Next {
        let Some(machine) = self.machine.as_mut() else {
            return Next::Scalar;
        };
        let verdict = machine.resume(reply);
        if !Rc::ptr_eq(&machine.grid, &self.grid) {
            self.grid = machine.grid.clone();
            self.forcing = None;
        }
        self.follow(verdict)
    }

    /// The lane period (or the end) the machine's `verdict` asks for.
    fn follow(&mut self, verdict: Verdict) -> Next {
        match verdict {
            Verdict::Run(Request::Trial { y, last }) => {
                self.pending = Pending::Newton { pick: false };
                if last {
                    // A fresh window (a refused earlier window's samples are not kept).
                    self.metrics = MetricsAccumulator::new(self.device, Some(self.period));
                }
                Next::Integrate(self.problem(&y, last, self.limits.newton))
            }
            Verdict::Run(Request::Linearise { y }) => {
                self.pending = Pending::Newton { pick: false };
                let mut c0 = [0.0; 20];
                c0[..4].copy_from_slice(&compact4(&y));
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
            Verdict::Run(Request::Pick { y }) => {
                self.pending = Pending::Newton { pick: true };
                Next::Integrate(self.adaptive_grid_period(&y))
            }
            Verdict::Converged(accepted) => self.done(accepted.state, accepted.residual),
            Verdict::GaveUp => Next::Scalar,
        }
    }

    /// Continues after the lane's period ended with `outcome`.
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
            (Pending::Sensitivity, _) => Next::Scalar,
            (
                Pending::Map,
                LaneOutcome::Done {
                    y,
                    over_tolerance: 0,
                    ..
                },
            ) => {
                let (grid, guess) = (self.grid.clone(), self.guess.clone());
                self.start_machine(expand4(&y), guess, false, grid, false)
            }
            (Pending::Map, _) => {
                // The neighbour's grid no longer suits: one adaptive period picks another
                // (`chooser.advance_with_steps`, in the lane).
                self.pending = Pending::Pick;
                Next::Integrate(self.adaptive_grid_period(&self.y.clone()))
            }
            (Pending::Pick, LaneOutcome::Done { y, steps, .. }) => {
                let guess = self.guess.clone();
                self.start_machine(expand4(&y), guess, false, steps.into(), true)
            }
            (Pending::Pick, LaneOutcome::Failed) => Next::Scalar,
            (Pending::Newton { pick: true }, LaneOutcome::Done { y, steps, .. }) => {
                self.reply(Reply::Picked(expand4(&y), steps))
            }
            (Pending::Newton { pick: false }, LaneOutcome::Done { y, .. }) => {
                self.reply(Reply::Mapped(expand4(&y), None))
            }
            (Pending::Newton { .. }, LaneOutcome::Failed) => Next::Scalar,
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

    /// The converged point as `simulate` and `run_point` report it.
    fn done(&mut self, state: State, residual: f64) -> Next {
        let Some(machine) = self.machine.as_ref() else {
            return Next::Scalar;
        };
        let multipliers = crate::floquet::eigenvalues(&machine.jacobian).unwrap_or_default();
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
                cycles_run: self.warm_cycles + machine.periods - 1,
                residual,
                state,
                multipliers,
                jacobian: machine.jacobian.clone(),
                grid: self.grid.to_vec(),
            }
            .output(),
        )
    }
}

/// Feeds a lane's recorded samples to `metrics` in order, as the scalar window's sink does
/// (`StrokeSample::of_stroke_device`, then the accumulator); `closing`: the window's last
/// sample index. `false`: the scalar path would fail here.
pub(super) fn feed_samples(
    model: &LinearStroke<'_>,
    metrics: &mut MetricsAccumulator,
    block: &SampleBlock,
    closing: usize,
    with_force: bool,
) -> bool {
    let (inside, stroke, roll) = model.stroke_samples(&block.y);
    let all = (1u32 << block.count) - 1;
    if inside & all != all {
        return false;
    }
    let mut actuator_force = [0.0; 4];
    if with_force {
        for (f, &t) in actuator_force.iter_mut().zip(&block.t).take(block.count) {
            *f = model.force(t);
        }
    }
    metrics.add_stroke_block(&StrokeBlock {
        count: block.count,
        closing: block.first + block.count - 1 == closing,
        time: block.t,
        stroke: [stroke[0].to_array(), stroke[1].to_array()],
        roll_aero: [roll[0].to_array(), roll[1].to_array()],
        actuator_force,
        q2: block.y[1].to_array(),
    });
    true
}
