//! The lanes of a group of chains: which point each lane works on, refilled from its chain and
//! the group's queue of chains; groups on the sweep's rayon pool (see the module `lanes`).

use std::rc::Rc;

use paritysim_error::Result;

use super::linear_stroke::{LinearStrokeLanes, VariationalLanes};
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
            steppers.state.set_deadline(l, point.deadline);
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
            steppers.variational.set_deadline(l, point.deadline);
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
    // One per lane: a lane's next point usually has its chain predecessor's grid (one cache
    // for the group was overwritten by the other lanes' chains: 366 tables for 256 points).
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
            // The point's `max_wall_ms` is spent: its row is the budget error (as the scalar
            // run's), not a scalar rerun.
            let timeout = match outcome {
                Ok(_) => steppers.state.take_timeout(l),
                Err(_) => steppers.variational.take_timeout(l),
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
                Ok(o) => point.resume(o),
                Err(o) => point.resume_sensitivity(o),
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
        results[cursor.chain - first_chain] = cursor.out;
    }
    results
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
