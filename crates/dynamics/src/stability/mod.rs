//! Stability of periodic flapping (thesis §2.6), disturbance rejection (§2.7), and the Floquet
//! analysis of the full nonlinear model's limit cycle.
//!
//! * **Linearised model (§2.6).** The monodromy matrix of `ẍ + β0|cos t|ẋ + κx = 0` (eq. 2.25,
//!   period π) is integrated with a Taylor-series method of order [`TAYLOR_ORDER`] on the
//!   pieces where `|cos t|` is smooth (truncation at round-off level; closed forms of eqs.
//!   2.45, 2.50 and 2.54 hold to 1e-9 or better in `tests/dynamics/floquet/`); its
//!   half trace `a`, determinant `b` (eq. 2.36), multipliers (eq. 2.37) and region of Fig. 2.13
//!   ([`Region`], with the corrected Region III bound of docs/errata.md#9) follow. A
//!   [`stability_chart`] over a (β0, κ) grid is computed on the sweep engine's pool. [`brockett()`]
//!   is the criterion of eqs. 2.57–2.58 and [`PhysicalParameters::hill`] maps a device to
//!   (β0, κ1, κ2) with the factors of docs/errata.md#7.
//! * **Disturbance rejection (§2.7).** [`LtiModel`] is eq. 2.59; [`linearise`] derives its
//!   `β*` (cycle-averaged aerodynamic damping of the whippletree mode) and `κ0` from a device
//!   and its periodic orbit, and [`disturbance_response`] measures the same transfer on the
//!   full nonlinear model by injecting a sinusoidal roll torque on the wings
//!   ([`RollDisturbance`], an [`OdeSystem`](crate::integrate::OdeSystem) wrapped around the device).
//! * **Full nonlinear model.** [`periodic_orbit`] finds the limit cycle by Newton shooting on
//!   the stroboscopic map over one drive period, with the exact derivative of the computed map
//!   from the variational equations ([`crate::integrate::RungeKutta::flow_with_sensitivity`]),
//!   cycle-to-cycle simulation as the fallback; [`floquet`] returns the Floquet multipliers of
//!   that monodromy (checked against central differences of the map over the coordinates and
//!   rates the device integrates); [`balance_spring_sweep`] repeats that over K2 on the
//!   sweep engine (`rows.rs`: one row per value, a failing value a row with its error, the
//!   sweep's own thread pool), as [`disturbance_responses`] does over frequencies.
//!
//! Errata (docs/errata.md) relied on here, each verified numerically in
//! `tests/dynamics/floquet/`: item 7 (the drag forces of eqs. 2.17–2.19 carry `T³`, so
//! `β0 = 2ΩΦ/I`), item 8 (eq. 2.27's coefficient is `−¼β0²cos²t`), item 9 (Region I is
//! `b ≤ 1, |a| ≤ (1 + b)/2`), item 10 (eq. 2.52 is `M = exp(TQ)`, eq. 2.53 is `M^(n+1)`, eq. 2.54
//! lacks a factor π).

//!
//! One file per subject: `hill.rs` (§2.6, eq. 2.25), `brockett.rs` (§2.6.4), `lti.rs` (§2.6.1
//! and eq. 2.59), `shooting.rs` (periodic orbit of the full model), `multipliers.rs` (its Floquet multipliers),
//! `disturbance.rs` (K2 sweeps, linearisation and disturbance response, §2.7), `rows.rs` (the
//! parameter loops on the sweep engine). Everything is
//! re-exported here (and as `paritysim_dynamics::floquet`, the former module name).

pub mod brockett;
pub mod disturbance;
pub mod hill;
pub mod lti;
pub mod multipliers;
pub mod records;
pub mod rows;
pub mod shooting;

pub use brockett::*;
pub use disturbance::*;
pub use hill::*;
pub use lti::*;
pub use multipliers::*;
pub use rows::Rows;
pub use shooting::*;
