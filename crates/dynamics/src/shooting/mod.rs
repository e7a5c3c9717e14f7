//! Shooting: the periodic steady state as the fixed point of the period map.
//!
//! * `newton`: the kernels, written once (residual, trial step, least-squares step with the
//!   neutral-direction rule, Broyden's update, tolerances, the iteration limit).
//! * `grid`: Newton on the frozen-grid map ([`grid::shoot`]), used by `simulate`,
//!   `stability::periodic_orbit` and continuation; the SIMD-lane points (`crate::lanes`) run
//!   the same kernels a period at a time.

pub(crate) mod grid;
pub(crate) mod newton;
