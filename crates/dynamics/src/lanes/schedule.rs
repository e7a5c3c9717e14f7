//! The lanes of a worker: which point each lane works on, refilled from its chain and the
//! sweep's shared queue of chains; one worker per thread of the sweep's rayon pool (see the
//! module `lanes`).

use std::rc::Rc;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use paritysim_error::Result;

use super::linear_stroke::{LinearStrokeLanes, VariationalLanes};
use super::plane_point::{PlanePoint, PlaneStep};
use super::plane_rhs::{self, M, M12, PlaneLanes};
use super::point::{LanePoint, Next};
use crate::device::Device;
use crate::integrate::lanes::{LaneOutcome, LaneStepper, SampleBlock};
use crate::simulate::SimulationOptions;
use crate::sweep::{
    ChainStart, Converged, PointOutput, SweepControl, chain_point, chain_range, chain_start,
    continued_options, remember, run_tasks,
};

/// The last forcing table built in a lane: its grid, actuator and forces.
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
    point: Option<(usize, ChainStart, Task<'a>)>,
}

/// A point in a lane: a drivetrain-coordinate one, or a switched device's on four
/// coordinates (`M` compact entries) or five (`M12`).
enum Task<'a> {
    Linear(LanePoint<'a>),
    Plane(PlanePoint<'a, M>),
    Plane12(PlanePoint<'a, M12>),
}

/// What a point does next, of its kind.
enum Step {
    Linear(Next),
    Plane(PlaneStep<M>),
    Plane12(PlaneStep<M12>),
}

/// How a lane's period ended, by stepper.
enum Ended {
    State(LaneOutcome<4>),
    Variational(LaneOutcome<20>),
    Plane(LaneOutcome<M>),
    Plane12(LaneOutcome<M12>),
}

type ChainResults = Vec<Option<Result<Vec<Result<PointOutput>>>>>;

/// The chains of a sweep, handed out one at a time to the workers' lanes, and each chain's
/// results as its worker completes it.
struct ChainQueue {
    next: AtomicUsize,
    n_chains: usize,
    /// Whether chain `c` was taken by a worker.
    taken: Vec<AtomicBool>,
    done: Mutex<Vec<Option<Vec<Result<PointOutput>>>>>,
}

impl ChainQueue {
    fn new(n_chains: usize) -> Self {
        Self {
            next: AtomicUsize::new(0),
            n_chains,
            taken: (0..n_chains).map(|_| AtomicBool::new(false)).collect(),
            done: Mutex::new((0..n_chains).map(|_| None).collect()),
        }
    }

    /// The next chain nobody has taken.
    fn take(&self) -> Option<usize> {
        let c = self.next.fetch_add(1, Ordering::Relaxed);
        (c < self.n_chains).then(|| {
            self.taken[c].store(true, Ordering::Release);
            c
        })
    }

    fn complete(&self, chain: usize, results: Vec<Result<PointOutput>>) {
        // A poisoned lock means a worker panicked while storing: the slots are still valid.
        let mut done = self.done.lock().unwrap_or_else(|p| p.into_inner());
        done[chain] = Some(results);
    }
}

/// Runs the `n_chains` chains of `points` on `threads` workers of `lanes` lanes each (see the
/// module); slot `c` is chain `c`'s results as `sweep::run_points` collects them.
///
/// Every worker takes the next chain from one shared queue whenever one of its lanes runs out
/// of points, so the workers stay busy until the last chains (fixed groups of chains left one
/// thread idle while the other finished its group). A point's result does not depend on its
/// lane or on the points beside it, so results are the same for any thread count.
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
    let queue = ChainQueue::new(n_chains);
    // Few chains: spread over the threads (wall time) rather than packed into one worker's
    // lanes.
    let workers = threads.max(1).min(n_chains.max(1));
    let outcomes = run_tasks(workers, threads, control, false, |_| {
        run_worker(points, metric_names, &queue, lanes, control);
        Ok(())
    })?;
    // A worker's panic (an engine bug) fails the chains it had taken and not completed.
    let panic = outcomes.into_iter().find_map(|o| match o {
        Some(Err(e)) => Some(e),
        _ => None,
    });
    let done = queue.done.into_inner().unwrap_or_else(|p| p.into_inner());
    Ok(done
        .into_iter()
        .zip(&queue.taken)
        .map(|(results, taken)| match (results, &panic) {
            (Some(results), _) => Some(Ok(results)),
            (None, Some(e)) if taken.load(Ordering::Acquire) => Some(Err(e.clone())),
            (None, _) => None,
        })
        .collect())
}

/// The worker's lane steppers (the drivetrain state, with its variational equations, and
/// the switched devices' states).
struct Steppers {
    state: LaneStepper<4>,
    variational: LaneStepper<20>,
    plane: LaneStepper<M, M>,
    plane12: LaneStepper<M12, M12>,
    /// Lanes started since each stepper's last run.
    fresh: [u32; 4],
}

/// The right-hand sides of a worker's lanes.
struct Models<'a> {
    linear: LinearStrokeLanes<'a>,
    plane: PlaneLanes<'a, M>,
    plane12: PlaneLanes<'a, M12>,
}

/// Runs a switched-device stepper when busy (see [`LaneStepper::run`]): its samples go to the
/// point in each lane (`point_of` picks it from the lane's task).
fn run_plane<'a, const M: usize>(
    stepper: &mut LaneStepper<M, M>,
    lanes: &PlaneLanes<'a, M>,
    fresh: &mut u32,
    cursors: &mut [Option<Cursor<'a>>],
    point_of: for<'t> fn(&'t mut Task<'a>) -> Option<&'t mut PlanePoint<'a, M>>,
) -> Vec<(usize, LaneOutcome<M>)> {
    if !stepper.any_busy() {
        return Vec::new();
    }
    let mut sink = |l: usize, block: &SampleBlock<M>| {
        cursors[l]
            .as_mut()
            .and_then(|c| c.point.as_mut())
            .and_then(|(_, _, task)| point_of(task))
            .is_some_and(|p| p.sample(block))
    };
    stepper.run(lanes, std::mem::take(fresh), &mut sink)
}

/// Starts a switched point's `step` in lane `l` (see [`launch`]).
fn launch_plane<'a, const M: usize>(
    l: usize,
    step: PlaneStep<M>,
    point: &mut PlanePoint<'a, M>,
    (stepper, fresh): (&mut LaneStepper<M, M>, &mut u32),
    lanes: &mut PlaneLanes<'a, M>,
) -> Option<Option<PointOutput>> {
    match step {
        PlaneStep::Integrate(problem) => {
            lanes.load(l, point.device);
            if problem.adaptive.is_none() {
                lanes.load_forcing(l, point.forcing());
            }
            stepper.set_deadline(l, point.deadline);
            let mut sink = |_: usize, block: &SampleBlock<M>| point.sample(block);
            if stepper.start(l, problem, &mut sink) {
                *fresh |= 1 << l;
                None
            } else {
                Some(None)
            }
        }
        PlaneStep::Done(output) => Some(Some(*output)),
        PlaneStep::Scalar => Some(None),
    }
}

/// Starts `next` of `task` in lane `l`: `None` while it is in flight, else the point is
/// complete (`Some(Some(output))` from the lanes, `Some(None)`: run it on the scalar path).
fn launch<'a>(
    l: usize,
    next: Step,
    task: &mut Task<'a>,
    steppers: &mut Steppers,
    models: &mut Models<'a>,
    forcing_cache: &mut ForcingCache,
) -> Option<Option<PointOutput>> {
    let (next, point) = match (next, task) {
        (Step::Linear(next), Task::Linear(point)) => (next, point),
        (Step::Plane(step), Task::Plane(point)) => {
            let fresh = &mut steppers.fresh[2];
            return launch_plane(
                l,
                step,
                point,
                (&mut steppers.plane, fresh),
                &mut models.plane,
            );
        }
        (Step::Plane12(step), Task::Plane12(point)) => {
            let fresh = &mut steppers.fresh[3];
            let stepper = &mut steppers.plane12;
            return launch_plane(l, step, point, (stepper, fresh), &mut models.plane12);
        }
        // A period of another kind than the point's (not handed out).
        _ => return Some(None),
    };
    let deadline = point.deadline;
    match next {
        Next::Integrate(problem) => {
            // A lane reads only its own point's table (adaptive periods evaluate the drive).
            let table = problem
                .adaptive
                .is_none()
                .then(|| forcing(point, forcing_cache));
            models.linear.load_forcing(l, table);
            steppers.state.set_deadline(l, deadline);
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
            models.linear.load_forcing(l, table);
            steppers.variational.set_deadline(l, deadline);
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

/// One worker: `lanes` lanes fed from `queue` until it is empty; each chain's results (cut
/// short by a cancel) go to the queue as the chain completes.
// The lane index addresses the cursors and both steppers: an index loop reads clearest.
#[allow(clippy::needless_range_loop)]
fn run_worker(
    points: &[Result<(Device, SimulationOptions)>],
    metric_names: &[String],
    queue: &ChainQueue,
    lanes: usize,
    control: &SweepControl,
) {
    let mut cursors: Vec<Option<Cursor<'_>>> = (0..lanes).map(|_| None).collect();
    let mut steppers = Steppers {
        state: LaneStepper::new(),
        variational: LaneStepper::new(),
        plane: LaneStepper::new(),
        plane12: LaneStepper::new(),
        fresh: [0; 4],
    };
    let mut models = Models {
        linear: LinearStrokeLanes::new(),
        plane: PlaneLanes::new(plane_rhs::build),
        plane12: PlaneLanes::new(plane_rhs::build12),
    };
    let mut times_cache = None;
    // One per lane: a lane's next point usually has its chain predecessor's grid (one cache
    // for the worker was overwritten by the other lanes' chains: 366 tables for 256 points).
    let mut forcing_cache: Vec<ForcingCache> = (0..lanes).map(|_| None).collect();
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
                        queue.complete(done.chain, done.out);
                    }
                    let Some(chain) = queue.take() else {
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
                    let options = options.as_ref().unwrap_or(own);
                    LanePoint::new(device, options, metric_names, &mut times_cache)
                        .map(|(p, next)| (Task::Linear(p), Step::Linear(next)))
                        .or_else(|| {
                            PlanePoint::new(device, options, metric_names, &mut times_cache)
                                .map(|(p, step)| (Task::Plane(p), Step::Plane(step)))
                        })
                        .or_else(|| {
                            PlanePoint::new(device, options, metric_names, &mut times_cache)
                                .map(|(p, step)| (Task::Plane12(p), Step::Plane12(step)))
                        })
                });
                let Some((mut point, next)) = lane_point else {
                    finish_point(points, metric_names, cursor, i, &start, None, control);
                    continue;
                };
                if let Task::Linear(p) = &point {
                    models.linear.load(l, &p.model);
                }
                match launch(
                    l,
                    next,
                    &mut point,
                    &mut steppers,
                    &mut models,
                    &mut forcing_cache[l],
                ) {
                    None => cursor.point = Some((i, start, point)),
                    Some(done) => finish_point(
                        points,
                        metric_names,
                        cursor,
                        i,
                        &start,
                        done.map(Ok),
                        control,
                    ),
                }
            }
        }
        let busy = steppers.state.any_busy()
            || steppers.variational.any_busy()
            || steppers.plane.any_busy()
            || steppers.plane12.any_busy();
        if control.is_cancelled() || !busy {
            break;
        }
        let mut finished: Vec<(usize, Ended)> = Vec::new();
        if steppers.state.any_busy() {
            let mut sink = |l: usize, block: &SampleBlock| {
                cursors[l]
                    .as_mut()
                    .and_then(|c| c.point.as_mut())
                    .is_some_and(|(_, _, task)| match task {
                        Task::Linear(p) => p.sample(block),
                        _ => false,
                    })
            };
            let fresh = std::mem::take(&mut steppers.fresh[0]);
            finished.extend(
                steppers
                    .state
                    .run(&models.linear, fresh, &mut sink)
                    .into_iter()
                    .map(|(l, o)| (l, Ended::State(o))),
            );
        }
        if steppers.variational.any_busy() {
            let fresh = std::mem::take(&mut steppers.fresh[1]);
            let rhs = VariationalLanes(&models.linear);
            finished.extend(
                steppers
                    .variational
                    .run(&rhs, fresh, &mut |_: usize, _: &SampleBlock| true)
                    .into_iter()
                    .map(|(l, o)| (l, Ended::Variational(o))),
            );
        }
        finished.extend(
            run_plane(
                &mut steppers.plane,
                &models.plane,
                &mut steppers.fresh[2],
                &mut cursors,
                |t| match t {
                    Task::Plane(p) => Some(p),
                    _ => None,
                },
            )
            .into_iter()
            .map(|(l, o)| (l, Ended::Plane(o))),
        );
        finished.extend(
            run_plane(
                &mut steppers.plane12,
                &models.plane12,
                &mut steppers.fresh[3],
                &mut cursors,
                |t| match t {
                    Task::Plane12(p) => Some(p),
                    _ => None,
                },
            )
            .into_iter()
            .map(|(l, o)| (l, Ended::Plane12(o))),
        );
        for (l, outcome) in finished {
            let cursor = cursors[l].as_mut().expect("a busy lane has a chain");
            let (i, start, mut point) = cursor.point.take().expect("a busy lane has a point");
            // The point's `max_wall_ms` is spent: its row is the budget error (as the scalar
            // run's), not a scalar rerun.
            let timeout = match outcome {
                Ended::State(_) => steppers.state.take_timeout(l),
                Ended::Variational(_) => steppers.variational.take_timeout(l),
                Ended::Plane(_) => steppers.plane.take_timeout(l),
                Ended::Plane12(_) => steppers.plane12.take_timeout(l),
            };
            if let Some(error) = timeout {
                finish_point(
                    points,
                    metric_names,
                    cursor,
                    i,
                    &start,
                    Some(Err(error)),
                    control,
                );
                continue;
            }
            let next = match (outcome, &mut point) {
                (Ended::State(o), Task::Linear(p)) => Step::Linear(p.resume(o)),
                (Ended::Variational(o), Task::Linear(p)) => Step::Linear(p.resume_sensitivity(o)),
                (Ended::Plane(o), Task::Plane(p)) => Step::Plane(p.resume(o)),
                (Ended::Plane12(o), Task::Plane12(p)) => Step::Plane12(p.resume(o)),
                _ => Step::Linear(Next::Scalar),
            };
            match launch(
                l,
                next,
                &mut point,
                &mut steppers,
                &mut models,
                &mut forcing_cache[l],
            ) {
                None => cursor.point = Some((i, start, point)),
                Some(done) => finish_point(
                    points,
                    metric_names,
                    cursor,
                    i,
                    &start,
                    done.map(Ok),
                    control,
                ),
            }
        }
    }
    for cursor in cursors.into_iter().flatten() {
        queue.complete(cursor.chain, cursor.out);
    }
}

/// Completes point `i` of the chain in `cursor`: `done` is its lane result (or error), else
/// it runs on the scalar path; then the chain's bookkeeping of `sweep::run_points`.
fn finish_point(
    points: &[Result<(Device, SimulationOptions)>],
    metric_names: &[String],
    cursor: &mut Cursor<'_>,
    i: usize,
    start: &ChainStart,
    done: Option<Result<PointOutput>>,
    control: &SweepControl,
) {
    let result = chain_point(points, i, start, metric_names, false, done);
    remember(&mut cursor.previous, i, &result);
    control.count_point(&result);
    cursor.out.push(result);
}
