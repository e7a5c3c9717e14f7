//! Our own Dormand–Prince integrators (DOP853 and DOPRI5 with Hairer's dense output and step
//! control), sampling the solution at requested times through a callback.
//!
//! * The integrator works on a compact array of `2n` entries (`n` coordinates, `n` rates) and,
//!   only when asked for, the two work integrals. The work integrals ride along on the same
//!   stages but take no part in the error control (they never shorten a step).
//! * Dense output is prepared only on steps where a sample falls (DOP853's three extra stages
//!   are not computed on the other steps); a sample at a step's end is the step's value.
//! * `differential-equations` 0.7.0 is kept as a dev-dependency to cross-check steps; its
//!   DOP853 interpolant is O(h⁵) (see docs/findings.md), ours is Hairer's CONTD8.

/// Evaluates `$body` with `$stepper` a new stepper of `$method` on `$m` entries: one
/// monomorphised copy of the body per pair (the loops are generic over [`Stepper`]).
macro_rules! with_stepper {
    ($method:expr, $m:ident, |$stepper:ident| $body:expr) => {
        match $method {
            Method::Dop853 => {
                let $stepper = &mut dop853::Dop853::<$m>::new();
                $body
            }
            Method::Dopri5 => {
                let $stepper = &mut dopri5::Dopri5::<$m>::new();
                $body
            }
        }
    };
}

mod adaptive;
mod array;
pub mod budget;
mod dop853;
mod dopri5;
mod events;
mod fixed_grid;
mod lane_control;
mod runge_kutta;
mod state;
mod stepper;
mod switched;
mod system;
#[cfg(test)]
mod tests;
mod variational;

/// DOP853 on fixed grids for several problems in SIMD lanes.
pub(crate) use dop853::lanes;

use paritysim_error::{Error, Result};

use adaptive::{drive_method, initial_step};
pub use array::{ArrayRhs, ArraySink, ArraySystem, integrate_array, integrate_system};
pub(crate) use events::WithoutEvents;
pub use events::{MAX_SWITCHES, Sides};
pub(crate) use fixed_grid::{check_grid, drive_method_on_grid};
pub use runge_kutta::RungeKutta;
pub use state::State;
use stepper::sample_step;
pub(crate) use stepper::{Rhs, Stepper, Tolerances};
pub use system::{IntegrationStats, Integrator, Method, OdeSystem, Sink};

/// Largest number of integrated coordinates.
pub const MAX_DOF: usize = 6;

/// Checks an integration window: finite `t0 < t_end`, sample `times` sorted within it.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `t_end` or `times[i]`.
fn check_window(t0: f64, t_end: f64, times: &[f64]) -> Result<()> {
    if t_end.is_nan() || t_end <= t0 || !t0.is_finite() || !t_end.is_finite() {
        return Err(Error::invalid("t_end", t_end, format!("> t0 = {t0}")));
    }
    if let Some(i) = (0..times.len())
        .find(|&i| !(times[i] >= t0 && times[i] <= t_end) || (i > 0 && times[i] < times[i - 1]))
    {
        return Err(Error::invalid(
            format!("times[{i}]"),
            times[i],
            format!("sorted and within [{t0}, {t_end}]"),
        ));
    }
    Ok(())
}

fn integration_error(time: f64, state: &State, reason: impl Into<String>) -> Error {
    Error::Integration {
        time,
        state: state.to_vec(),
        reason: reason.into(),
    }
}
