//! Fixed-grid periods of several devices at once in the lanes, four at a time: the
//! sensitivities' perturbed period maps and recorded windows (`crate::sensitivity`), which are
//! independent integrations on one grid. Each lane performs the scalar path's operations
//! (see the module `lanes`), so the results are bit-identical to the scalar integrations.

use std::rc::Rc;
use std::sync::atomic::{AtomicUsize, Ordering};

use wide::f64x4;

use crate::device::Device;
use crate::integrate::State;
use crate::integrate::lanes::{
    LANES, LaneOutcome, LaneProblem, LaneStepper, LaneTolerances, SampleBlock,
};
use crate::metrics::MetricsAccumulator;

pub(crate) use super::linear_stroke::{DriveSeed, DriveTables};
use super::linear_stroke::{LinearStroke, LinearStrokeLanes};
use super::point::{compact4, feed_samples};

/// Periods completed here (`super::periods_completed_in_lanes`).
pub(crate) static COMPLETED: AtomicUsize = AtomicUsize::new(0);

/// One period to integrate.
pub(crate) struct Job<'a> {
    pub(crate) device: &'a Device,
    /// The fixed step grid.
    pub(crate) grid: Rc<[f64]>,
    /// The state at `grid[0]`.
    pub(crate) y0: State,
    /// The recorded window's sample times (`record_window`'s), or `None`: the map only.
    pub(crate) times: Option<Rc<[f64]>>,
}

/// A job's state at its grid's end (compact `[q1, q2, q̇1, q̇2]`) and, for a window, its
/// metrics or (captured) its sample states.
pub(crate) struct Done {
    pub(crate) end: [f64; 4],
    pub(crate) metrics: Option<Vec<(String, f64)>>,
    pub(crate) states: SampleBlocks,
}

/// A window's sample states as the lanes read them: sample `s`'s compact component `c` in
/// vector lane `s % 4` of `blocks[s / 4][c]`, a short last block repeating its last sample.
pub(crate) type SampleBlocks = Vec<[f64x4; 4]>;

/// Samples of `K` numbers each (one after another) in blocks of four, as [`SampleBlocks`]
/// holds compact states (`K = 4`): number `k` of sample `s` in vector lane `s % 4` of
/// `blocks[s / 4][k]`, a short last block repeating its last sample.
pub(crate) fn blocks_of<const K: usize>(samples: &[f64]) -> Vec<[f64x4; K]> {
    let mut blocks = Vec::with_capacity(samples.len().div_ceil(LANES * K));
    let mut full = samples.chunks_exact(LANES * K);
    for s in &mut full {
        blocks.push(std::array::from_fn(|k| {
            f64x4::new([s[k], s[K + k], s[2 * K + k], s[3 * K + k]])
        }));
    }
    let rest = full.remainder();
    if rest.len() >= K {
        let in_block = rest.len() / K;
        blocks.push(std::array::from_fn(|k| {
            f64x4::new(std::array::from_fn(|i| {
                if i < in_block { rest[i * K + k] } else { 0.0 }
            }))
        }));
    }
    repeat_last_sample(&mut blocks, samples.len() / K);
    blocks
}

/// Fills the unused lanes of the last of the blocks holding `count` samples with its last
/// sample.
fn repeat_last_sample<const K: usize>(blocks: &mut [[f64x4; K]], count: usize) {
    let used = count % LANES;
    if let Some(last) = blocks.last_mut()
        && used != 0
    {
        for component in last.iter_mut() {
            let lanes = component.as_mut_array();
            let value = lanes[used - 1];
            lanes[used..].fill(value);
        }
    }
}

/// The first `count` samples of `blocks` as compact states, one after another.
pub(crate) fn compact_of(blocks: &[[f64x4; 4]], count: usize) -> Vec<f64> {
    (0..count)
        .flat_map(|s| (0..4).map(move |c| blocks[s / LANES][c].as_array()[s % LANES]))
        .collect()
}

/// What a job keeps of its window's samples.
enum Window {
    None,
    Metrics(Box<MetricsAccumulator>),
    /// The samples (as many as the window has times) in their blocks.
    States(SampleBlocks, usize),
}

impl Window {
    /// Takes `block`: `false` when a sample is outside the lane model (see [`feed_samples`]).
    fn take(
        &mut self,
        model: &LinearStroke<'_>,
        block: &SampleBlock,
        closing: usize,
        with_force: bool,
    ) -> bool {
        match self {
            Window::None => true,
            Window::Metrics(m) => feed_samples(model, m, block, closing, with_force),
            Window::States(blocks, _) => {
                // The samples come in order: a block is pushed when its first sample arrives.
                if block.first % LANES == 0 && block.count == LANES {
                    debug_assert_eq!(block.first / LANES, blocks.len());
                    blocks.push(block.y);
                    return true;
                }
                for i in 0..block.count {
                    let s = block.first + i;
                    if s / LANES == blocks.len() {
                        blocks.push([f64x4::ZERO; 4]);
                    }
                    for (target, component) in blocks[s / LANES].iter_mut().zip(&block.y) {
                        target.as_mut_array()[s % LANES] = component.as_array()[i];
                    }
                }
                true
            }
        }
    }
}

/// `device`'s drive tables on `grid` (`None`: no lane model), computed once to seed the
/// [`DriveTables`] of several runs on other threads (a sensitivity's parameter groups: the
/// parameters that move neither the grid nor the drive share the base point's forces, those
/// that scale the drive its sines).
pub(crate) fn drive_seed(device: &Device, grid: &[f64]) -> Option<DriveSeed> {
    LinearStroke::of(device).map(|model| DriveTables::seed(grid, model.actuator()))
}

/// Runs `jobs` in the lanes, windows with the metrics `metric_names` (stroke metrics only),
/// or, with `capture`, keeping the windows' sample states: `None` when a device has no lane
/// model, a metric is not a stroke metric, or a lane would fail where the scalar path reports
/// the error (the caller then runs them scalar).
pub(crate) fn run<'a>(
    jobs: &[Job<'a>],
    (metric_names, capture): (&[String], bool),
    tol: LaneTolerances,
    weight: Option<f64>,
    tables: &mut DriveTables,
) -> Option<Vec<Done>> {
    if !metric_names
        .iter()
        .all(|m| crate::metrics::is_stroke_metric(m))
    {
        return None;
    }
    let models: Vec<LinearStroke<'_>> = jobs
        .iter()
        .map(|j| LinearStroke::of(j.device))
        .collect::<Option<_>>()?;
    let with_force = metric_names.iter().any(|m| m == "actuator_force_peak");
    let mut windows: Vec<Window> = jobs
        .iter()
        .map(|j| match (&j.times, capture) {
            (None, _) => Window::None,
            (Some(times), true) => {
                Window::States(Vec::with_capacity(times.len().div_ceil(LANES)), times.len())
            }
            (Some(_), false) => Window::Metrics(Box::new(
                MetricsAccumulator::new(j.device, j.device.period()).with_weight(weight),
            )),
        })
        .collect();
    // The closing sample's index: the window's sample count.
    let closing: Vec<usize> = jobs
        .iter()
        .map(|j| j.times.as_ref().map_or(0, |t| t.len().saturating_sub(1)))
        .collect();
    let mut stepper: LaneStepper<4> = LaneStepper::new();
    let mut lanes = LinearStrokeLanes::new();
    let mut in_lane: [Option<usize>; LANES] = [None; LANES];
    let mut done: Vec<Option<Done>> = jobs.iter().map(|_| None).collect();
    let (mut next, mut fresh) = (0, 0u32);
    loop {
        for (l, slot) in in_lane.iter_mut().enumerate() {
            if slot.is_some() || next == jobs.len() {
                continue;
            }
            let k = next;
            next += 1;
            let job = &jobs[k];
            lanes.load(l, &models[k]);
            lanes.load_forcing(l, Some(tables.forces(&job.grid, models[k].actuator())));
            let problem = LaneProblem {
                grid: job.grid.clone(),
                adaptive: None,
                y0: compact4(&job.y0),
                times: job.times.clone().unwrap_or_else(|| Rc::from([])),
                tol,
            };
            let (model, window) = (&models[k], &mut windows[k]);
            let mut feed = |_: usize, block: &_| window.take(model, block, closing[k], with_force);
            if !stepper.start(l, problem, &mut feed) {
                return None;
            }
            *slot = Some(k);
            fresh |= 1 << l;
        }
        if !stepper.any_busy() {
            break;
        }
        let finished = {
            let mut feed = |l: usize, block: &_| {
                let k = in_lane[l].expect("a busy lane has a job");
                windows[k].take(&models[k], block, closing[k], with_force)
            };
            stepper.run(&lanes, std::mem::take(&mut fresh), &mut feed)
        };
        for (l, outcome) in finished {
            let k = in_lane[l].take().expect("a busy lane has a job");
            let LaneOutcome::Done { y, .. } = outcome else {
                return None;
            };
            let (metrics, states) = match std::mem::replace(&mut windows[k], Window::None) {
                Window::None => (None, Vec::new()),
                Window::Metrics(m) => (Some(m.finish_only(Some(metric_names))), Vec::new()),
                Window::States(mut blocks, count) => {
                    repeat_last_sample(&mut blocks, count);
                    (None, blocks)
                }
            };
            done[k] = Some(Done {
                end: y,
                metrics,
                states,
            });
        }
    }
    COMPLETED.fetch_add(jobs.len(), Ordering::Relaxed);
    done.into_iter().collect()
}

/// The stroke metrics `metric_names` of a window of `device` from its sample states at
/// `times` ([`SampleBlocks`], one block after another), four samples at a time as [`run`]
/// takes them: `None` as for [`run`].
pub(crate) fn window_metrics(
    device: &Device,
    times: &[f64],
    blocks: impl IntoIterator<Item = [f64x4; 4]>,
    metric_names: &[String],
    weight: Option<f64>,
) -> Option<Vec<(String, f64)>> {
    if !metric_names
        .iter()
        .all(|m| crate::metrics::is_stroke_metric(m))
    {
        return None;
    }
    let model = LinearStroke::of(device)?;
    let with_force = metric_names.iter().any(|m| m == "actuator_force_peak");
    let mut metrics = MetricsAccumulator::new(device, device.period()).with_weight(weight);
    let closing = times.len().saturating_sub(1);
    for (b, (t, y)) in times.chunks(LANES).zip(blocks).enumerate() {
        let count = t.len();
        let block = SampleBlock {
            first: b * LANES,
            count,
            t: std::array::from_fn(|i| t[i.min(count - 1)]),
            y,
        };
        if !feed_samples(&model, &mut metrics, &block, closing, with_force) {
            return None;
        }
    }
    Some(metrics.finish_only(Some(metric_names)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_hold_the_samples_and_repeat_the_last_in_a_short_block() {
        let compact: Vec<f64> = (0..4 * 6).map(f64::from).collect();
        let blocks = blocks_of::<4>(&compact);
        assert_eq!(blocks.len(), 2);
        assert_eq!(blocks[1][3].to_array(), [19.0, 23.0, 23.0, 23.0]);
        assert_eq!(compact_of(&blocks, 6), compact);
    }
}
