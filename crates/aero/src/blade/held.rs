//! The blade-element moments on a branch held by event location, written for SIMD lanes:
//! over [`Real`] (one state or four, the same bits per lane) and the §3.4 stroke plane's
//! closed form over `f64x4` (issue 12 item 6).

use std::f64::consts::{FRAC_PI_2, PI};

use paritysim_simd::{Real, atan2, f64x4};

use super::{BladeElementModel, Branch, NormalForceLaw, unit_sign};
use crate::coefficients::CoefficientSet;

/// A branch held by event location ([`Branch`]) of one state or of four in SIMD lanes: `σ`
/// (`±1`, the chordwise side), the side of α = π/2 (`below`) and `sgn ω_z` (`±1`).
#[derive(Clone, Copy, Debug)]
pub struct HeldBranch<R: Real> {
    /// `σ = ±1`.
    pub sigma: R,
    /// The α ≤ π/2 branch of the coefficients.
    pub below: R::Mask,
    /// `sgn ω_z = ±1` of the rotational damping.
    pub spanwise: R,
}

impl HeldBranch<f64> {
    /// The scalar form of `branch`.
    pub fn of(branch: Branch) -> Self {
        Self {
            sigma: unit_sign(branch.chordwise_positive),
            below: branch.normal_positive,
            spanwise: unit_sign(branch.spanwise_positive),
        }
    }
}

impl HeldBranch<f64x4> {
    /// Four branches, one per lane.
    pub fn lanes(branches: [Branch; 4]) -> Self {
        let mask = |b: bool| if b { f64::from_bits(!0) } else { 0.0 };
        Self {
            sigma: f64x4::new(branches.map(|b| unit_sign(b.chordwise_positive))),
            below: f64x4::new(branches.map(|b| mask(b.normal_positive))),
            spanwise: f64x4::new(branches.map(|b| unit_sign(b.spanwise_positive))),
        }
    }
}

impl BladeElementModel<CoefficientSet> {
    /// [`Self::moments_stroke_plane`]'s torque `(M_N, M_T, M_r + M_rd)` on held branches for
    /// four states at once (SIMD lanes, `branch` per lane): bit for bit the scalar torque of
    /// each lane (the same operations in the same order, the coefficients'
    /// [`CoefficientSet::lift_drag_branch_generic`]). For the ensembles of the sweep engine.
    /// `None` for a lane with `ω_x = ω_y = 0` (the scalar model's special case).
    #[inline]
    pub fn stroke_plane_torque_lanes(
        &self,
        phi_dot: f64x4,
        psi: f64x4,
        (sin_psi, cos_psi): (f64x4, f64x4),
        psi_dot: f64x4,
        branch: &HeldBranch<f64x4>,
    ) -> Option<[f64x4; 3]> {
        let o = &self.omegas;
        let k = f64x4::splat;
        let (wx, wy, wz) = (cos_psi * phi_dot, -sin_psi * phi_dot, psi_dot);
        let w2 = wx * wx + wy * wy;
        if w2.simd_eq(k(0.0)).any() {
            return None;
        }
        let damping = branch.spanwise * wz * wz;
        let rotational_damping = k(-o.omega2 * self.rotational_damping) * damping; // eq. 3.10
        let sigma = branch.sigma;
        let alpha = k(FRAC_PI_2) + sigma * psi;
        let (cn, ct) = match self.law {
            NormalForceLaw::Coefficient => {
                let (cl, cd) = self
                    .coefficients
                    .lift_drag_branch_generic(alpha, branch.below);
                let (sin_a, cos_a) = (cos_psi, -sigma * sin_psi);
                (cl * cos_a + cd * sin_a, cd * cos_a - cl * sin_a)
            }
            NormalForceLaw::Unit => (k(1.0), k(0.0)),
        };
        let d_cp = k(0.82 / PI) * alpha + k(0.05); // eq. 3.7
        // AeroMoments::of_strip, eqs. 3.8, 3.9, 3.11.
        let normal = k(-o.omega1) * sigma * w2 * cn;
        let tangential = k(-o.omega1) * w2 * ct;
        let rotational = -(k(o.omega3) * d_cp - k(o.omega4)) * sigma * w2 * cn;
        Some([normal, tangential, rotational + rotational_damping])
    }

    /// [`Self::moments_omega_branch`]'s torque `(M_N, M_T, M_r + M_rd)` written once over
    /// [`Real`] (eqs. 3.8–3.11; the shared polynomial `atan2`, `sin`, `cos` of
    /// `paritysim_simd`): of one state, or of four in SIMD lanes on one model, bit for bit the
    /// same per lane. What the free-deviation devices' right-hand side takes on a held branch.
    #[inline]
    pub fn torque_on_branch<R: Real>(&self, omega: [R; 3], branch: &HeldBranch<R>) -> [R; 3] {
        let o = &self.omegas;
        let k = R::splat;
        let [wx, wy, wz] = omega;
        let w2 = wx * wx + wy * wy;
        let rotational_damping =
            k(-o.omega2) * k(self.rotational_damping) * branch.spanwise * wz * wz; // eq. 3.10
        let sigma = branch.sigma;
        // α on the branch of σ: atan2(σ ω_x, ω_y) continued through 0 and π (`branch_alpha`).
        let a = atan2(sigma * wx, wy);
        let alpha = R::select(a.lt(k(-FRAC_PI_2)), a + k(2.0 * PI), a);
        let (cn, ct) = match self.law {
            NormalForceLaw::Coefficient => {
                let (cl, cd) = self
                    .coefficients
                    .lift_drag_branch_generic(alpha, branch.below);
                crate::coefficients::to_normal_tangential_generic(alpha, cl, cd)
            }
            NormalForceLaw::Unit => (k(1.0), k(0.0)),
        };
        let d_cp = k(0.82 / PI) * alpha + k(0.05); // eq. 3.7
        // AeroMoments::of_strip: eqs. 3.8, 3.9, 3.11.
        let normal = k(-o.omega1) * sigma * w2 * cn;
        let tangential = k(-o.omega1) * w2 * ct;
        let rotational = -(k(o.omega3) * d_cp - k(o.omega4)) * sigma * w2 * cn;
        // ω_x = ω_y = 0: only the rotational damping (the scalar model's special case).
        let still = w2.eq(k(0.0));
        [
            R::select(still, k(0.0), normal),
            R::select(still, k(0.0), tangential),
            R::select(
                still,
                k(0.0) + rotational_damping,
                rotational + rotational_damping,
            ),
        ]
    }
}
