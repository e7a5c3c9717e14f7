//! DOP853 for [`LANES`] independent problems at once, one per SIMD lane (`wide::f64x4`): the
//! ensemble technique of heyoka and MPGOS (several sweep points integrated together, each lane
//! with its own time, step size, state and accept/reject decision, refilled when its problem
//! ends; `crate::lanes` schedules them).
//!
//! * **Fixed grids** (the frozen-grid periods of [`crate::SteadyState::Shooting`], most of a
//!   chained sweep point's work; docs/findings.md §7), with the error estimate counted per
//!   lane (`over_tolerance`) and the dense output four samples at a time per lane.
//! * **Adaptive** lanes with Hairer's initial step and step control per lane (the loop of
//!   `drive` in integrate/adaptive.rs): a rejected lane retries from its own state while the others
//!   move on. They return the accepted step times (the grid the fixed-grid periods retrace).
//! * The state is the compact `[q1, q2, q̇1, q̇2]`, optionally followed by uncontrolled entries
//!   (`M = 20`: the variational equations' `Φ`, as in integrate/variational.rs).
//!
//! Every lane performs exactly the scalar path's floating-point operations in the same order
//! (the stages of [`super::Dop853::attempt`], its error norm and dense output, the step
//! control of `drive`): SIMD addition, multiplication, division and square root are the IEEE
//! operations of the scalar code and nothing is fused, so a lane's result is bit-identical to
//! the scalar integration of the same problem (tested in tests/dynamics/lanes.rs).

// Index loops on purpose: they mirror dop853.rs line by line (the operation order is the contract).
#![allow(clippy::needless_range_loop)]

use std::convert::Infallible;
use std::rc::Rc;
use std::time::Instant;

use paritysim_error::Error;

use wide::f64x4;

use super::super::State;
use super::super::budget::{self, CHECK_EVERY};
use super::super::lane_control::{Adaptive, Control};
use super::*;

/// Problems integrated at once.
pub(crate) const LANES: usize = 4;

type V = f64x4;

/// One lane's value of `v`.
#[inline]
fn lane(v: V, l: usize) -> f64 {
    v.as_array()[l]
}

/// `v` with lane `l` set to `x`.
#[inline]
fn with_lane(v: V, l: usize, x: f64) -> V {
    let mut a = v.to_array();
    a[l] = x;
    V::new(a)
}

/// The right-hand side of several lanes on the compact layout `[q1, q2, q̇1, q̇2]`.
pub(crate) trait LaneRhs<const M: usize> {
    /// Writes `f(t, y)` of every lane; `stage[l]` is lane `l`'s position in the list of
    /// [`stage_times`] of its grid ([`NO_STAGE`] outside it), for right-hand sides that
    /// tabulate their time dependence. Returns the bit mask of lanes whose evaluation failed
    /// (left out of the domain of the model).
    fn eval(&self, t: [f64; LANES], stage: [usize; LANES], y: &[V; M], dydt: &mut [V; M]) -> u32;
}

/// Right-hand side evaluations per step in [`stage_times`]: the step's start, stages 2–12,
/// and the three dense-output stages.
pub(crate) const STAGES_PER_STEP: usize = 15;

/// A stage outside a grid's [`stage_times`].
pub(crate) const NO_STAGE: usize = usize::MAX;

/// Every time at which a fixed-grid integration on `grid` evaluates the right-hand side, in
/// the table order the stepper's `stage` indices refer to (`STAGES_PER_STEP` per step, then
/// the grid's end), computed with the stepper's own arithmetic (`t + c h`).
pub(crate) fn stage_times(grid: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(STAGES_PER_STEP * grid.len());
    for pair in grid.windows(2) {
        let (t, h) = (pair[0], pair[1] - pair[0]);
        out.push(t);
        for c in [C2, C3, C4, C5, C6, C7, C8, C9, C10, C11, 1.0, C14, C15, C16] {
            out.push(t + c * h);
        }
    }
    out.extend(grid.last());
    out
}

/// Tolerances of one lane's error estimate (see [`super::Tolerances`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct LaneTolerances {
    pub(crate) rtol: f64,
    pub(crate) atol: f64,
}

/// One integration given to a lane: on a fixed grid, or adaptive from `grid[0]` to the
/// grid's end.
pub(crate) struct LaneProblem<const M: usize> {
    /// Step times (at least two, increasing); adaptive: only the span `[t0, t_end]` is read.
    pub(crate) grid: Rc<[f64]>,
    /// `Some(max_steps)`: adaptive steps (Hairer's control, as `RungeKutta`), returning the
    /// accepted step times in [`LaneOutcome::Done`]; no samples.
    pub(crate) adaptive: Option<usize>,
    /// Initial compact state at `grid[0]`.
    pub(crate) y0: [f64; M],
    /// Sample times (sorted, within the grid's span).
    pub(crate) times: Rc<[f64]>,
    /// Tolerances of the error estimate (counted in [`LaneOutcome::over_tolerance`]).
    pub(crate) tol: LaneTolerances,
}

/// How a lane's integration ended.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum LaneOutcome<const M: usize> {
    /// The state at the grid's end and the steps whose error estimate exceeded the tolerances.
    Done {
        /// Compact end state.
        y: [f64; M],
        /// See [`super::IntegrationStats::over_tolerance`] (fixed grids).
        over_tolerance: usize,
        /// Adaptive: `t0` and the accepted step times (the grid a fixed-grid run retraces, as
        /// `RungeKutta::advance_with_steps` returns it); empty on fixed grids.
        steps: Vec<f64>,
    },
    /// The scalar path would have returned an error here (the model left its domain, a
    /// non-finite state or error estimate, or the sample sink refused).
    Failed,
}

/// Up to four consecutive samples of one lane: `count` of them from `first` (index in the
/// lane's times), their times and compact states (sample `j` in vector lane `j`; the others
/// are padding).
pub(crate) struct SampleBlock<const C: usize = 4> {
    /// Index of the first sample in the lane's times.
    pub(crate) first: usize,
    /// Samples in the block (1 to 4).
    pub(crate) count: usize,
    /// Their times.
    pub(crate) t: [f64; 4],
    /// Their compact states `[q1, q2, q̇1, q̇2]`, one sample per vector lane.
    pub(crate) y: [V; C],
}

/// Receives the samples of a lane in blocks, in order: `(lane, block)`; `false` fails the
/// lane.
pub(crate) type LaneSink<'a, const C: usize = 4> = dyn FnMut(usize, &SampleBlock<C>) -> bool + 'a;

/// Per-lane progress.
#[derive(Clone, Default)]
struct Progress {
    adaptive: Option<Adaptive>,
    grid: Rc<[f64]>,
    times: Rc<[f64]>,
    step: usize,
    next: usize,
    over_tolerance: usize,
    active: bool,
}

/// [`LANES`] lanes of DOP853 on fixed grids.
///
/// `C` entries of the state are controlled and sampled: the compact `[coords (C/2), rates
/// (C/2)]` (4: the two-DOF drivetrain, 8: the stroke-plane device); the rest (`M > C`: a
/// variational system's sensitivities) ride along uncontrolled, as in
/// integrate/variational.rs.
pub(crate) struct LaneStepper<const M: usize, const C: usize = 4> {
    y: [V; M],
    f0: [V; M],
    stages: Dop853<M, V>,
    rtol: V,
    atol: V,
    lanes: [Progress; LANES],
    /// Each lane's point's wall-time deadline and budget (ms), checked every
    /// [`CHECK_EVERY`] steps as the scalar integrator checks its run's budget.
    deadlines: [Option<(Instant, f64)>; LANES],
    /// Lanes stopped by their deadline: the budget error (taken by [`Self::take_timeout`]).
    timeouts: [Option<Error>; LANES],
    steps: usize,
}

impl<const M: usize, const C: usize> LaneStepper<M, C> {
    /// All lanes idle.
    pub(crate) fn new() -> Self {
        let z = [V::splat(0.0); M];
        Self {
            y: z,
            f0: z,
            stages: Dop853::new(),
            rtol: V::splat(1.0),
            atol: V::splat(1.0),
            lanes: std::array::from_fn(|_| Progress::default()),
            deadlines: [None; LANES],
            timeouts: std::array::from_fn(|_| None),
            steps: 0,
        }
    }

    /// The wall-time deadline of lane `l`'s point (`budget::deadline`), for the problems it
    /// is given from now on.
    pub(crate) fn set_deadline(&mut self, l: usize, deadline: Option<(Instant, f64)>) {
        self.deadlines[l] = deadline;
    }

    /// The budget error of lane `l` if its last problem was stopped by its deadline (it then
    /// finished as [`LaneOutcome::Failed`]).
    pub(crate) fn take_timeout(&mut self, l: usize) -> Option<Error> {
        self.timeouts[l].take()
    }

    /// Stops the busy lanes past their deadline (the budget error, as the scalar integrator
    /// raises it, with the lane's time and state).
    fn check_deadlines(&mut self, finished: &mut Vec<(usize, LaneOutcome<M>)>) {
        if !self.deadlines.iter().any(Option::is_some) {
            return;
        }
        let now = Instant::now();
        for l in 0..LANES {
            let (p, deadline) = (&mut self.lanes[l], self.deadlines[l]);
            let Some((_, ms)) = deadline.filter(|(d, _)| p.active && now >= *d) else {
                continue;
            };
            let t = p.adaptive.as_ref().map_or(p.grid[p.step], |a| a.t);
            let mut y = State::default();
            for i in 0..C / 2 {
                y.coords[i] = lane(self.y[i], l);
                y.rates[i] = lane(self.y[C / 2 + i], l);
            }
            p.active = false;
            self.timeouts[l] = Some(budget::stop_error(budget::Stop::Wall(ms), t, y.to_vec()));
            finished.push((l, LaneOutcome::Failed));
        }
    }

    /// Whether any lane is integrating.
    pub(crate) fn any_busy(&self) -> bool {
        self.lanes.iter().any(|p| p.active)
    }

    /// Gives `problem` to the idle lane `l`: its samples at `grid[0]` go to `sink` at once.
    /// Its first derivative is evaluated by the next [`Self::run`]. `false` (lane left idle)
    /// when the sink refuses a sample or the grid is too short.
    pub(crate) fn start(
        &mut self,
        l: usize,
        problem: LaneProblem<M>,
        sink: &mut LaneSink<'_, C>,
    ) -> bool {
        if problem.grid.len() < 2 {
            return false;
        }
        let t0 = problem.grid[0];
        let at_start = problem.times.partition_point(|&s| s <= t0);
        let y0: [V; C] = std::array::from_fn(|i| V::splat(problem.y0[i]));
        if !emit_constant(l, &problem.times, 0, at_start, &y0, sink) {
            return false;
        }
        let next = at_start;
        for i in 0..M {
            self.y[i] = with_lane(self.y[i], l, problem.y0[i]);
        }
        self.rtol = with_lane(self.rtol, l, problem.tol.rtol);
        self.atol = with_lane(self.atol, l, problem.tol.atol);
        let adaptive = problem.adaptive.map(|max_steps| Adaptive {
            t: t0,
            t_end: problem.grid[problem.grid.len() - 1],
            h: 0.0,
            fac_old: 1e-4,
            rejected_last: false,
            attempts: 0,
            max_steps,
            last: false,
            steps: vec![t0],
        });
        self.lanes[l] = Progress {
            adaptive,
            grid: problem.grid,
            times: problem.times,
            step: 0,
            next,
            over_tolerance: 0,
            active: true,
        };
        true
    }

    /// Steps every busy lane until at least one finishes; returns `(lane, outcome)` of the
    /// finished ones (those lanes are idle again). `fresh`: mask of lanes started since the
    /// last call (their `f(t0, y0)` is evaluated first).
    pub(crate) fn run<R: LaneRhs<M>>(
        &mut self,
        rhs: &R,
        fresh: u32,
        sink: &mut LaneSink<'_, C>,
    ) -> Vec<(usize, LaneOutcome<M>)> {
        let mut finished = Vec::new();
        if fresh != 0 {
            let t0 = std::array::from_fn(|l| {
                let p = &self.lanes[l];
                if p.active { p.grid[0] } else { 0.0 }
            });
            // Fixed grids read their table at the first stage; adaptive lanes have none.
            let stage = std::array::from_fn(|l| {
                let p = &self.lanes[l];
                if p.active && p.adaptive.is_none() {
                    0
                } else {
                    NO_STAGE
                }
            });
            let mut f = [V::splat(0.0); M];
            let failed = rhs.eval(t0, stage, &self.y, &mut f);
            for l in 0..LANES {
                if fresh & (1 << l) == 0 || !self.lanes[l].active {
                    continue;
                }
                if failed & (1 << l) != 0 {
                    self.lanes[l].active = false;
                    finished.push((l, LaneOutcome::Failed));
                    continue;
                }
                for i in 0..M {
                    self.f0[i] = with_lane(self.f0[i], l, lane(f[i], l));
                }
                if self.lanes[l].adaptive.is_some() && !self.initial_step(rhs, l) {
                    self.lanes[l].active = false;
                    finished.push((l, LaneOutcome::Failed));
                }
            }
        }
        while finished.is_empty() && self.any_busy() {
            self.step(rhs, sink, &mut finished);
            self.steps += 1;
            if self.steps % CHECK_EVERY == 0 {
                self.check_deadlines(&mut finished);
            }
        }
        finished
    }

    /// Hairer's initial step of adaptive lane `l` (`initial_step` of integrate/adaptive.rs on
    /// this lane alone); `false` when its extra evaluation fails.
    fn initial_step(&mut self, rhs: &dyn LaneRhs<M>, l: usize) -> bool {
        let y0: [f64; M] = std::array::from_fn(|i| lane(self.y[i], l));
        let f0: [f64; M] = std::array::from_fn(|i| lane(self.f0[i], l));
        let tol = Tolerances {
            rtol: lane(self.rtol, l),
            atol: lane(self.atol, l),
            controlled: C,
        };
        let a = self.lanes[l].adaptive.as_mut().expect("an adaptive lane");
        let mut one = OneLane::<M, C> { rhs, l };
        match super::super::initial_step(&mut one, 8, &tol, a.t, &y0, &f0, a.t_end - a.t) {
            Ok(h) => {
                a.h = h;
                true
            }
            Err(_) => false,
        }
    }

    /// One step of every busy lane (fixed, or an adaptive attempt; idle lanes repeat a
    /// harmless zero step).
    fn step<R: LaneRhs<M>>(
        &mut self,
        rhs: &R,
        sink: &mut LaneSink<'_, C>,
        finished: &mut Vec<(usize, LaneOutcome<M>)>,
    ) {
        let mut t = [0.0; LANES];
        let mut t_new = [0.0; LANES];
        let mut hs = [0.0; LANES];
        // Lanes whose adaptive control gives up before attempting (the scalar errors).
        let mut given_up = 0u32;
        for (l, p) in self.lanes.iter_mut().enumerate() {
            if !p.active {
                continue;
            }
            match &mut p.adaptive {
                None => {
                    t[l] = p.grid[p.step];
                    t_new[l] = p.grid[p.step + 1];
                    hs[l] = t_new[l] - t[l];
                }
                Some(a) => {
                    if a.attempts >= a.max_steps
                        || 0.1 * a.h.abs() <= a.t.abs() * f64::EPSILON
                        || !a.h.is_finite()
                    {
                        given_up |= 1 << l;
                    }
                    a.last = a.t + 1.01 * a.h >= a.t_end;
                    if a.last {
                        a.h = a.t_end - a.t;
                    }
                    t[l] = a.t;
                    hs[l] = a.h;
                    t_new[l] = if a.last { a.t_end } else { a.t + a.h };
                }
            }
        }
        let h = V::new(hs);
        let at = |c: f64| -> [f64; LANES] { std::array::from_fn(|l| t[l] + c * hs[l]) };
        let base: [usize; LANES] = std::array::from_fn(|l| {
            let p = &self.lanes[l];
            if p.active && p.adaptive.is_none() {
                p.step * STAGES_PER_STEP
            } else {
                NO_STAGE
            }
        });
        let idx = |s: usize| -> [usize; LANES] { base.map(|b| b.saturating_add(s)) };
        let mut failed = 0u32;
        let (y, f0, tol) = (self.y, self.f0, (C, self.atol, self.rtol));
        let err = self
            .stages
            .try_step(&y, &f0, h, tol, |stage, c, ys, f| {
                failed |= rhs.eval(at(c), idx(stage), ys, f);
                Ok::<(), Infallible>(())
            })
            .unwrap_or_else(|never| match never {});
        // Failures of the new derivative count only on accepted steps (the scalar evaluates
        // it after accepting).
        let mut f1 = [V::splat(0.0); M];
        let failed_f1 = rhs.eval(t_new, idx(STAGES_PER_STEP), &self.stages.y1, &mut f1);
        let y1_finite = self.stages.y1[..C]
            .iter()
            .fold(V::splat(0.0).simd_eq(V::splat(0.0)), |all, v| {
                all & v.is_finite()
            })
            .to_bitmask();
        let err_finite = err.is_finite().to_bitmask();
        let wants_dense = (0..LANES).any(|l| {
            let p = &self.lanes[l];
            p.active && p.next < p.times.len() && p.times[p.next] < t_new[l]
        });
        if wants_dense {
            failed |= self.prepare_dense(rhs, &t, &base, h, &f1);
        }
        let mut accepted = [true; LANES];
        for l in 0..LANES {
            if !self.lanes[l].active {
                continue;
            }
            let bit = 1 << l;
            if self.lanes[l].adaptive.is_some() {
                let err = lane(err, l);
                let p = &mut self.lanes[l];
                let a = p.adaptive.as_mut().expect("an adaptive lane");
                let outcome = a.control(err, given_up & bit != 0, failed & bit != 0, || {
                    failed_f1 & bit == 0 && y1_finite & bit != 0
                });
                accepted[l] = outcome == Control::Accepted || outcome == Control::Finished;
                match outcome {
                    Control::Failed => {
                        p.active = false;
                        finished.push((l, LaneOutcome::Failed));
                    }
                    Control::Finished => {
                        p.active = false;
                        finished.push((
                            l,
                            LaneOutcome::Done {
                                y: std::array::from_fn(|i| lane(self.stages.y1[i], l)),
                                over_tolerance: 0,
                                steps: std::mem::take(&mut a.steps),
                            },
                        ));
                    }
                    Control::Accepted | Control::Rejected => {}
                }
                continue;
            }
            let ok = failed & bit == 0
                && failed_f1 & bit == 0
                && err_finite & bit != 0
                && y1_finite & bit != 0
                && self.emit(l, t[l], hs[l], t_new[l], sink);
            let p = &mut self.lanes[l];
            if lane(err, l) > 1.0 {
                p.over_tolerance += 1;
            }
            p.step += 1;
            if !ok {
                p.active = false;
                finished.push((l, LaneOutcome::Failed));
            } else if p.step + 1 == p.grid.len() {
                p.active = false;
                finished.push((
                    l,
                    LaneOutcome::Done {
                        y: std::array::from_fn(|i| lane(self.stages.y1[i], l)),
                        over_tolerance: p.over_tolerance,
                        steps: Vec::new(),
                    },
                ));
            }
        }
        if accepted.iter().all(|&a| a) {
            self.y = self.stages.y1;
            self.f0 = f1;
        } else {
            // Rejected lanes retry from the same state and derivative.
            for i in 0..M {
                let (mut y, mut f0) = (self.y[i].to_array(), self.f0[i].to_array());
                let (y1, f1) = (self.stages.y1[i].to_array(), f1[i].to_array());
                for l in (0..LANES).filter(|&l| accepted[l]) {
                    y[l] = y1[l];
                    f0[l] = f1[l];
                }
                self.y[i] = V::new(y);
                self.f0[i] = V::new(f0);
            }
        }
    }

    /// The samples of lane `l` inside `[t, t_new)` (interpolated, four at a time) and at
    /// `t_new`.
    fn emit(&mut self, l: usize, t: f64, h: f64, t_new: f64, sink: &mut LaneSink<'_, C>) -> bool {
        let p = &mut self.lanes[l];
        let inside = p.next + p.times[p.next..].partition_point(|&s| s < t_new);
        if inside > p.next {
            // This lane's interpolant, broadcast: the vector lanes now hold samples.
            let c: [[V; C]; 8] = std::array::from_fn(|r| {
                std::array::from_fn(|i| V::splat(lane(self.stages.cont[r][i], l)))
            });
            while p.next < inside {
                let count = (inside - p.next).min(4);
                let mut ts = [t; 4];
                ts[..count].copy_from_slice(&p.times[p.next..p.next + count]);
                let s = (V::new(ts) - V::splat(t)) / V::splat(h);
                let y: [V; C] =
                    std::array::from_fn(|i| interpolate(std::array::from_fn(|r| c[r][i]), s));
                let finite = y
                    .iter()
                    .fold(V::splat(0.0).simd_eq(V::splat(0.0)), |all, v| {
                        all & v.is_finite()
                    })
                    .to_bitmask();
                let block = SampleBlock {
                    first: p.next,
                    count,
                    t: ts,
                    y,
                };
                if finite & ((1 << count) - 1) != (1 << count) - 1 || !sink(l, &block) {
                    return false;
                }
                p.next += count;
            }
        }
        let at_end = p.next + p.times[p.next..].partition_point(|&s| s <= t_new);
        let end: [V; C] = std::array::from_fn(|i| V::splat(lane(self.stages.y1[i], l)));
        let ok = emit_constant(l, &p.times, p.next, at_end, &end, sink);
        p.next = at_end;
        ok
    }

    /// The dense output of the step just taken (the scalar `prepare_dense`, on every lane).
    fn prepare_dense<R: LaneRhs<M>>(
        &mut self,
        rhs: &R,
        t: &[f64; LANES],
        base: &[usize; LANES],
        h: V,
        f1: &[V; M],
    ) -> u32 {
        let hs = h.to_array();
        let at = |c: f64| -> [f64; LANES] { std::array::from_fn(|l| t[l] + c * hs[l]) };
        let idx = |s: usize| -> [usize; LANES] { base.map(|b| b.saturating_add(s)) };
        let mut failed = 0;
        let (y, f0) = (self.y, self.f0);
        self.stages
            .dense_output(&y, &f0, f1, h, |stage, c, ys, f| {
                failed |= rhs.eval(at(c), idx(stage), ys, f);
                Ok::<(), Infallible>(())
            })
            .unwrap_or_else(|never| match never {});
        failed
    }
}

/// The samples `from..to` of lane `l` at one state `y` (broadcast), in blocks.
fn emit_constant<const C: usize>(
    l: usize,
    times: &[f64],
    from: usize,
    to: usize,
    y: &[V; C],
    sink: &mut LaneSink<'_, C>,
) -> bool {
    let mut first = from;
    while first < to {
        let count = (to - first).min(4);
        let mut t = [times[first]; 4];
        t[..count].copy_from_slice(&times[first..first + count]);
        let block = SampleBlock {
            first,
            count,
            t,
            y: *y,
        };
        if !sink(l, &block) {
            return false;
        }
        first += count;
    }
    true
}

/// One lane of a [`LaneRhs`] as a scalar right-hand side (for `initial_step`).
struct OneLane<'r, const M: usize, const C: usize> {
    rhs: &'r dyn LaneRhs<M>,
    l: usize,
}

impl<const M: usize, const C: usize> Rhs<M> for OneLane<'_, M, C> {
    fn eval(&mut self, t: f64, y: &[f64; M], dydt: &mut [f64; M]) -> paritysim_error::Result<()> {
        let mut out = [V::splat(0.0); M];
        let failed = self
            .rhs
            .eval([t; LANES], [NO_STAGE; LANES], &y.map(V::splat), &mut out);
        if failed & (1 << self.l) != 0 {
            return Err(paritysim_error::Error::OutOfDomain {
                what: "lane right-hand side".into(),
                detail: format!("t = {t}"),
            });
        }
        for i in 0..M {
            dydt[i] = lane(out[i], self.l);
        }
        Ok(())
    }

    fn expand(&self, c: &[f64; M]) -> State {
        let mut y = State::default();
        y.coords[..C / 2].copy_from_slice(&c[..C / 2]);
        y.rates[..C / 2].copy_from_slice(&c[C / 2..C]);
        y
    }
}
