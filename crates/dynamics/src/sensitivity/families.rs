//! Families of orbits in a sensitivity (a multiplier at or near 1, K2 = 0's whippletree): a
//! parameter that breaks one has no derivative there, and a metric that moves along a neutral
//! or nearly neutral direction is flagged (docs/findings.md §30).

use nalgebra::DVector;
use paritysim_error::Result;

use crate::shooting::newton::LeastSquares;

use super::value_of;

/// A window's metrics (name, value).
type Metrics = Vec<(String, f64)>;

/// A metric that changes along a neutral direction of the orbit by more than this (relative to
/// its size, per unit of the neutral vector) depends on which member of the family is meant.
pub const NEUTRAL_CHANGE_TOLERANCE: f64 = 1e-6;

/// A parameter whose `∂P/∂p` has more than this fraction outside the range of `∂P/∂x − I`
/// breaks a neutral family. Measured (docs/findings.md §30): parameters that keep the family
/// (frequency, amplitude, Ω1) leave up to 9e-6 at the default tolerances (7e-7 at rtol
/// 1e-10); the balance spring at K2 = 0 of the §3.3 1-Cut, 2-Cut and §3.4 K2 = 0 PARITY and
/// 1-Cut leaves 1.7e-2, 5.7e-2, 0.63 and 0.47.
pub const FAMILY_BREAK_TOLERANCE: f64 = 1e-3;

/// ... unless the part along the family changes the period map by less than this (relative to
/// `1 + ‖x*‖∞`) over a change of the parameter by its size (`|p|`, or 1 near 0): round-off.
/// Measured: the balance spring on identical wings acts on a coordinate symmetry holds at 0,
/// so its `∂P/∂p` is round-off (3e-28) of any direction: about 1e-28 there, 6e-8 on the §3.3
/// 1-Cut.
pub const FAMILY_BREAK_FLOOR: f64 = 1e-15;

/// Why the orbit is not differentiable in a parameter whose map changes by `dp` (`None`: it
/// is): a part of `dp` that `∂P/∂x − I` cannot reach (the solvability residual `uᵀ dp`, `u` a
/// left null vector) means no orbit through `x*` follows the parameter. `size`: the
/// parameter's size; `state_size`: `1 + ‖x*‖∞`.
pub(super) fn broken(
    least_squares: &LeastSquares,
    dp: &DVector<f64>,
    size: f64,
    state_size: f64,
) -> Option<String> {
    let unreachable = least_squares.unreachable(dp);
    let fraction = unreachable / dp.norm();
    // A change of the map below `FAMILY_BREAK_FLOOR` over the parameter's size is round-off (a
    // spring on a coordinate that symmetry holds at zero).
    let felt = unreachable * size > FAMILY_BREAK_FLOOR * state_size;
    (felt && fraction > FAMILY_BREAK_TOLERANCE).then(|| {
        format!(
            "breaks a family of orbits (a multiplier at 1): {fraction:.1e} of the period map's \
             change with it is along the family, which no nearby orbit absorbs, so the steady \
             state moves to another member (a jump) as it changes"
        )
    })
}

/// Flags the metrics that move along a neutral direction (`neutral`: their derivative depends
/// on the member of the family) or a nearly neutral one (a multiplier within the sweeps'
/// family tolerance of 1: the derivative divides the period map's error by a small singular
/// value; the §3.3 1-Cut at K2 = 1e-3: d(stroke mean)/d(offset) 4.7e-4 off). `window_along`:
/// the metrics of the window started at `x* + shift`.
///
/// # Errors
/// A window that fails.
pub(super) fn flag_moving_metrics(
    least_squares: &LeastSquares,
    neutral: &[DVector<f64>],
    window_along: &dyn Fn(&DVector<f64>) -> Result<Metrics>,
    metrics: &[(String, f64)],
    not_differentiable: &mut [Option<String>],
) -> Result<()> {
    let tol = crate::sweep::NEUTRAL_MULTIPLIER_TOL;
    let slow = least_squares.slow_directions(tol);
    let directions = neutral
        .iter()
        .map(|v| (None, v))
        .chain(slow.iter().map(|(sigma, v)| (Some(*sigma), v)));
    for (sigma, v) in directions {
        let eps = 1e-6;
        let (plus, minus) = (window_along(&(v * eps))?, window_along(&(v * -eps))?);
        for (i, (name, m0)) in metrics.iter().enumerate() {
            let slope = (value_of(&plus, name) - value_of(&minus, name)) / (2.0 * eps);
            if not_differentiable[i].is_none()
                && slope.abs() > NEUTRAL_CHANGE_TOLERANCE.max(1e-4 * m0.abs())
            {
                not_differentiable[i] = Some(match sigma {
                    None => format!(
                        "changes along a neutral direction of the orbit (slope {slope:e}): a \
                         family of orbits (a multiplier at 1), so the derivative depends on the \
                         member"
                    ),
                    Some(sigma) => format!(
                        "changes along a nearly neutral direction of the orbit (slope \
                         {slope:e}; a multiplier within {tol:e} of 1, which a sweep treats as a \
                         family): its derivative divides the period map's error by {sigma:.1e}"
                    ),
                });
            }
        }
    }
    Ok(())
}
