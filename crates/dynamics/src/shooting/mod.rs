//! Shooting: the periodic steady state as the fixed point of the period map.
//!
//! * `newton`: the kernels, written once (residual, trial step, least-squares step with the
//!   neutral-direction rule, Broyden's update, tolerances, the iteration limit).
//! * `machine`: Newton on the frozen-grid map as a state machine ([`machine::GridNewton`])
//!   that requests one period at a time: written once, run by two executors.
//! * `grid`: the scalar executor ([`grid::shoot`]: the first map, then each request at once),
//!   used by `simulate`, `stability::periodic_orbit` and continuation; the SIMD-lane points
//!   (`crate::lanes::point`) are the other executor.

pub(crate) mod grid;
pub(crate) mod machine;
pub(crate) mod newton;
