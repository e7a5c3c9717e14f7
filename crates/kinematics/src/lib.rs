//! Kinematics of paritysim (thesis §2.3, Appendix A).
//!
//! * [`rotation`]: `R_x`, `R_y`, `R_z`, axis-angle rotation and the skew matrix `S(v)` (A.1).
//! * [`shoulder`]: the spherical five-bar shoulder of §2.3.3: closed-form joint angles
//!   (eqs. 2.11–2.14), link rotations (2.2–2.6), first and second partials of γ2, γ3, γ5 and the
//!   Jacobian `J6` (A.9).
//! * [`drivetrain`]: planar drivetrains mapping actuator coordinates `(q1, q2)` to stroke angles
//!   `(φL, φR)` with Jacobian and Hessian: the HMF four-bar (§2.3.1), the Drag PARITY differential
//!   (§2.3.2) as the linear map of eq. 2.15 and as a nonlinear linkage, with a biased whippletree
//!   pivot (§2.4.2).
//!
//! Units: mm, rad (mg-mm-ms-rad-V system). All constructors validate and return
//! [`paritysim_error::Result`]; evaluation outside a mechanism's domain returns
//! [`paritysim_error::Error::OutOfDomain`], never NaN.

pub mod drivetrain;
pub mod records;
pub mod rotation;
pub mod shoulder;

pub use drivetrain::{Drivetrain, DrivetrainEval, OddPolynomial, RodCrank};
pub use paritysim_error::{Error, Result};
pub use shoulder::{ShoulderPartials, ShoulderPose, SphericalShoulder};
