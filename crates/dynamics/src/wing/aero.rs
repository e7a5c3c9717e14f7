//! A wing's aerodynamic model inside the right-hand side: stroke drag or the blade element.

use nalgebra::{Matrix3, Vector3};
use paritysim_aero::{
    BladeElementModel, Branch, CoefficientSet, stroke_drag_constant, stroke_drag_torque,
};
use paritysim_error::{Result, check_non_negative};

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
}

impl WingAero {
    /// The §3.3 fixed-wing drag `Ω φ̇²` scaled by `coefficient`.
    pub fn stroke_drag(omega1: f64, coefficient: f64) -> Result<Self> {
        Ok(WingAero::StrokeDrag {
            omega1: check_non_negative("omega1", omega1)?,
            coefficient: check_non_negative("coefficient", coefficient)?,
        })
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
        }
    }

    /// Aerodynamic torque on the wing, in frame 6 (the blade element on `branch` when given).
    #[inline]
    pub(super) fn torque(
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
    pub(crate) fn torque_about(
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
