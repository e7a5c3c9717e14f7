//! Wing dynamics, actuator, drivetrain coupling and integration (thesis §3.2, Appendix A).
//!
//! Data flow: [`DeviceSpec`] (validated, immutable) -> [`Device`] (the model: `Send + Sync`,
//! shared by sweeps) -> per-run integrator state -> samples -> streamed [`metrics`] (and asked [`Trajectory`] columns).
//!
//! * [`wing`]: one wing on a spherical shoulder: mass matrix `M = J6ᵀ I J6`, Coriolis and
//!   centrifugal vector from Euler's equations, joint springs (A.5–A.7), aerodynamic torques
//!   mapped by `J6ᵀ` (A.12).
//! * [`actuator`]: zeroth-order piezo model (§3.2.2 item 4): force = (force per volt) × V(t)
//!   in parallel with a linear spring; sine (eq. 3.24) and sampled waveforms.
//! * [`device`]: n ≤ 2 wings, constraints `C p = c0` (null-space or eq. 3.20 projection), a
//!   planar drivetrain with balance-beam spring, the actuator; the right-hand side.
//! * [`integrate`]: our own Dormand–Prince pairs (DOP853 default, DOPRI5) with Hairer's dense
//!   output, sampled through a callback; errors that carry the time and state.
//! * [`simulate`](mod@simulate): periodic steady state, perturbations; the recorded window is streamed into
//!   [`metrics`] and, only when asked, into [`trajectory`] columns (a name/unit/getter table).

pub mod actuator;
pub mod continuation;
pub mod device;
pub mod integrate;
pub mod lanes;
pub mod metrics;
pub mod sensitivity;
mod shooting;
pub mod simulate;
pub mod stability;
pub mod sweep;
pub mod trajectory;
pub mod wing;

pub use actuator::{Actuator, DcOffset, Waveform};
pub use device::{Device, DeviceSpec, Formulation, Transmission};
pub use integrate::budget::CancelFlag;
pub use integrate::{Integrator, MAX_DOF, Method, State};
pub use paritysim_error::{Error, Result};
pub use simulate::{
    Perturbation, SimulationOptions, SimulationResult, SteadyState, Trajectory, simulate,
};
/// The former name of [`stability`] (kept for the bindings and existing users).
pub use stability as floquet;
pub use wing::{JointSpring, TunableHinge, Wing, WingAero};
