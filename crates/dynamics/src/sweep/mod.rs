//! Parameter sweeps: many independent simulations on a local rayon pool.
//!
//! A sweep is a list of points; each point is a device (plus its options) built from a base
//! design and a row of parameter values. Every point runs [`simulate`](crate::simulate()) on its
//! own and produces the selected metrics (and optionally its last recorded cycle):
//!
//! * **Order and determinism.** Results come back in input order whatever the thread count.
//!   Points with [`SteadyState::Shooting`](crate::SteadyState::Shooting) (the default) run in continuation chains of
//!   [`CHAIN_LENGTH`] consecutive points of one call ([`run_points`]), each started from its
//!   converged neighbours' orbit, Jacobian and step grid; other points run on their own. The
//!   chains are fixed by the input order alone and each is computed sequentially, so results
//!   are **bit-identical for any thread count and on repeated runs**. A chained point is *not*
//!   bit-identical to a direct [`simulate`](crate::simulate()) of the same device (another
//!   start, another frozen step grid), but both converge the same periodic orbit: their
//!   metrics agree to the accuracy of the orbit (Newton residual `≤ rtol / 10`, or
//!   `≤ steady_tol` along a nearly neutral direction, amplified by slow modes, plus the two
//!   grids' truncation errors): about 1e-7 of each metric's scale at the default options
//!   (measured 3e-8 to 1.2e-7). A chained start that does not converge or needs the
//!   transient fallback (Newton failed, or found an unstable orbit) is rerun from the spec's
//!   own start, and only orbits found by shooting continue a chain, so a point without a
//!   stable orbit is exactly its direct `simulate`. The same holds between two different splittings of a table into calls
//!   (chunks, resumed checkpoints).
//! * **Failures are rows.** A point whose device cannot be built (an invalid combination) or
//!   whose integration fails yields `Err(error)` in its slot; every other point is kept. A panic
//!   inside a point is caught and reported the same way (it never unwinds into the caller).
//! * **Progress and cancellation.** [`SweepControl`] holds an atomic counter of finished points
//!   (poll it from another thread) and a cancel flag: once set, no new point starts, the running
//!   ones stop at their integrator's next budget check, and their slots and the unstarted ones
//!   come back as `None`.
//! * **Threads.** [`resolve_threads`]: an explicit count, else the environment variable
//!   [`THREADS_ENV`] (`PARITYSIM_THREADS`), else all available cores. Each run builds its own
//!   pool, so the global rayon pool is never touched.
//!
//! ```
//! use paritysim_dynamics::sweep::{Grid, SweepControl, SweepSettings, sweep};
//! # use paritysim_dynamics::{Device, DeviceSpec, Formulation, Wing, WingAero, JointSpring, SimulationOptions};
//! # use paritysim_constraints::Constraints;
//! # use paritysim_kinematics::SphericalShoulder;
//! # use nalgebra::Matrix3;
//! // A free wing on a stroke spring, swept over the spring stiffness.
//! let build = |values: &[f64]| {
//!     let mut springs = [JointSpring::default(); 6];
//!     springs[0] = JointSpring::linear(values[0], 0.0)?;
//!     let wing = Wing::new(
//!         SphericalShoulder::new(std::f64::consts::FRAC_PI_2, 0.0)?,
//!         Matrix3::from_diagonal_element(10.0),
//!         springs,
//!         WingAero::None,
//!     )?;
//!     Device::new(DeviceSpec {
//!         wings: vec![wing],
//!         constraints: Constraints::none(3)?,
//!         transmission: None,
//!         actuator: None,
//!         formulation: Formulation::Auto,
//!     })
//! };
//! let grid = Grid::new().axis("stiffness", [1.0, 2.0, 4.0])?;
//! let options = SimulationOptions {
//!     duration_ms: Some(5.0),
//!     initial: Some((nalgebra::Vector6::zeros(), nalgebra::Vector6::new(0.1, 0.0, 0.0, 0.0, 0.0, 0.0))),
//!     ..Default::default()
//! };
//! let control = SweepControl::new();
//! let result = sweep(&grid.table(), build, &options, &SweepSettings::default(), &control)?;
//! assert_eq!(result.rows.len(), 3);
//! assert_eq!(control.finished(), 3);
//! # Ok::<(), paritysim_dynamics::Error>(())
//! ```

mod chain;
mod point;
mod pool;
mod select;
mod table;

pub use chain::{CHAIN_LENGTH, run_points, run_points_with_lanes};
pub(crate) use chain::{
    ChainStart, Converged, chain_point, chain_range, chain_start, continued_options, remember,
};
pub use point::{NEUTRAL_MULTIPLIER_TOL, PointOutput, SweepSettings, has_neutral_mode, run_point};
pub(crate) use pool::run_tasks;
pub use pool::{MAX_THREADS, SweepControl, THREADS_ENV, resolve_threads, run_indexed};
pub use select::{metric_names, select, trajectory_columns};
pub use table::{Grid, ParameterTable};

use paritysim_error::{Error, Result};

use crate::device::Device;
use crate::simulate::SimulationOptions;

/// One row of a [`SweepResult`].
#[derive(Clone, Debug, PartialEq)]
pub struct SweepRow {
    /// Position in the input table.
    pub index: usize,
    /// The parameter values of this point.
    pub parameters: Vec<f64>,
    /// Its metrics, or why it failed.
    pub outcome: Result<PointOutput>,
}

/// The finished rows of a sweep, in input order.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepResult {
    /// Parameter names (the table's columns).
    pub parameters: Vec<String>,
    /// Metric names (the columns of [`PointOutput::metrics`]).
    pub metrics: Vec<String>,
    /// Finished points in input order (fewer than the table when cancelled).
    pub rows: Vec<SweepRow>,
    /// Whether the sweep was cancelled before every point ran.
    pub cancelled: bool,
}

/// Sweeps a table: `build(values)` makes each point's device (an `Err` there becomes that
/// point's error row), all points share `options`.
///
/// Metric names are validated against the device of the first point that builds, before any
/// simulation runs.
///
/// # Errors
/// [`Error::InvalidParameter`] for an unknown metric name or a bad thread count. Point failures
/// are reported in their rows.
pub fn sweep<F>(
    table: &ParameterTable,
    build: F,
    options: &SimulationOptions,
    settings: &SweepSettings,
    control: &SweepControl,
) -> Result<SweepResult>
where
    F: Fn(&[f64]) -> Result<Device> + Sync,
{
    let threads = resolve_threads(settings.threads)?;
    let devices: Vec<Result<(Device, SimulationOptions)>> =
        run_indexed(table.len(), threads, &SweepControl::new(), |i| {
            build(&table.rows[i]).map(|d| (d, options.clone()))
        })?
        .into_iter()
        .map(|slot| slot.unwrap_or(Err(Error::Cancelled)))
        .collect();
    let names = match devices.iter().find_map(|d| d.as_ref().ok()) {
        Some((device, _)) => select(
            "metrics",
            settings.metrics.as_deref(),
            &metric_names(device),
        )?,
        None => settings.metrics.clone().unwrap_or_default(),
    };
    let slots = run_points(
        &devices,
        &names,
        settings.keep_cycle,
        Some(threads),
        control,
    )?;
    let cancelled = slots.iter().any(Option::is_none);
    let rows = slots
        .into_iter()
        .enumerate()
        .filter_map(|(index, slot)| {
            slot.map(|outcome| SweepRow {
                index,
                parameters: table.rows[index].clone(),
                outcome,
            })
        })
        .collect();
    Ok(SweepResult {
        parameters: table.names.clone(),
        metrics: names,
        rows,
        cancelled,
    })
}
