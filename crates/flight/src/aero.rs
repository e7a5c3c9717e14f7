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
//!
//! Switching functions (event location): the blade-element model jumps or kinks where a
//! component of `ω_eff` crosses zero ([`paritysim_aero::Branch`]); the stroke-drag torque
//! `−Ω c |r| r` of the stroke-axis rate `r` has a kink in its derivative at `r = 0`. Each wing
//! has three switching functions ([`switching`]), and [`wrench`] evaluates the branch named by
//! their sides when given one.

use nalgebra::{Matrix3, Vector3};
use paritysim_aero::Branch;
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

/// The angular velocity the blade elements see: `ω` corrected by the shoulder's velocity at
/// the force radius (module docs).
#[inline]
fn effective(omega6: &Vector3<f64>, v6: &Vector3<f64>, r_f: f64) -> Vector3<f64> {
    Vector3::new(omega6.x - v6.y / r_f, omega6.y + v6.x / r_f, omega6.z)
}

/// The wing's three switching functions (arguments as [`wrench`]): the blade-element model's
/// [`paritysim_aero::BladeElementModel::switching_functions`] of `ω_eff`; the stroke-axis
/// rate for the stroke-drag torque; `1` (never an event) where the model is smooth.
#[inline]
pub fn switching(
    aero: &WingAero,
    omega6: &Vector3<f64>,
    v6: &Vector3<f64>,
    r61: &Matrix3<f64>,
    r_f: f64,
) -> [f64; 3] {
    match aero {
        WingAero::None => [1.0; 3],
        WingAero::StrokeDrag { .. } => [(r61 * omega6).x, 1.0, 1.0],
        WingAero::BladeElement(model) => model.switching_functions(&effective(omega6, v6, r_f)),
    }
}

/// The wing's aerodynamic wrench at total angular velocity `omega6` and shoulder velocity
/// `v6` (both frame 6), rotation `r61`, force radius `r_f` (mm); on `branch` (the sides of
/// [`switching`]: for stroke drag its first entry is the side of the rate) or, without one,
/// on the side the state lies on.
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
    branch: Option<Branch>,
) -> Result<Wrench> {
    Ok(match aero {
        WingAero::None => Wrench::default(),
        WingAero::StrokeDrag {
            omega1,
            coefficient,
        } => {
            // Torque-only model (eq. 2.16): about the stroke axis, at the stroke-axis rate.
            let rate = (r61 * omega6).x;
            let magnitude = match branch {
                Some(b) if b.chordwise_positive => rate,
                Some(_) => -rate,
                None => rate.abs(),
            };
            Wrench {
                force: Vector3::zeros(),
                torque: Vector3::x()
                    * paritysim_aero::stroke_drag(
                        paritysim_aero::stroke_drag_constant(*omega1, *coefficient),
                        magnitude,
                        rate,
                    ),
            }
        }
        WingAero::BladeElement(model) => {
            let eff = effective(omega6, v6, r_f);
            let loads = match branch {
                Some(b) => model.loads_omega_branch(&eff, r61, b)?,
                None => model.loads_omega(&eff, r61)?,
            };
            Wrench {
                force: loads.lift + loads.drag,
                torque: loads.torque(),
            }
        }
    })
}

/// [`wrench`] together with its torque in the wing frame 6 (`R_6^1ᵀ τ`); on a branch of the
/// blade-element model through the lean
/// [`paritysim_aero::BladeElementModel::wing_frame_wrench_branch`] (the right-hand side's path).
///
/// # Errors
/// As [`wrench`].
#[inline]
pub fn wrench_and_wing_torque(
    aero: &WingAero,
    omega6: &Vector3<f64>,
    v6: &Vector3<f64>,
    r61: &Matrix3<f64>,
    r_f: f64,
    branch: Option<Branch>,
) -> Result<(Wrench, Vector3<f64>)> {
    match (aero, branch) {
        (WingAero::None, _) => Ok((Wrench::default(), Vector3::zeros())),
        (WingAero::BladeElement(model), Some(b)) => {
            let (f6, t6) = model.wing_frame_wrench_branch(&effective(omega6, v6, r_f), b)?;
            Ok((
                Wrench {
                    force: r61 * f6,
                    torque: r61 * t6,
                },
                t6,
            ))
        }
        _ => {
            let w = wrench(aero, omega6, v6, r61, r_f, branch)?;
            Ok((w, r61.transpose() * w.torque))
        }
    }
}
