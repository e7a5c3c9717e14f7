//! The perturbed periods of a sensitivity: fixed-grid maps (with their window's samples) or
//! recorded windows, four at a time in the lanes where the devices have a lane model.

use nalgebra::DVector;
use paritysim_error::Result;

use crate::integrate::{RungeKutta, State};
use crate::simulate::SimulationOptions;

use super::Point;

/// What a perturbed period keeps.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Keep {
    /// The end state (a map).
    End,
    /// The end state and the window's sample states (a map whose window is replayed).
    Samples,
    /// The recorded window's metrics.
    Metrics,
}

/// A perturbed period: its end state (compact; `Keep::End`, `Keep::Samples`), its window's
/// sample states (`Keep::Samples`) or metrics (`Keep::Metrics`).
#[derive(Default)]
pub(super) struct Period {
    pub(super) end: DVector<f64>,
    pub(super) states: WindowStates,
    pub(super) metrics: Vec<(String, f64)>,
}

/// A window's sample states: compact (`2n` numbers each, one after another) from the scalar
/// periods, or the lanes' blocks.
pub(super) enum WindowStates {
    Compact(Vec<f64>),
    Blocks(crate::lanes::batch::SampleBlocks),
}

impl Default for WindowStates {
    fn default() -> Self {
        WindowStates::Compact(Vec::new())
    }
}

/// Whether the perturbed periods run in the lanes (`crate::lanes::batch`): DOP853 and not
/// `PARITYSIM_LANES=1` (the scalar path, as for sweeps); the batch itself refuses devices
/// without a lane model and metrics other than stroke metrics.
pub(super) fn in_lanes(options: &SimulationOptions) -> Result<bool> {
    Ok(
        options.method == crate::integrate::Method::Dop853
            && crate::lanes::resolve_lanes(None)? > 1,
    )
}

/// One fixed-grid period of each `points[k]` from `starts[k]`, keeping `keep`. Four at a time
/// in the lanes where every device has a lane model (bit-identical to the scalar periods,
/// `crate::lanes::batch`), else on the sensitivity's threads.
pub(super) fn periods(
    points: &[&Point],
    starts: &[State],
    (keep, tables): (Keep, &mut crate::lanes::batch::DriveTables),
    rk: &RungeKutta,
    options: &SimulationOptions,
) -> Result<Vec<Period>> {
    // The lanes compute stroke metrics only: a window asking every metric runs scalar.
    let lane_metrics = match (keep, &options.metrics) {
        (Keep::End | Keep::Samples, _) => Some(&[][..]),
        (Keep::Metrics, Some(names)) => Some(names.as_slice()),
        (Keep::Metrics, None) => None,
    };
    let times =
        |point: &Point| crate::simulate::grid_window_times(&point.grid, point.period, options);
    if let (Some(names), true) = (lane_metrics, in_lanes(options)?) {
        let jobs: Vec<crate::lanes::batch::Job<'_>> = points
            .iter()
            .zip(starts)
            .map(|(point, y)| crate::lanes::batch::Job {
                device: &point.device,
                grid: std::rc::Rc::from(point.grid.as_slice()),
                y0: *y,
                times: (keep != Keep::End).then(|| times(point).into()),
            })
            .collect();
        let tol = crate::integrate::lanes::LaneTolerances {
            rtol: options.rtol,
            atol: options.atol,
        };
        let capture = keep == Keep::Samples;
        if let Some(done) =
            crate::lanes::batch::run(&jobs, (names, capture), tol, options.weight_mn, tables)
        {
            return Ok(done
                .into_iter()
                .map(|done| Period {
                    end: DVector::from_row_slice(&done.end),
                    states: WindowStates::Blocks(done.states),
                    metrics: done.metrics.unwrap_or_default(),
                })
                .collect());
        }
    }
    crate::stability::rows::run_parts(points.len(), |k| {
        let point = points[k];
        if keep == Keep::Metrics {
            let metrics = crate::simulate::grid_window(
                &point.device,
                rk,
                &point.grid,
                point.period,
                &starts[k],
                options,
            )?;
            return Ok(Period {
                metrics,
                ..Period::default()
            });
        }
        let sample_times = if keep == Keep::Samples {
            times(point)
        } else {
            Vec::new()
        };
        let n = point.device.n_dof();
        let mut states = Vec::with_capacity(2 * n * sample_times.len());
        let end = rk.with_work(false).integrate_on_grid(
            &point.device,
            &point.grid,
            &starts[k],
            &sample_times,
            &mut |_, _, y| {
                y.push_compact(n, &mut states);
                Ok(())
            },
        )?;
        Ok(Period {
            end: end.without_work().compact(n),
            states: WindowStates::Compact(states),
            metrics: Vec::new(),
        })
    })
}
