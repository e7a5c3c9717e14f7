//! Continuation of the periodic orbits of periodically forced systems (issue 18).
//!
//! A forced periodic orbit is a fixed point of the period map `P(x; p)` ([`PeriodMap`]).
//! [`continue_orbits`] follows one as a parameter changes — natural or pseudo-arclength, the step
//! adapted to Newton's convergence — and reports every point's Floquet multipliers (the
//! monodromy comes with the map, e.g. from variational equations). Between points it watches
//! the test functions of the three codimension-one bifurcations of a forced orbit and locates
//! each by bisection:
//!
//! | bifurcation | multiplier | test function |
//! |---|---|---|
//! | fold | +1 | the parameter component of the branch tangent |
//! | period doubling | −1 | `∏ (μ + 1)` |
//! | Neimark–Sacker | complex pair, `|μ| = 1` | `∏ (|μ|² − 1)` over pairs |
//! | branch point (symmetry breaking) | +1, no turn | `∏ (μ − 1)` without a fold |
//!
//! A cyclic coordinate (one whose shift maps orbits to orbits, like the Drag PARITY
//! whippletree angle without a balance spring) is handled explicitly: it is pinned, the orbit
//! is solved with a drift per period, and its trivial multiplier 1 is removed instead of being
//! reported as a fold.
//!
//! [`continue_fold_curve`] follows a located fold or period doubling in a second parameter
//! (a minimally extended system with a bordered test function).
//!
//! ```
//! use nalgebra::DVector;
//! use paritysim_continuation::{ContinuationOptions, RungeKuttaMap, continue_orbits};
//! use paritysim_continuation::oscillators::{DRIVE_FREQUENCY, Duffing};
//!
//! // A linear oscillator (no cubic term) driven from ω = 0.5 to 1.5.
//! let ode = Duffing { damping: 0.2, linear_stiffness: 1.0, cubic_stiffness: 0.0 };
//! let map = RungeKuttaMap::new(ode, 400)?;
//! let options = ContinuationOptions::new(DRIVE_FREQUENCY, 1.5);
//! let branch = continue_orbits(&map, &DVector::zeros(2), &[0.5, 0.3], &options)?;
//! assert!(branch.bifurcations.is_empty());
//! assert!((branch.points.last().unwrap().parameter - 1.5).abs() < 1e-12);
//! # Ok::<(), paritysim_error::Error>(())
//! ```

mod bifurcation;
mod branch;
mod map;
mod multipliers;
mod ode;
mod options;
mod orbit_system;
pub mod oscillators;
mod points;
mod system;
mod two_parameter;

pub use branch::continue_orbits;
pub use map::PeriodMap;
pub use multipliers::{
    Stability, fold_test, multipliers, neimark_sacker_test, period_doubling_test, stability,
};
pub use ode::{ForcedOde, RungeKuttaMap};
pub use options::{ContinuationOptions, Method};
pub use paritysim_error::{Error, Result};
pub use points::{Bifurcation, BifurcationKind, Branch, BranchPoint, StopReason};
pub use two_parameter::{Curve, CurveOptions, CurvePoint, continue_fold_curve};
