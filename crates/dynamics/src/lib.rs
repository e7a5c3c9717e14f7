//! Wing dynamics, actuator, drivetrain coupling and integration (thesis §3.2, Appendix A).
//!
//! Data flow: [`DeviceSpec`] (validated, immutable) -> [`Device`] (the model: `Send + Sync`,
//! shared by sweeps) -> per-run integrator state -> [`Trajectory`] -> [`metrics`].
//!
//! * [`wing`]: one wing on a spherical shoulder: mass matrix `M = J6ᵀ I J6`, Coriolis and
//!   centrifugal vector from Euler's equations, joint springs (A.5–A.7), aerodynamic torques
//!   mapped by `J6ᵀ` (A.12).
//! * [`actuator`]: zeroth-order piezo model (§3.2.2 item 4): force = (force per volt) × V(t)
//!   in parallel with a linear spring; sine (eq. 3.24) and sampled waveforms.
//! * [`device`]: n ≤ 2 wings, constraints `C p = c0` (null-space or eq. 3.20 projection), a
//!   planar drivetrain with balance-beam spring, the actuator; the right-hand side.
//! * [`integrate`]: our `Integrator` over the `differential-equations` crate (DOP853 default,
//!   DOPRI5), errors that carry the time and state.
//! * [`simulate`]: periodic steady state, perturbations, trajectories and metrics.

pub mod actuator;
pub mod continuation;
pub mod device;
pub mod floquet;
pub mod integrate;
pub mod metrics;
pub mod simulate;
pub mod sweep;
pub mod wing;

pub use actuator::{Actuator, DcOffset, Waveform};
pub use device::{Device, DeviceSpec, Formulation, Transmission};
pub use integrate::{Integrator, Method, STATE_LEN, State};
pub use paritysim_error::{Error, Result};
pub use simulate::{Perturbation, SimulationOptions, SimulationResult, Trajectory, simulate};
pub use wing::{JointSpring, TunableHinge, Wing, WingAero};
