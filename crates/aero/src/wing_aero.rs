//! A wing's aerodynamic law, written once: [`WingAero`] (none, the stroke drag of eq. 2.16,
//! the blade element of §3.2.4, or Whitney & Wood 2010 with rotational lift and added mass)
//! and everything the engine asks of it: the torque on a wing
//! turning about a fixed shoulder (the fixed-body right-hand sides, [`WingAero::torque`]), and
//! the wrench on a shoulder that moves with a flying body ([`wrench`], [`switching`]).
//!
//! Adding an aero model is a variant here with its arms in this file, its law in a file of
//! its own in this crate, and a spec variant (docs/recipes.md, "Add an aero model").
//!
//! # The wrench on a moving shoulder
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
//! component of `ω_eff` crosses zero ([`Branch`]); the stroke-drag torque
//! `−Ω c |r| r` of the stroke-axis rate `r` has a kink in its derivative at `r = 0`. Each wing
//! has three switching functions ([`switching`]), and [`wrench`] evaluates the branch named by
//! their sides when given one.

use nalgebra::{Matrix3, Vector3};
use paritysim_error::{Result, check_non_negative};

use crate::stroke_drag::{stroke_drag, stroke_drag_constant, stroke_drag_torque};
use crate::{BladeElementModel, Branch, CoefficientSet, WhitneyWoodModel};

/// Aerodynamic model of a wing, evaluated inside the right-hand side (allocation-free).
#[derive(Clone, Debug, PartialEq)]
pub enum WingAero {
    /// No aerodynamics (vacuum).
    None,
    /// Quadratic drag about the stroke axis, `τ = −Ω C sgn(φ̇) φ̇²`, the fixed-wing model of
    /// §2.6.1 (eq. 2.16, `C = 1`) or eq. 3.8 at α = 90° (`C = C_N(90°)`); docs/errata.md#12.
    StrokeDrag {
        /// Drag parameter Ω1 (mg·mm²).
        omega1: f64,
        /// Dimensionless multiplier `C`.
        coefficient: f64,
    },
    /// The quasi-steady blade-element model of §3.2.4 (crates/aero): `M_N, M_T, M_r, M_rd` of
    /// eqs. 3.8–3.11 from the wing's angular velocity `ω = J6 ṗ`, as a torque in frame 6.
    BladeElement(BladeElementModel<CoefficientSet>),
    /// Whitney & Wood 2010 (crates/aero/src/whitney_wood.rs): the blade element plus
    /// rotational lift (in the torques here) and added mass ([`Self::added_inertia`], which
    /// the wing adds to its inertia tensor).
    WhitneyWood2010(WhitneyWoodModel),
}

impl WingAero {
    /// The §3.3 fixed-wing drag `Ω φ̇²` scaled by `coefficient`.
    pub fn stroke_drag(omega1: f64, coefficient: f64) -> Result<Self> {
        Ok(WingAero::StrokeDrag {
            omega1: check_non_negative("omega1", omega1)?,
            coefficient: check_non_negative("coefficient", coefficient)?,
        })
    }

    /// The inertia the law adds to the wing's (mg·mm², frame 6, about the shoulder): the
    /// added mass of a law that has one, else zero. `paritysim_dynamics::Wing::new` adds it,
    /// so every form and flight run it as inertia.
    pub fn added_inertia(&self) -> Matrix3<f64> {
        match self {
            WingAero::WhitneyWood2010(model) => model.added_inertia(),
            _ => Matrix3::zeros(),
        }
    }

    /// The law's blade element when its switching surfaces are the blade element's (the
    /// blade element itself, or Whitney & Wood's translational part): event location.
    pub fn switching_blade(&self) -> Option<&BladeElementModel<CoefficientSet>> {
        match self {
            WingAero::BladeElement(model) => Some(model),
            WingAero::WhitneyWood2010(model) => Some(model.blade()),
            _ => None,
        }
    }

    /// Torque about the stroke axis of a wing that only strokes (θ = ψ = 0, `ω = φ̇ x̂`).
    #[inline]
    pub fn stroke_torque(&self, phi_dot: f64) -> f64 {
        match self {
            WingAero::None => 0.0,
            WingAero::StrokeDrag {
                omega1,
                coefficient,
            } => stroke_drag_torque(stroke_drag_constant(*omega1, *coefficient), phi_dot),
            WingAero::BladeElement(model) => {
                model.moments_omega(&Vector3::new(phi_dot, 0.0, 0.0)).normal
            }
            // ω_z = 0: no rotational lift.
            WingAero::WhitneyWood2010(model) => {
                model
                    .blade()
                    .moments_omega(&Vector3::new(phi_dot, 0.0, 0.0))
                    .normal
            }
        }
    }

    /// Aerodynamic torque on the wing, in frame 6 (the blade element on `branch` when given).
    #[inline]
    pub fn torque(
        &self,
        p_dot: &Vector3<f64>,
        omega: &Vector3<f64>,
        r61: &Matrix3<f64>,
        branch: Option<Branch>,
    ) -> Vector3<f64> {
        self.torque_about(p_dot.x, omega, &r61.row(0).transpose(), branch)
    }

    /// [`Self::torque`] from the stroke rate `φ̇`, `ω⁶` and the stroke axis x̂ (ground) in
    /// frame 6 (row 0 of `R_6^1`), the blade element on `branch` when given (event location:
    /// the smooth branch held between switches, [`Branch`]).
    #[inline]
    pub fn torque_about(
        &self,
        phi_dot: f64,
        omega: &Vector3<f64>,
        stroke_axis_6: &Vector3<f64>,
        branch: Option<Branch>,
    ) -> Vector3<f64> {
        match self {
            WingAero::None => Vector3::zeros(),
            WingAero::BladeElement(model) => match branch {
                None => model.moments_omega(omega).torque(),
                Some(b) => model.moments_omega_branch(omega, b).torque(),
            },
            WingAero::WhitneyWood2010(model) => model.torque(omega, branch),
            WingAero::StrokeDrag {
                omega1,
                coefficient,
            } => {
                // Torque about the stroke axis x̂ (ground), expressed in frame 6.
                *stroke_axis_6
                    * stroke_drag_torque(stroke_drag_constant(*omega1, *coefficient), phi_dot)
            }
        }
    }
}

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
/// [`BladeElementModel::switching_functions`] of `ω_eff`; the stroke-axis
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
        WingAero::WhitneyWood2010(model) => model
            .blade()
            .switching_functions(&effective(omega6, v6, r_f)),
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
                    * stroke_drag(stroke_drag_constant(*omega1, *coefficient), magnitude, rate),
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
        WingAero::WhitneyWood2010(model) => {
            let eff = effective(omega6, v6, r_f);
            let blade = model.blade();
            let loads = match branch {
                Some(b) => blade.loads_omega_branch(&eff, r61, b)?,
                None => blade.loads_omega(&eff, r61)?,
            };
            Wrench {
                force: loads.lift + loads.drag + r61 * model.rotational_lift_force(&eff, branch),
                torque: loads.torque() + r61 * model.rotational_lift_torque(&eff, branch),
            }
        }
    })
}

/// [`wrench`] together with its torque in the wing frame 6 (`R_6^1ᵀ τ`); on a branch of the
/// blade-element model through the lean
/// [`BladeElementModel::wing_frame_wrench_branch`] (the right-hand side's path).
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
