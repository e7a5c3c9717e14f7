//! Closed-form wing terms with a free deviation θ (α2 = 90°, α3 = 0 shoulders, §2.5).

use nalgebra::{Matrix3, Vector2, Vector3};
use paritysim_aero::Branch;

use super::{Wing, WingTerms};

/// The pose and velocity terms of a free-deviation wing ([`Wing::free_deviation_kinematics`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct FreeDeviationKinematics {
    /// `(sin φ, cos φ)` and `(sin θ, cos θ)`.
    pub(crate) sin_cos_phi: (f64, f64),
    pub(crate) sin_cos_theta: (f64, f64),
    /// `J6` (A.9), `ω⁶ = J6 ṗ`, `J̇6 ṗ` and `R_6^1`.
    pub(crate) j6: Matrix3<f64>,
    pub(crate) omega: Vector3<f64>,
    pub(crate) jdot_pdot: Vector3<f64>,
    pub(crate) rotation: Matrix3<f64>,
}

/// What the closed form of a free-deviation pose `(φ, θ, ψ)` starts from (module docs of
/// [`Wing::free_deviation_terms`]): the angles' sines and cosines, eq. 2.12's determinant
/// `D = cos²θ + cos²φ sin²θ`, `(sin γ5, cos γ5)` and `∂γ5/∂φ`, `∂γ5/∂θ`.
struct Pose {
    sin_cos_phi: (f64, f64),
    sin_cos_theta: (f64, f64),
    sin_cos_psi: (f64, f64),
    d: f64,
    sin_cos_gamma5: (f64, f64),
    g5_phi: f64,
    g5_theta: f64,
}

impl Pose {
    /// `None` for non-finite angles or within 1e-12 of the general solve's singular poses
    /// (eq. 2.12's and eq. 2.13's determinants).
    #[inline(always)]
    fn of(p: &Vector3<f64>) -> Option<Self> {
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
        Some(Self {
            sin_cos_phi: (sp, cp),
            sin_cos_theta: (st, ct),
            sin_cos_psi: psi.sin_cos(),
            d,
            sin_cos_gamma5: (cp * st / root, ct / root),
            g5_phi: -sp * st * ct / d,
            g5_theta: cp / d,
        })
    }
}

/// The dynamic terms of a free-deviation wing ([`Wing::free_deviation_dynamics`]), as in
/// [`WingTerms`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct FreeDeviationDynamics {
    pub(crate) mass: Matrix3<f64>,
    pub(crate) coriolis: Vector3<f64>,
    pub(crate) spring: Vector3<f64>,
    pub(crate) aero: Vector3<f64>,
    pub(crate) aero_frame6: Vector3<f64>,
    pub(crate) i_omega: Vector3<f64>,
    pub(crate) potential: f64,
}

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
        let k = self.free_deviation_kinematics(p, p_dot)?;
        let d = self.free_deviation_dynamics(p, p_dot, &k, branch);
        let (_, cp) = k.sin_cos_phi;
        let (st, ct) = k.sin_cos_theta;
        Some(WingTerms {
            mass: d.mass,
            coriolis: d.coriolis,
            spring: d.spring,
            aero: d.aero,
            aero_frame6: d.aero_frame6,
            j6: k.j6,
            omega: k.omega,
            jdot_pdot: k.jdot_pdot,
            rotation: k.rotation,
            theta_w: (cp * st).atan2(ct),
            potential: d.potential,
            kinetic: 0.5 * k.omega.dot(&d.i_omega),
        })
    }

    /// The pose and velocity terms of [`Self::free_deviation_terms`]: `J6`, `ω⁶`, `J̇6 ṗ`,
    /// `R_6^1` (see there). `None` where the closed form does not apply.
    #[inline(always)]
    pub(crate) fn free_deviation_kinematics(
        &self,
        p: &Vector3<f64>,
        p_dot: &Vector3<f64>,
    ) -> Option<FreeDeviationKinematics> {
        let Pose {
            sin_cos_phi: (sp, cp),
            sin_cos_theta: (st, ct),
            sin_cos_psi: (ss, cs),
            d,
            sin_cos_gamma5: (s5, c5),
            g5_phi,
            g5_theta,
        } = Pose::of(p)?;
        let d_sq = d * d;
        let h_pp = -st * ct * cp * (d + 2.0 * st * st * sp * sp) / d_sq;
        let h_pt = -sp * (d - 2.0 * cp * cp * st * st) / d_sq;
        let h_tt = 2.0 * cp * st * ct * sp * sp / d_sq;

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
        Some(FreeDeviationKinematics {
            sin_cos_phi: (sp, cp),
            sin_cos_theta: (st, ct),
            j6,
            omega,
            jdot_pdot,
            rotation: r61,
        })
    }

    /// The dynamic terms of [`Self::free_deviation_terms`] at the pose `k` of `(p, ṗ)`: what
    /// the lean right-hand side of the §2.5 devices (`device/free_deviation.rs`) reads.
    #[inline(always)]
    pub(crate) fn free_deviation_dynamics(
        &self,
        p: &Vector3<f64>,
        p_dot: &Vector3<f64>,
        k: &FreeDeviationKinematics,
        branch: Option<Branch>,
    ) -> FreeDeviationDynamics {
        let (phi, theta, psi) = (p.x, p.y, p.z);
        let (j6, omega) = (&k.j6, &k.omega);
        let i_omega = self.inertia * omega;
        let mass = j6.transpose() * self.inertia * j6;
        let coriolis = j6.transpose() * (self.inertia * k.jdot_pdot + omega.cross(&i_omega));

        // A.6 with springs on joints 1, 4, 6 only.
        let s = &self.springs;
        let mut spring = Vector3::new(s[0].torque(phi), s[3].torque(theta), s[5].torque(psi));
        let mut potential = s[0].energy(phi) + s[3].energy(theta) + s[5].energy(psi);
        self.add_tunable_hinge(theta, psi, &mut spring, &mut potential);

        let aero_frame6 = self.aero.torque(p_dot, omega, &k.rotation, branch);
        FreeDeviationDynamics {
            mass,
            coriolis,
            spring,
            aero: j6.transpose() * aero_frame6,
            aero_frame6,
            i_omega,
            potential,
        }
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
        let Pose {
            sin_cos_psi: (ss, cs),
            sin_cos_gamma5: (s5, c5),
            g5_phi,
            g5_theta,
            ..
        } = Pose::of(p)?;
        let y4 = Vector3::new(ss, cs, 0.0);
        let x3 = Vector3::new(c5 * cs, c5 * -ss, s5);
        let j6 = Matrix3::from_columns(&[y4 * g5_phi + x3, y4 * g5_theta, Vector3::z()]);
        Some(j6 * p_dot)
    }
}
