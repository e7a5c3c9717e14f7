//! A free-flying airframe (issue 17, beyond the thesis): the body-mounted device of
//! `paritysim-dynamics` on a rigid body that is clamped, gimballed about its centre of mass
//! or free in 6 DOF under gravity.
//!
//! * [`body`]: the body model ([`Body`], [`BodyMode`]): mass, inertia, centre of mass,
//!   shoulder positions, gravity, body-referenced mechanisms and slow control.
//! * [`model`]: [`FlightModel`], the coupled equations of motion (Kane's equations: one mass
//!   matrix assembled from the body's and each wing's velocity Jacobians; exact
//!   velocity-product terms) and its right-hand side on a plain array state.
//! * [`aero`]: the blade-element wrench (force and torque) of a wing whose shoulder moves
//!   with the body.
//! * [`run`]: free-flight runs (wings first brought to their clamped periodic steady state,
//!   then released), trajectory columns and streamed metrics in the engine's result types.
//!
//! Data flow as in the engine: [`Body`] + `Device` (validated, immutable) -> [`FlightModel`]
//! (`Send + Sync`) -> per-run array state -> samples -> metrics and asked columns.

pub mod aero;
pub mod body;
pub mod control;
pub mod mechanisms;
pub mod model;
pub mod run;

pub use body::{Body, BodyMode};
pub use control::{Control, ControlInput, Interpolation, SetPoint};
pub use mechanisms::DriveCoordinate;
pub use mechanisms::Mechanism;
pub use model::Inputs;
pub use model::{FlightEval, FlightModel, STATE_LEN};
pub use run::{
    Controller, FlightSample, FlightSystem, Release, Schedule, body_values, flight_column_units,
    flight_columns, flight_metrics, fly, fly_controlled, integrate_flight,
};
