//! Closed-form wing terms on the stroke plane (θ held at 0, α2 = 90° shoulders, §3.4).

use nalgebra::{Matrix3, Vector3};
use paritysim_aero::Branch;

use super::{Wing, WingAero, WingTerms};

impl Wing {
    /// [`Self::terms`] on the stroke plane (θ = θ̇ = 0) of an α2 = 90° shoulder, in closed form:
    /// with γ5 ≡ 0, γ3 = 0, γ2 = φ and ∂γ5/∂θ = cos φ (any α3), `R_6^1 = R_x(φ) R_z(ψ)`,
    /// `J6 = [(cψ, −sψ, 0), cos φ (sψ, cψ, 0), ẑ]` and `J̇6 ṗ = φ̇ ψ̇ (−sψ, −cψ, 0)`. Valid without
    /// springs on joints 2, 3, 5; tested against [`Self::terms`].
    pub fn stroke_plane_terms(&self, p: &Vector3<f64>, p_dot: &Vector3<f64>) -> WingTerms {
        self.stroke_plane_terms_on(p, p_dot, None)
    }

    /// [`Self::stroke_plane_terms`] with the blade element on `branch` when given (event
    /// location).
    pub(crate) fn stroke_plane_terms_on(
        &self,
        p: &Vector3<f64>,
        p_dot: &Vector3<f64>,
        branch: Option<Branch>,
    ) -> WingTerms {
        let k = self.stroke_plane_kinematics(p, p_dot);
        let i_omega = self.inertia * k.omega;
        let aero_frame6 = self.aero.torque(p_dot, &k.omega, &k.rotation, branch);
        WingTerms {
            mass: k.j6.transpose() * self.inertia * k.j6,
            coriolis: k.j6.transpose() * (self.inertia * k.jdot_pdot + k.omega.cross(&i_omega)),
            aero: k.j6.transpose() * aero_frame6,
            aero_frame6,
            kinetic: 0.5 * k.omega.dot(&i_omega),
            ..k
        }
    }

    /// The kinematic part of [`Self::stroke_plane_terms`] (rotation, `J6`, `ω`, `J̇6 ṗ`) and the
    /// joint springs with the tunable hinge, without the inertial and aerodynamic terms (the
    /// free-flight model assembles its own): `mass` is the identity, `coriolis`, `aero`,
    /// `aero_frame6` and `kinetic` are zero.
    pub fn stroke_plane_kinematics(&self, p: &Vector3<f64>, p_dot: &Vector3<f64>) -> WingTerms {
        let (phi, psi) = (p.x, p.z);
        let (sp, cp) = phi.sin_cos();
        // ψ ≡ 0 on fixed (stroke-only) wings: skip its rotation.
        let (ss, cs) = if psi == 0.0 {
            (0.0, 1.0)
        } else {
            psi.sin_cos()
        };
        let roll = Matrix3::new(1.0, 0.0, 0.0, 0.0, cp, -sp, 0.0, sp, cp);
        let rotation = if psi == 0.0 {
            roll
        } else {
            roll * Matrix3::new(cs, -ss, 0.0, ss, cs, 0.0, 0.0, 0.0, 1.0)
        };
        let j6 = Matrix3::new(cs, cp * ss, 0.0, -ss, cp * cs, 0.0, 0.0, 0.0, 1.0);
        let omega = j6 * p_dot;
        let jdot_pdot = Vector3::new(-ss, -cs, 0.0) * (p_dot.x * p_dot.z);
        let sp_ = &self.springs;
        let mut spring = Vector3::new(sp_[0].torque(phi), sp_[3].torque(0.0), sp_[5].torque(psi));
        let mut potential = sp_[0].energy(phi) + sp_[3].energy(0.0) + sp_[5].energy(psi);
        self.add_tunable_hinge(0.0, psi, &mut spring, &mut potential);
        WingTerms {
            mass: Matrix3::identity(),
            coriolis: Vector3::zeros(),
            spring,
            aero: Vector3::zeros(),
            aero_frame6: Vector3::zeros(),
            j6,
            omega,
            jdot_pdot,
            rotation,
            theta_w: 0.0,
            potential,
            kinetic: 0.0,
        }
    }

    /// Body reaction torques `(aerodynamic, inertial)` of a wing that only strokes (θ = ψ = 0
    /// held, α2 = 90°: [`Self::stroke_plane_terms`] at ψ = 0), in the shoulder ground frame and
    /// not mirrored: `τ_react = R6 (τ_aero⁶ − (I ω̇ + ω × I ω))` (Euler's equations, the
    /// reaction of A.13's wing on the body) with, in closed form, `R6 = R_x(φ)`, `ω = φ̇ x̂`,
    /// `ω̇ = φ̈ x̂` (`J6 = diag(1, cos φ, 1)`, `J̇6 ṗ = 0`), so
    /// `I ω̇ + ω × I ω = φ̈ I x̂ + φ̇² (0, −I_zx, I_yx)`; the §3.3 drag torque stays on the
    /// stroke axis (`R6 R6ᵀ x̂ = x̂`). The operations are those of the general path in the same
    /// order (tested against it): about 30 flops instead of a mass matrix and two rotations.
    #[inline]
    pub fn stroke_reaction_torques(
        &self,
        phi: f64,
        phi_dot: f64,
        phi_ddot: f64,
    ) -> (Vector3<f64>, Vector3<f64>) {
        let inertia_x = Vector3::new(
            self.inertia[(0, 0)],
            self.inertia[(1, 0)],
            self.inertia[(2, 0)],
        );
        let on_axis = matches!(self.aero, WingAero::None | WingAero::StrokeDrag { .. });
        if on_axis && inertia_x.y == 0.0 && inertia_x.z == 0.0 {
            // No product of inertia with the stroke axis and a drag torque about it: both
            // torques lie on x̂, which R_x(φ) keeps (the general path's other components are
            // exact zeros too).
            let inertial = -(inertia_x.x * phi_ddot);
            return (
                Vector3::new(self.aero.stroke_torque(phi_dot), 0.0, 0.0),
                Vector3::new(inertial, 0.0, 0.0),
            );
        }
        let (s, c) = phi.sin_cos();
        // R_x(φ) v.
        let rotate = |v: &Vector3<f64>| Vector3::new(v.x, c * v.y - s * v.z, s * v.y + c * v.z);
        let aero = match &self.aero {
            WingAero::None => Vector3::zeros(),
            WingAero::StrokeDrag { .. } => Vector3::new(self.aero.stroke_torque(phi_dot), 0.0, 0.0),
            other => {
                let omega = Vector3::new(phi_dot, 0.0, 0.0);
                let rotation = Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c);
                rotate(&other.torque(&omega, &omega, &rotation, None))
            }
        };
        let i_omega = inertia_x * phi_dot;
        // ω × Iω with ω = φ̇ x̂.
        let gyro = Vector3::new(0.0, -(phi_dot * i_omega.z), phi_dot * i_omega.y);
        let inertial6 = -(inertia_x * phi_ddot + gyro);
        (aero, rotate(&inertial6))
    }

    /// The joint-spring loads `(∂V/∂φ, ∂V/∂ψ)` on the stroke plane (θ = 0; joints 1 and 6
    /// and the tunable hinge, as [`Self::stroke_plane_kinematics`] adds them).
    #[inline]
    pub(crate) fn stroke_plane_springs(&self, phi: f64, psi: f64) -> (f64, f64) {
        let s = &self.springs;
        let mut spring = Vector3::new(s[0].torque(phi), 0.0, s[5].torque(psi));
        let mut potential = 0.0;
        self.add_tunable_hinge(0.0, psi, &mut spring, &mut potential);
        (spring.x, spring.z)
    }

    /// The derivatives `(∂²V/∂φ², ∂²V/∂ψ²)` of [`Self::stroke_plane_springs`] (θ = 0: the
    /// tunable hinge adds `k(0)`; the loads do not couple φ and ψ).
    #[inline]
    pub(crate) fn stroke_plane_spring_slopes(&self, phi: f64, psi: f64) -> (f64, f64) {
        let s = &self.springs;
        let hinge = self.tunable_hinge.map_or(0.0, |h| h.stiffness(0.0));
        (s[0].slope(phi), s[5].slope(psi) + hinge)
    }
}
