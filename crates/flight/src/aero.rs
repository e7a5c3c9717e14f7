//! The aerodynamic wrench of a wing whose shoulder moves with the body: the aero law's own
//! home is `paritysim_aero::wing_aero` (one place per law, used by the fixed-body engine and
//! by flight alike); its names are re-exported here.

pub use paritysim_aero::wing_aero::{Wrench, switching, wrench, wrench_and_wing_torque};
