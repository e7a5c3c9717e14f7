//! The lanes of a worker: which point each lane works on, refilled from its chain and the
//! sweep's shared queue of chains; one worker per thread of the sweep's rayon pool (see the
//! module `lanes`).

use std::rc::Rc;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use paritysim_error::Result;

use super::linear_stroke::{DriveTables, LinearStrokeLanes, VariationalLanes};
use super::point::{LanePoint, Next};
use crate::device::Device;
use crate::integrate::lanes::{LaneOutcome, LaneStepper, SampleBlock};
use crate::simulate::SimulationOptions;
use crate::sweep::{
    ChainStart, Converged, PointOutput, SweepControl, chain_point, chain_range, chain_start,
    continued_options, remember, run_tasks,
};

/// A lane's drive tables: the newest of each kind, which its chain's next point usually
/// shares (the same grid; the same drive, or one that scales the same sines).
type ForcingCache = DriveTables;

/// `point`'s forcing table, from `cache` when a previous point had the same grid and drive.
fn forcing(point: &mut LanePoint<'_>, cache: &mut ForcingCache) -> Rc<[f64]> {
    if let Some(f) = &point.forcing {
        return f.clone();
    }
    let table = cache.forces(&point.grid, point.model.actuator());
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

/// How a lane's period ended, by stepper.
enum Ended {
    State(LaneOutcome<4>),
    Variational(LaneOutcome<20>),
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

/// The worker's lane steppers (the drivetrain state, with its variational equations).
struct Steppers {
    state: LaneStepper<4>,
    variational: LaneStepper<20>,
    /// Lanes started since each stepper's last run.
    fresh: [u32; 2],
}

/// Starts `next` of `task` in lane `l`: `None` while it is in flight, else the point is
/// complete (`Some(Some(output))` from the lanes, `Some(None)`: run it on the scalar path).
fn launch<'a>(
    l: usize,
    next: Next,
    point: &mut LanePoint<'a>,
    steppers: &mut Steppers,
    models: &mut LinearStrokeLanes<'a>,
    forcing_cache: &mut ForcingCache,
) -> Option<Option<PointOutput>> {
    let deadline = point.deadline;
    match next {
        Next::Integrate(problem) => {
            // A lane reads only its own point's table (adaptive periods evaluate the drive).
            let table = problem
                .adaptive
                .is_none()
                .then(|| forcing(point, forcing_cache));
            models.load_forcing(l, table);
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
            models.load_forcing(l, table);
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
        fresh: [0; 2],
    };
    let mut models = LinearStrokeLanes::new();
    let mut times_cache = None;
    // One per lane: a lane's next point usually has its chain predecessor's grid (one cache
    // for the worker was overwritten by the other lanes' chains: 366 tables for 256 points).
    let mut forcing_cache: Vec<ForcingCache> =
        (0..lanes).map(|_| DriveTables::newest_only()).collect();
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
        let busy = steppers.state.any_busy() || steppers.variational.any_busy();
        if control.is_cancelled() || !busy {
            break;
        }
        let mut finished: Vec<(usize, Ended)> = Vec::new();
        if steppers.state.any_busy() {
            let mut sink = |l: usize, block: &SampleBlock| {
                cursors[l]
                    .as_mut()
                    .and_then(|c| c.point.as_mut())
                    .is_some_and(|(_, _, point)| point.sample(block))
            };
            let fresh = std::mem::take(&mut steppers.fresh[0]);
            finished.extend(
                steppers
                    .state
                    .run(&models, fresh, &mut sink)
                    .into_iter()
                    .map(|(l, o)| (l, Ended::State(o))),
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
                    .map(|(l, o)| (l, Ended::Variational(o))),
            );
        }
        for (l, outcome) in finished {
            let cursor = cursors[l].as_mut().expect("a busy lane has a chain");
            let (i, start, mut point) = cursor.point.take().expect("a busy lane has a point");
            // The point's `max_wall_ms` is spent: its row is the budget error (as the scalar
            // run's), not a scalar rerun.
            let timeout = match outcome {
                Ended::State(_) => steppers.state.take_timeout(l),
                Ended::Variational(_) => steppers.variational.take_timeout(l),
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
            let next = match outcome {
                Ended::State(o) => point.resume(o),
                Ended::Variational(o) => point.resume_sensitivity(o),
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
