//! The aerodynamic wrench of a wing whose shoulder moves with the body.
//!
//! The quasi-steady model of §3.2.4 evaluates a strip at span `z` with the velocity
//! `z ω × ẑ` of a wing turning about a fixed shoulder (crates/aero/src/blade.rs). On a moving
//! body the wing turns with its total angular velocity `ω = R_6^1ᵀ Ω₁ + J6 ṗ` (body rate
//! included: this is the exact "flapping counter-torque" part) and the shoulder translates
//! with `v_s` (frame 6). Strips then move with `v_s + z ω × ẑ`; we evaluate the model at the
//! effective angular velocity that reproduces that velocity at the force radius `r_f`:
//! `ω_eff = (ω_x − v_{s,y}/r_f, ω_y + v_{s,x}/r_f, ω_z)` (spanwise flow ignored, as in the
//! blade-element model). Exact for a shoulder at rest; first order in `|v_s| / (r_f |ω|)`
//! otherwise (hover: body speeds are a few % of the wing speed at `r_f`).

use nalgebra::{Matrix3, Vector3};
use paritysim_dynamics::WingAero;
use paritysim_error::Result;

/// Force (mN) and torque about the shoulder (mN·mm), in the wing's own frame 1.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Wrench {
    /// Force (mN).
    pub force: Vector3<f64>,
    /// Torque about the spherical centre (mN·mm).
    pub torque: Vector3<f64>,
}

/// The wing's aerodynamic wrench at total angular velocity `omega6` and shoulder velocity
/// `v6` (both frame 6), rotation `r61`, force radius `r_f` (mm).
///
/// # Errors
/// A blade-element model without force parameter (the flight model always sets one).
#[inline]
pub fn wrench(
    aero: &WingAero,
    omega6: &Vector3<f64>,
    v6: &Vector3<f64>,
    r61: &Matrix3<f64>,
    r_f: f64,
) -> Result<Wrench> {
    Ok(match aero {
        WingAero::None => Wrench::default(),
        WingAero::StrokeDrag {
            omega1,
            coefficient,
        } => {
            // Torque-only model (eq. 2.16): about the stroke axis, at the stroke-axis rate.
            let rate = (r61 * omega6).x;
            Wrench {
                force: Vector3::zeros(),
                torque: Vector3::x() * (-omega1 * coefficient * rate.abs() * rate),
            }
        }
        WingAero::BladeElement(model) => {
            let eff = Vector3::new(omega6.x - v6.y / r_f, omega6.y + v6.x / r_f, omega6.z);
            let loads = model.loads_omega(&eff, r61)?;
            Wrench {
                force: loads.lift + loads.drag,
                torque: loads.torque(),
            }
        }
    })
}
