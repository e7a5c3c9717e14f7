//! Sweep chains in SIMD lanes: several shooting points integrated at once.
//!
//! A shooting point of [`SteadyState::Shooting`] is a sequence of one-period integrations:
//! the warm-up and the variational period of a chain's start, then (continued points) the
//! neighbour's grid checked or a new one picked, Newton trials on the frozen grid and the
//! recorded window (docs/findings.md §6-7). Here [`LANES`] chains advance side by side, one
//! point per lane: every lane carries its own grid or step control, time, step and state
//! through the DOP853 stages ([`crate::integrate::lanes`], `wide::f64x4`), and a lane whose
//! period ends is handed its point's next period (or the next point of its chain, or the next
//! chain of its group) while the others keep stepping: the ensemble technique of heyoka and
//! MPGOS. Groups of chains run in parallel on the sweep's rayon pool.
//!
//! * **Which points.** A shooting point qualifies when it reads stroke metrics only, records
//!   one plain cycle, uses DOP853, and its device integrates drivetrain coordinates of the
//!   linear differential map with stroke drag ([`has_lane_model`]); every other point runs the
//!   scalar path in place, in its chain's order.
//! * **Same results.** The lanes perform the scalar path's floating-point operations in its
//!   order, and the Newton logic here ([`LanePoint`]) is that of `grid_shooting::shoot` and
//!   `simulate::shooting_steady_state`. The branches it does not follow (a failing period, a
//!   singular Newton step, no convergence, an unstable orbit: `shoot`'s `Ok(None)` and errors)
//!   rerun the point on the scalar path from the same start, so every point's result is
//!   bit-identical to the scalar sweep (`PARITYSIM_LANES=1`; tested for lane widths 1 to 4 and
//!   thread counts).
//! * **Failures are rows**: a failing point fails on the scalar rerun, with the scalar error.
//!   A panic (an engine bug) fails the points of its group of chains (up to `2 × LANES`
//!   chains) rather than of its chain.
//! * **Not covered**: the per-run wall budget `max_wall_ms` is not checked inside the lanes
//!   (a lane period is bounded by `max_steps`; the sweep's cancel is checked between periods).

pub(crate) mod linear_stroke;

use std::rc::Rc;

use nalgebra::{DMatrix, DVector};
use paritysim_error::{Error, Result, bail};

use crate::device::Device;
use crate::grid_shooting::GRID_TOLERANCE_FACTOR;
use crate::integrate::lanes::{
    LANES, LaneOutcome, LaneProblem, LaneStepper, LaneTolerances, SampleBlock,
};
use crate::integrate::{Method, RungeKutta, State};
use crate::metrics::{MetricsAccumulator, StrokeBlock};
use crate::simulate::{SimulationOptions, SimulationResult, SteadyState, UNSTABLE_MARGIN};
use crate::sweep::{
    ChainStart, Converged, PointOutput, SweepControl, chain_point, chain_range, chain_start,
    continued_options, remember, run_tasks,
};
use crate::trajectory::Trajectory;
use linear_stroke::{LinearStroke, LinearStrokeLanes, VariationalLanes};

/// Environment variable read by [`resolve_lanes`] when no lane width is given: an integer in
/// `[1, 4]` (`PARITYSIM_LANES=1` runs the scalar path).
pub const LANES_ENV: &str = "PARITYSIM_LANES";

/// The largest lane width (one `f64x4`).
pub const MAX_LANES: usize = LANES;

/// The lane width a sweep uses: `requested` if given, else [`LANES_ENV`], else
/// [`MAX_LANES`]. One lane is the scalar path.
///
/// # Errors
/// [`Error::InvalidParameter`] for 0, more than [`MAX_LANES`], or an environment value that is
/// not such an integer (naming `lanes` or `PARITYSIM_LANES`).
pub fn resolve_lanes(requested: Option<usize>) -> Result<usize> {
    let allowed = format!("an integer in [1, {MAX_LANES}]");
    if let Some(n) = requested {
        if !(1..=MAX_LANES).contains(&n) {
            bail!(invalid "lanes", n, allowed);
        }
        return Ok(n);
    }
    if let Ok(raw) = std::env::var(LANES_ENV) {
        let raw = raw.trim();
        if !raw.is_empty() {
            return match raw.parse::<usize>() {
                Ok(n) if (1..=MAX_LANES).contains(&n) => Ok(n),
                _ => Err(Error::invalid(LANES_ENV, format!("{raw:?}"), allowed)),
            };
        }
    }
    Ok(MAX_LANES)
}

/// Whether `device` has a SIMD-lane model: its continued shooting points then run in lanes
/// when the sweep's other conditions hold (see the module). Today: drivetrain coordinates of
/// the two-DOF linear differential map (eq. 2.15) with stroke drag or no aerodynamics.
pub fn has_lane_model(device: &Device) -> bool {
    LinearStroke::of(device).is_some()
}

/// Points completed in lanes since the process started (tests and benchmarks read it to see
/// that the lanes ran).
static COMPLETED_IN_LANES: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// How many sweep points the SIMD lanes have completed in this process (monotonic; points
/// rerun on the scalar path are not counted).
pub fn points_completed_in_lanes() -> usize {
    COMPLETED_IN_LANES.load(std::sync::atomic::Ordering::Relaxed)
}

/// Newton steps of the shooting (as `simulate` gives `grid_shooting::shoot`).
const MAX_NEWTON: usize = 20;

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
    /// A Newton trial from `y_new`; `last`: the recorded window.
    Trial {
        y_new: State,
        delta: DVector<f64>,
        step: f64,
        last: bool,
    },
}

/// What a lane point does next.
enum Next {
    /// Integrate this period in its lane.
    Integrate(LaneProblem<4>),
    /// Integrate this period with the variational equations in its lane.
    Sensitivity(LaneProblem<20>),
    /// Converged: the point's output.
    Done(Box<PointOutput>),
    /// Leave the straight path: rerun the point on the scalar path.
    Scalar,
}

/// One shooting point in a lane: `simulate::shooting_steady_state` and `grid_shooting::shoot`
/// as a state machine that hands out one period at a time (see the module).
struct LanePoint<'a> {
    device: &'a Device,
    model: LinearStroke<'a>,
    metric_names: &'a [String],
    samples_per_cycle: usize,
    period: f64,
    tol: f64,
    accept_tol: f64,
    newton_tol: LaneTolerances,
    grid_tol: LaneTolerances,
    max_steps: usize,
    grid: Rc<[f64]>,
    /// The actuator force at the grid's stage times (`None` until asked, and after the grid
    /// changes).
    forcing: Option<Rc<[f64]>>,
    times: Rc<[f64]>,
    jac: DMatrix<f64>,
    /// Whether `jac` is an exact Jacobian at `y` (after a re-linearisation).
    fresh: bool,
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

/// `(P(y) − y, ‖P(y) − y‖∞ / (1 + ‖y‖∞))` (as `grid_shooting`).
fn residual(y: &State, py: &State) -> (DVector<f64>, f64) {
    let (yv, pv) = (y.compact(2), py.compact(2));
    let f = pv - &yv;
    let r = f.amax() / (1.0 + yv.amax());
    (f, r)
}

/// Least-squares Newton step (as `grid_shooting`).
fn newton_step(jac: &DMatrix<f64>, eye: &DMatrix<f64>, f: &DVector<f64>) -> Option<DVector<f64>> {
    let svd = (jac - eye).svd(true, true);
    let cutoff = 1e-10 * svd.singular_values.max().max(f64::MIN_POSITIVE);
    svd.solve(&(-f), cutoff).ok()
}

impl<'a> LanePoint<'a> {
    /// The point and its first period, or `None` when it does not qualify (see the module).
    fn new(
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
        let chooser = GRID_TOLERANCE_FACTOR.clamp(f64::MIN_POSITIVE, 1.0);
        let n_samples = options.samples_per_cycle;
        // The recorded window's sample times, as `record_window` makes them.
        let times = match times_cache {
            Some((p, n, times)) if *p == period && *n == n_samples => times.clone(),
            _ => {
                let (t_start, window) = (grid[0], period);
                let t_end = t_start + window;
                let times: Rc<[f64]> = (0..=n_samples)
                    .map(|k| {
                        if k == n_samples {
                            t_end
                        } else {
                            t_start + window * k as f64 / n_samples as f64
                        }
                    })
                    .collect();
                *times_cache = Some((period, n_samples, times.clone()));
                times
            }
        };
        let point = Self {
            device,
            model,
            metric_names,
            samples_per_cycle: n_samples,
            period,
            tol: (1e-2 * options.steady_tol).min(0.1 * options.rtol),
            accept_tol: options.steady_tol,
            newton_tol: LaneTolerances {
                rtol: options.rtol,
                atol: options.atol,
            },
            grid_tol: LaneTolerances {
                rtol: options.rtol * chooser,
                atol: options.atol * chooser,
            },
            max_steps: options.max_steps,
            grid: grid.into(),
            forcing: None,
            times,
            jac,
            fresh: false,
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
            adaptive: Some(self.max_steps),
            y0: compact4(&self.y),
            times: Rc::from([]),
            tol: self.newton_tol,
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
            adaptive: Some(self.max_steps),
            y0: c0,
            times: Rc::from([]),
            tol: self.grid_tol,
        })
    }

    /// Continues after the variational period ended with `outcome`.
    fn resume_sensitivity(&mut self, outcome: LaneOutcome<20>) -> Next {
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
                Pending::Map | Pending::Pick | Pending::Sensitivity => self.grid_tol,
                Pending::Trial { .. } | Pending::WarmUp | Pending::Relinearise { .. } => {
                    self.newton_tol
                }
            },
        }
    }

    /// Feeds recorded samples to the metrics in order, as the scalar window's sink does
    /// (`StrokeSample::of_stroke_device`, then the accumulator); `false`: the scalar path
    /// would fail here.
    fn sample(&mut self, block: &SampleBlock) -> bool {
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
        if self.iterations >= MAX_NEWTON {
            return Next::Scalar;
        }
        self.iterations += 1;
        let Some(delta) = newton_step(&self.jac, &self.eye, &self.f) else {
            return Next::Scalar;
        };
        let scale = 1.0 + self.y.compact(2).amax();
        let step = delta.amax() / scale;
        // The next iterate's error: the step times the contraction seen so far (Newton's
        // quadratic model after a fresh Jacobian; unknown, so 1, after a neighbour's).
        let contraction = match self.last_step {
            Some(s) => step / s,
            None if self.fresh => step,
            None => 1.0,
        }
        .min(1.0);
        let y_new = State::from_compact(2, &(self.y.compact(2) + &delta));
        let last = contraction * step <= self.tol || step <= 1e-3 * self.tol;
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
    fn resume(&mut self, outcome: LaneOutcome<4>) -> Next {
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
                Next::Integrate(LaneProblem {
                    grid: Rc::from([0.0, self.period]),
                    adaptive: Some(self.max_steps),
                    y0: compact4(&self.y),
                    times: Rc::from([]),
                    tol: self.grid_tol,
                })
            }
            (Pending::Pick, LaneOutcome::Done { y, steps, .. }) => {
                self.grid = steps.into();
                self.forcing = None;
                self.periods = 1;
                (self.f, self.res) = residual(&self.y, &expand4(&y));
                self.iterate()
            }
            (Pending::Pick, LaneOutcome::Failed) => Next::Scalar,
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
                let tol = self.tol;
                if last && res_new > tol && res_new <= self.accept_tol && !self.fresh {
                    // Re-linearise at the candidate, then decide with the exact Jacobian.
                    return self.relinearise(&y_new, Some((y_new, f_new, res_new)));
                }
                let neutral = || {
                    res_new <= self.accept_tol
                        && newton_step(&self.jac, &self.eye, &f_new)
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
                // Good Broyden: the secant condition on the step just taken.
                let s_dot = delta.dot(&delta);
                if s_dot > 0.0 {
                    let mismatch = (&f_new - &self.f) - (&self.jac - &self.eye) * &delta;
                    self.jac += mismatch * delta.transpose() / s_dot;
                }
                self.fresh = false;
                (self.y, self.f, self.res) = (y_new, f_new, res_new);
                self.last_step = Some(step);
                self.iterate()
            }
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
            tol: self.newton_tol,
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
        let steady_state = state.without_work();
        let result = SimulationResult {
            trajectory: Trajectory::default(),
            metrics: self.metrics.finish(),
            cycles_run: self.warm_cycles + self.periods - 1,
            converged: true,
            period_ms: self.period,
            residual,
            steady_state,
            multipliers,
            monodromy: Some(self.jac.clone()),
            step_grid: self.grid.to_vec(),
        };
        let coordinates = self.device.coordinates(&steady_state).ok();
        COMPLETED_IN_LANES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        Next::Done(Box::new(PointOutput::keep(
            result,
            self.metric_names,
            false,
            self.samples_per_cycle,
            coordinates,
        )))
    }
}

/// The last forcing table built in a group: its grid, actuator and forces.
type ForcingCache = Option<(Rc<[f64]>, crate::actuator::Actuator, Rc<[f64]>)>;

/// `point`'s forcing table, from `cache` when a previous point had the same grid and drive.
fn forcing(point: &mut LanePoint<'_>, cache: &mut ForcingCache) -> Rc<[f64]> {
    if let Some(f) = &point.forcing {
        return f.clone();
    }
    let table = match cache {
        Some((grid, actuator, table))
            if **grid == *point.grid && actuator == point.model.actuator() =>
        {
            table.clone()
        }
        _ => {
            let table = point.model.forcing(&point.grid);
            *cache = Some((
                point.grid.clone(),
                point.model.actuator().clone(),
                table.clone(),
            ));
            table
        }
    };
    point.forcing = Some(table.clone());
    table
}

/// A chain being worked through by one lane.
struct Cursor<'a> {
    chain: usize,
    /// The next point of the chain to start.
    next: usize,
    end: usize,
    previous: Vec<Converged>,
    out: Vec<Result<PointOutput>>,
    /// The point in the lane: its index, start and state.
    point: Option<(usize, ChainStart, LanePoint<'a>)>,
}

type ChainResults = Vec<Option<Result<Vec<Result<PointOutput>>>>>;

/// Runs the `n_chains` chains of `points` with `lanes` lanes per group of chains (see the
/// module); slot `c` is chain `c`'s results as `sweep::run_points` collects them.
///
/// # Errors
/// [`Error::InvalidParameter`] for a bad thread count.
pub(crate) fn run_chains(
    points: &[Result<(Device, SimulationOptions)>],
    metric_names: &[String],
    n_chains: usize,
    threads: usize,
    lanes: usize,
    control: &SweepControl,
) -> Result<ChainResults> {
    // Groups small enough to keep every thread busy, large enough to refill the lanes.
    let per_group = n_chains.div_ceil(threads.max(1)).clamp(1, 2 * lanes);
    let n_groups = n_chains.div_ceil(per_group);
    let groups = run_tasks(n_groups, threads, control, false, |g| {
        let chains = g * per_group..((g + 1) * per_group).min(n_chains);
        Ok(run_group(points, metric_names, chains, lanes, control))
    })?;
    let mut out: ChainResults = Vec::with_capacity(n_chains);
    for (g, group) in groups.into_iter().enumerate() {
        let len = ((g + 1) * per_group).min(n_chains) - g * per_group;
        match group {
            Some(Ok(chains)) => out.extend(chains.into_iter().map(|c| Some(Ok(c)))),
            Some(Err(e)) => out.extend((0..len).map(|_| Some(Err(e.clone())))),
            None => out.extend((0..len).map(|_| None)),
        }
    }
    Ok(out)
}

/// The group's two lane steppers (the state, and the state with its variational equations).
struct Steppers {
    state: LaneStepper<4>,
    variational: LaneStepper<20>,
    /// Lanes started since each stepper's last run.
    fresh: [u32; 2],
}

/// Starts `next` of `point` in lane `l`: `None` while it is in flight, else the point is
/// complete (`Some(Some(output))` from the lanes, `Some(None)`: run it on the scalar path).
fn launch<'a>(
    l: usize,
    next: Next,
    point: &mut LanePoint<'a>,
    steppers: &mut Steppers,
    models: &mut LinearStrokeLanes<'a>,
    forcing_cache: &mut ForcingCache,
) -> Option<Option<PointOutput>> {
    match next {
        Next::Integrate(problem) => {
            // A lane reads only its own point's table (adaptive periods evaluate the drive).
            let table = problem
                .adaptive
                .is_none()
                .then(|| forcing(point, forcing_cache));
            models.load_forcing(l, table);
            let mut sink = |_: usize, block: &SampleBlock| point.sample(block);
            if steppers.state.start(l, problem, &mut sink) {
                steppers.fresh[0] |= 1 << l;
                None
            } else {
                Some(None)
            }
        }
        Next::Sensitivity(problem) => {
            let table = problem
                .adaptive
                .is_none()
                .then(|| forcing(point, forcing_cache));
            models.load_forcing(l, table);
            if steppers
                .variational
                .start(l, problem, &mut |_: usize, _: &SampleBlock| true)
            {
                steppers.fresh[1] |= 1 << l;
                None
            } else {
                Some(None)
            }
        }
        Next::Done(output) => Some(Some(*output)),
        Next::Scalar => Some(None),
    }
}

/// One group of chains on `lanes` lanes; each chain's results in order (cut short by a
/// cancel).
// The lane index addresses the cursors and both steppers: an index loop reads clearest.
#[allow(clippy::needless_range_loop)]
fn run_group(
    points: &[Result<(Device, SimulationOptions)>],
    metric_names: &[String],
    chains: std::ops::Range<usize>,
    lanes: usize,
    control: &SweepControl,
) -> Vec<Vec<Result<PointOutput>>> {
    let first_chain = chains.start;
    let mut results: Vec<Vec<Result<PointOutput>>> = chains.clone().map(|_| Vec::new()).collect();
    let mut queue = chains;
    let mut cursors: Vec<Option<Cursor<'_>>> = (0..lanes).map(|_| None).collect();
    let mut steppers = Steppers {
        state: LaneStepper::new(),
        variational: LaneStepper::new(),
        fresh: [0; 2],
    };
    let mut models = LinearStrokeLanes::new();
    let mut times_cache = None;
    let mut forcing_cache: ForcingCache = None;
    loop {
        if control.is_cancelled() {
            break;
        }
        // Every lane without a point in flight advances its chain (scalar points in place)
        // to its next lane point, or takes the next chain.
        for l in 0..lanes {
            loop {
                if cursors[l].as_ref().is_some_and(|c| c.point.is_some()) {
                    break;
                }
                if cursors[l].as_ref().is_none_or(|c| c.next == c.end) {
                    if let Some(done) = cursors[l].take() {
                        results[done.chain - first_chain] = done.out;
                    }
                    let Some(chain) = queue.next() else {
                        break;
                    };
                    let range = chain_range(chain, points.len());
                    cursors[l] = Some(Cursor {
                        chain,
                        next: range.start,
                        end: range.end,
                        previous: Vec::with_capacity(2),
                        out: Vec::with_capacity(range.len()),
                        point: None,
                    });
                    continue;
                }
                if control.is_cancelled() {
                    break;
                }
                let cursor = cursors[l].as_mut().expect("a chain is in this lane");
                let i = cursor.next;
                cursor.next += 1;
                let start = chain_start(points, &mut cursor.previous, i);
                // Continued from the neighbours, or (a chain's start) from the spec's own state.
                let lane_point = points[i].as_ref().ok().and_then(|(device, own)| {
                    let options = continued_options(points, i, &start);
                    LanePoint::new(
                        device,
                        options.as_ref().unwrap_or(own),
                        metric_names,
                        &mut times_cache,
                    )
                });
                let Some((mut point, next)) = lane_point else {
                    finish_point(points, metric_names, cursor, i, &start, None, control);
                    continue;
                };
                models.load(l, &point.model);
                match launch(
                    l,
                    next,
                    &mut point,
                    &mut steppers,
                    &mut models,
                    &mut forcing_cache,
                ) {
                    None => cursor.point = Some((i, start, point)),
                    Some(done) => {
                        finish_point(points, metric_names, cursor, i, &start, done, control)
                    }
                }
            }
        }
        if control.is_cancelled() || !(steppers.state.any_busy() || steppers.variational.any_busy())
        {
            break;
        }
        let mut finished: Vec<(usize, Result<LaneOutcome<4>, LaneOutcome<20>>)> = Vec::new();
        if steppers.state.any_busy() {
            let mut sink = |l: usize, block: &SampleBlock| {
                cursors[l]
                    .as_mut()
                    .and_then(|c| c.point.as_mut())
                    .is_some_and(|(_, _, p)| p.sample(block))
            };
            let fresh = std::mem::take(&mut steppers.fresh[0]);
            finished.extend(
                steppers
                    .state
                    .run(&models, fresh, &mut sink)
                    .into_iter()
                    .map(|(l, o)| (l, Ok(o))),
            );
        }
        if steppers.variational.any_busy() {
            let fresh = std::mem::take(&mut steppers.fresh[1]);
            let rhs = VariationalLanes(&models);
            finished.extend(
                steppers
                    .variational
                    .run(&rhs, fresh, &mut |_: usize, _: &SampleBlock| true)
                    .into_iter()
                    .map(|(l, o)| (l, Err(o))),
            );
        }
        for (l, outcome) in finished {
            let cursor = cursors[l].as_mut().expect("a busy lane has a chain");
            let (i, start, mut point) = cursor.point.take().expect("a busy lane has a point");
            let next = match outcome {
                Ok(o) => point.resume(o),
                Err(o) => point.resume_sensitivity(o),
            };
            match launch(
                l,
                next,
                &mut point,
                &mut steppers,
                &mut models,
                &mut forcing_cache,
            ) {
                None => cursor.point = Some((i, start, point)),
                Some(done) => finish_point(points, metric_names, cursor, i, &start, done, control),
            }
        }
    }
    for cursor in cursors.into_iter().flatten() {
        results[cursor.chain - first_chain] = cursor.out;
    }
    results
}

/// Completes point `i` of the chain in `cursor`: `done` is its lane result, else it runs on
/// the scalar path; then the chain's bookkeeping of `sweep::run_points`.
fn finish_point(
    points: &[Result<(Device, SimulationOptions)>],
    metric_names: &[String],
    cursor: &mut Cursor<'_>,
    i: usize,
    start: &ChainStart,
    done: Option<PointOutput>,
    control: &SweepControl,
) {
    let result = chain_point(points, i, start, metric_names, false, done.map(Ok));
    remember(&mut cursor.previous, i, &result);
    control.count_point(&result);
    cursor.out.push(result);
}
