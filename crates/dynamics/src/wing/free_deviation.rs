//! Closed-form wing terms with a free deviation θ (α2 = 90°, α3 = 0 shoulders, §2.5).

use nalgebra::{Matrix3, Vector2, Vector3};
use paritysim_aero::Branch;

use super::{Wing, WingTerms};

impl Wing {
    /// [`Self::terms`] with the deviation θ free on an α2 = 90°, α3 = 0 shoulder (the Table 3.3
    /// wings' and the §2.5 Lift / Dual PARITY devices'), in closed form: the closure
    /// `R_x(φ) R_y(γ5) ŝ3 = R_y(θ) R_ŝ2(γ2) ŝ3` (eqs. 2.2–2.7 with `ŝ2 = x̂`, `ŝ3 = ẑ`) gives
    /// `tan γ5 = cos φ tan θ` (eq. 2.12's solution, `γ5 = atan2(cos φ sin θ, cos θ)`), so with
    /// `D = cos²θ + cos²φ sin²θ` (eq. 2.12's determinant)
    ///
    /// ```text
    /// ∂γ5/∂φ = −sin φ sin θ cos θ / D          ∂γ5/∂θ = cos φ / D
    /// ∂²γ5/∂φ² = −sin θ cos θ cos φ (D + 2 sin²θ sin²φ) / D²
    /// ∂²γ5/∂φ∂θ = −sin φ (D − 2 cos²φ sin²θ) / D²      ∂²γ5/∂θ² = 2 cos φ sin θ cos θ sin²φ / D²
    /// ```
    ///
    /// and `J6`, `J̇6 ṗ` (A.9, as [`Self::terms`] assembles them) need no joint-angle solve, no
    /// closure LU and no second pose. Valid without springs on joints 2, 3, 5
    /// ([`Self::has_closed_form_free_deviation`]); tested against [`Self::terms`]. `None` (use
    /// [`Self::terms`], which reports the error) for non-finite input or within 1e-12 of the
    /// singular poses of eqs. 2.12 / 2.13.
    pub fn free_deviation_terms(
        &self,
        p: &Vector3<f64>,
        p_dot: &Vector3<f64>,
    ) -> Option<WingTerms> {
        self.free_deviation_terms_on(p, p_dot, None)
    }

    /// [`Self::free_deviation_terms`] with the blade element on `branch` when given (event
    /// location).
    pub(crate) fn free_deviation_terms_on(
        &self,
        p: &Vector3<f64>,
        p_dot: &Vector3<f64>,
        branch: Option<Branch>,
    ) -> Option<WingTerms> {
        let (phi, theta, psi) = (p.x, p.y, p.z);
        if !(phi.is_finite() && theta.is_finite() && psi.is_finite()) {
            return None;
        }
        let (sp, cp) = phi.sin_cos();
        let (st, ct) = theta.sin_cos();
        let d = ct * ct + cp * cp * st * st;
        // The general solve's singular poses (eq. 2.12's and eq. 2.13's determinants).
        if d < 1e-12 || cp * cp + ct * ct * sp * sp < 1e-12 {
            return None;
        }
        let root = d.sqrt();
        let (s5, c5) = (cp * st / root, ct / root);
        let g5 = (cp * st).atan2(ct);
        let d_sq = d * d;
        let g5_phi = -sp * st * ct / d;
        let g5_theta = cp / d;
        let h_pp = -st * ct * cp * (d + 2.0 * st * st * sp * sp) / d_sq;
        let h_pt = -sp * (d - 2.0 * cp * cp * st * st) / d_sq;
        let h_tt = 2.0 * cp * st * ct * sp * sp / d_sq;

        let (ss, cs) = psi.sin_cos();
        let r3 = Matrix3::new(1.0, 0.0, 0.0, 0.0, cp, -sp, 0.0, sp, cp);
        let r4 = r3 * Matrix3::new(c5, 0.0, s5, 0.0, 1.0, 0.0, -s5, 0.0, c5);
        let r61 = r4 * Matrix3::new(cs, -ss, 0.0, ss, cs, 0.0, 0.0, 0.0, 1.0);
        // A.9: ŷ4⁶ = R_z(ψ)ᵀ ŷ, x̂3⁶ = R_6^1ᵀ x̂.
        let y4 = Vector3::new(ss, cs, 0.0);
        let x3 = r61.row(0).transpose();
        let j6 = Matrix3::from_columns(&[y4 * g5_phi + x3, y4 * g5_theta, Vector3::z()]);
        let omega = j6 * p_dot;

        // J̇6 ṗ from link angular velocities, as in `terms`.
        let rates = Vector2::new(p_dot.x, p_dot.y);
        let g5_dot = g5_phi * p_dot.x + g5_theta * p_dot.y;
        let y3 = Vector3::new(0.0, cp, sp);
        let z4 = Vector3::new(r4[(0, 2)], r4[(1, 2)], r4[(2, 2)]);
        let omega4 = Vector3::x() * p_dot.x + y3 * g5_dot;
        let hessian = nalgebra::Matrix2::new(h_pp, h_pt, h_pt, h_tt);
        let accel_ground = y3 * rates.dot(&(hessian * rates))
            + Vector3::x().cross(&y3) * (g5_dot * p_dot.x)
            + omega4.cross(&z4) * p_dot.z;
        let jdot_pdot = r61.transpose() * accel_ground;

        let i_omega = self.inertia * omega;
        let mass = j6.transpose() * self.inertia * j6;
        let coriolis = j6.transpose() * (self.inertia * jdot_pdot + omega.cross(&i_omega));

        // A.6 with springs on joints 1, 4, 6 only.
        let s = &self.springs;
        let mut spring = Vector3::new(s[0].torque(phi), s[3].torque(theta), s[5].torque(psi));
        let mut potential = s[0].energy(phi) + s[3].energy(theta) + s[5].energy(psi);
        self.add_tunable_hinge(theta, psi, &mut spring, &mut potential);

        let aero_frame6 = self.aero.torque(p_dot, &omega, &r61, branch);
        Some(WingTerms {
            mass,
            coriolis,
            spring,
            aero: j6.transpose() * aero_frame6,
            aero_frame6,
            j6,
            omega,
            jdot_pdot,
            rotation: r61,
            theta_w: g5,
            potential,
            kinetic: 0.5 * omega.dot(&i_omega),
        })
    }

    /// `ω⁶ = J6 ṗ` of [`Self::free_deviation_terms`] alone (the same operations: the blade
    /// element's switching functions read it once per step): `J6 = [ŷ4⁶ ∂γ5/∂φ + x̂3⁶,
    /// ŷ4⁶ ∂γ5/∂θ, ẑ]` with `x̂3⁶ = (cos γ5 cos ψ, −cos γ5 sin ψ, sin γ5)`, the first row of
    /// `R_6^1 = R_x(φ) R_y(γ5) R_z(ψ)`. `None` where the closed form does not apply.
    pub(crate) fn free_deviation_omega(
        &self,
        p: &Vector3<f64>,
        p_dot: &Vector3<f64>,
    ) -> Option<Vector3<f64>> {
        let (phi, theta, psi) = (p.x, p.y, p.z);
        if !(phi.is_finite() && theta.is_finite() && psi.is_finite()) {
            return None;
        }
        let (sp, cp) = phi.sin_cos();
        let (st, ct) = theta.sin_cos();
        let d = ct * ct + cp * cp * st * st;
        if d < 1e-12 || cp * cp + ct * ct * sp * sp < 1e-12 {
            return None;
        }
        let root = d.sqrt();
        let (s5, c5) = (cp * st / root, ct / root);
        let g5_phi = -sp * st * ct / d;
        let g5_theta = cp / d;
        let (ss, cs) = psi.sin_cos();
        let y4 = Vector3::new(ss, cs, 0.0);
        let x3 = Vector3::new(c5 * cs, c5 * -ss, s5);
        let j6 = Matrix3::from_columns(&[y4 * g5_phi + x3, y4 * g5_theta, Vector3::z()]);
        Some(j6 * p_dot)
    }
}
