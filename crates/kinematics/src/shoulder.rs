//! The spherical five-bar shoulder of §2.3.3.
//!
//! Six links, six revolute joints through one spherical centre; link 1 is ground. The
//! configuration is `p = (φ, θ, ψ) = (γ1, γ4, γ6)` (eq. 2.1). Link rotations relative to ground:
//!
//! ```text
//! R_3^1 = R_x(φ)          (2.2)      R_4^1 = R_x(φ) R_y(γ5)            (2.5)
//! R_2^1 = R_y(θ)          (2.3)      R_5^1 = R_y(θ) R_ŝ2(γ2)           (2.6)
//! R_6^4 = R_z(ψ)          (2.4)      R_6^1 = R_4^1 R_z(ψ),  R_4^5 = R_ŝ3(γ3)
//! ```
//!
//! with `ŝ2 = (sin α2, 0, cos α2)` and `ŝ3 = (sin α3, 0, cos α3)` (eq. 2.7). The wing (frame 6)
//! is `R_6^1 = R_x(φ) R_y(γ5) R_z(ψ)`, so the wing angles are the intrinsic x-y-z Euler angles
//! `(φ_w, θ_w, ψ_w) = (φ, γ5, ψ)`.
//!
//! Partial derivatives: instead of the overdetermined 3×2 systems A.18–A.28 (see docs/errata.md#1
//! to #3, which this module does not inherit), we use the angular-velocity closure of link 4 via
//! both chains, `φ̇ x̂ + γ̇5 ŷ3 = θ̇ ŷ + γ̇2 ŝ2¹ + γ̇3 ŝ3¹`, a square 3×3 system
//! `A (γ2, γ3, γ5)' = (x̂ | −ŷ)` whose derivative gives the second partials as
//! `A g'' = −A' g'`. The integration tests cross-check this against finite differences and
//! against the corrected A.18/A.26–A.28.

use nalgebra::{Matrix2, Matrix3, Unit, Vector2, Vector3};
use paritysim_error::{Error, Result, bail, check_finite};

use crate::rotation::{rot_axis, rot_x, rot_y, rot_z};

/// Relative determinant below which the closure system is treated as singular.
const SINGULAR_TOL: f64 = 1e-12;

/// Smallest `alpha2` and `alpha2 - alpha3` (rad): the rest pose's closure determinant
/// `sin(alpha2 - alpha3)` stays six orders above `SINGULAR_TOL`.
pub const MIN_LINK_ANGLE: f64 = 1e-6;

/// Spherical five-bar shoulder parameterised by `α2, α3` (eq. 2.7).
///
/// Construct with [`SphericalShoulder::new`]; it fails unless `0 <= α3 < α2 <= π` and
/// `α2 − α3 < π` (at `α2 − α3 = π` the denominator of eq. 2.14 vanishes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphericalShoulder {
    alpha2: f64,
    alpha3: f64,
    s2: Unit<Vector3<f64>>,
    s3: Unit<Vector3<f64>>,
    /// `c_α2 s_α3 − s_α2 c_α3 = sin(α3 − α2)`, the denominator of eq. 2.14.
    denominator: f64,
}

/// Full configuration of the shoulder at `(φ, θ, ψ)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShoulderPose {
    /// `γ1..γ6` (rad), with `γ1 = φ`, `γ4 = θ`, `γ6 = ψ`.
    pub joint_angles: [f64; 6],
    /// `R_i^1` for links 1..6 (index 0 is ground, the identity).
    pub link_rotations: [Matrix3<f64>; 6],
    /// `(φ_w, θ_w, ψ_w)`: intrinsic x-y-z Euler angles of the wing frame 6.
    pub wing_angles: Vector3<f64>,
}

/// First and second partials of the dependent joint angles with respect to `(φ, θ)`.
///
/// Gradients are `(∂/∂φ, ∂/∂θ)`, Hessians `[[∂²/∂φ², ∂²/∂φ∂θ], [∂²/∂θ∂φ, ∂²/∂θ²]]`. All
/// partials with respect to `ψ` vanish (A.17).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShoulderPartials {
    /// Gradient of γ2.
    pub gamma2: Vector2<f64>,
    /// Gradient of γ3.
    pub gamma3: Vector2<f64>,
    /// Gradient of γ5 (= θ_w).
    pub gamma5: Vector2<f64>,
    /// Hessian of γ2.
    pub gamma2_hessian: Matrix2<f64>,
    /// Hessian of γ3.
    pub gamma3_hessian: Matrix2<f64>,
    /// Hessian of γ5.
    pub gamma5_hessian: Matrix2<f64>,
}

impl SphericalShoulder {
    /// Validates `0 <= α3 < α2 <= π` (rad) and `α2 − α3 < π`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `alpha2` or `alpha3` and the allowed range.
    pub fn new(alpha2: f64, alpha3: f64) -> Result<Self> {
        use std::f64::consts::PI;
        check_finite("alpha2", alpha2)?;
        check_finite("alpha3", alpha3)?;
        if !(alpha2 > 0.0 && alpha2 <= PI) {
            bail!(invalid "alpha2", alpha2, "in (0, pi] rad");
        }
        // At rest the closure of eq. 2.12 has determinant sin(alpha2 - alpha3): a vanishing
        // link angle makes every pose singular.
        if alpha2 < MIN_LINK_ANGLE {
            bail!(invalid "alpha2", alpha2, format!("in [{MIN_LINK_ANGLE:e}, pi] rad (the closure is singular as alpha2 -> 0)"));
        }
        if alpha2 - alpha3 < MIN_LINK_ANGLE {
            bail!(invalid "alpha3", alpha3, format!("<= alpha2 - {MIN_LINK_ANGLE:e} rad (alpha2 - alpha3 -> 0 makes the closure singular)"));
        }
        if !(alpha3 >= 0.0 && alpha3 < alpha2) {
            bail!(invalid "alpha3", alpha3, format!("in [0, alpha2 = {alpha2}) rad"));
        }
        if alpha2 - alpha3 >= PI - 1e-9 {
            bail!(invalid "alpha3", alpha3,
                "> alpha2 - pi (alpha2 - alpha3 = pi makes eq. 2.14 singular)");
        }
        let (s2s, s2c) = alpha2.sin_cos();
        let (s3s, s3c) = alpha3.sin_cos();
        Ok(Self {
            alpha2,
            alpha3,
            s2: Unit::new_normalize(Vector3::new(s2s, 0.0, s2c)),
            s3: Unit::new_normalize(Vector3::new(s3s, 0.0, s3c)),
            denominator: s2c * s3s - s2s * s3c,
        })
    }

    /// `α2` (rad).
    pub fn alpha2(&self) -> f64 {
        self.alpha2
    }

    /// `α3` (rad).
    pub fn alpha3(&self) -> f64 {
        self.alpha3
    }

    /// Joint-2 axis `ŝ2` in frames 2 and 5 (eq. 2.7).
    pub fn axis2(&self) -> Unit<Vector3<f64>> {
        self.s2
    }

    /// Joint-3 axis `ŝ3` in frames 4 and 5 (eq. 2.7).
    pub fn axis3(&self) -> Unit<Vector3<f64>> {
        self.s3
    }

    /// `sin γ3` from eq. 2.14; its magnitude exceeds 1 outside the joint limit.
    #[inline]
    pub fn sin_gamma3(&self, phi: f64, theta: f64) -> f64 {
        (theta + self.alpha2).cos() * phi.sin() / self.denominator
    }

    /// Joint-limit condition of eq. 2.10.
    #[inline]
    pub fn is_reachable(&self, phi: f64, theta: f64) -> bool {
        self.sin_gamma3(phi, theta).abs() <= 1.0
    }

    /// Largest `|sin φ|` the joint limit of eq. 2.10 allows at deviation `theta`:
    /// `|sin(α3 − α2) / cos(θ + α2)|` (infinite where `cos(θ + α2) = 0`: every stroke).
    pub fn max_sin_stroke(&self, theta: f64) -> f64 {
        (self.denominator / (theta + self.alpha2).cos()).abs()
    }

    /// Attributes an out-of-domain error of the pose at `(phi, theta)` to `phi` with the stroke
    /// range eq. 2.10 allows at this `theta` (other errors are returned unchanged).
    pub fn attribute_joint_limit(&self, err: Error, phi: f64, theta: f64) -> Error {
        if !matches!(err, Error::OutOfDomain { .. }) || self.is_reachable(phi, theta) {
            return err;
        }
        let bound = self.max_sin_stroke(theta).min(1.0);
        let allowed = format!(
            "within the joint limit of eq. 2.10 at theta = {theta} rad: |sin(phi)| <= {bound:.6}, \
             i.e. |phi| <= {:.6} rad (mod pi)",
            bound.asin()
        );
        err.attributed("phi", phi, allowed)
    }

    /// `(γ2, γ3, γ5)` from the closed form of eqs. 2.11–2.13 (γ3 in `[−π/2, π/2]`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for non-finite angles, [`Error::OutOfDomain`] when eq. 2.10
    /// fails, [`Error::Singular`] where eqs. 2.12/2.13 are singular.
    pub fn dependent_angles(&self, phi: f64, theta: f64) -> Result<(f64, f64, f64)> {
        check_finite("phi", phi)?;
        check_finite("theta", theta)?;
        let sin_g3 = self.sin_gamma3(phi, theta);
        if sin_g3.abs() > 1.0 {
            return Err(Error::OutOfDomain {
                what: "shoulder pose".into(),
                detail: format!(
                    "outside the joint limit of eq. 2.10 at phi = {phi}, theta = {theta} rad: \
                     |cos(theta + alpha2) sin(phi) / sin(alpha3 - alpha2)| = {} > 1",
                    sin_g3.abs()
                ),
            });
        }
        let g3 = sin_g3.asin();
        let cos_g3 = g3.cos();
        let (sa2, ca2) = self.alpha2.sin_cos();
        let (sa3, ca3) = self.alpha3.sin_cos();
        let (sp, cp) = phi.sin_cos();
        let (s, c) = (theta + self.alpha2).sin_cos();

        // eq. 2.12: [[s, −cφ c], [cφ c, s]] (cγ5, sγ5)ᵀ = r
        let r1 = sa2 * sa3 * sa3
            + ca2 * sa3 * ca3
            + (sa2 * (1.0 - sa3 * sa3) - ca2 * sa3 * ca3) * cos_g3;
        let r2 = sa2 * sa3 * ca3
            + ca2 * ca3 * ca3
            + (-sa2 * sa3 * ca3 + ca2 * (1.0 - ca3 * ca3)) * cos_g3;
        let (a, b) = (s, cp * c);
        let det5 = a * a + b * b;
        if det5 < SINGULAR_TOL {
            bail!(Singular "eq. 2.12 is singular at phi = {phi}, theta = {theta} (det = {det5:e})");
        }
        let g5 = (-b * r1 + a * r2).atan2(a * r1 + b * r2);

        // eq. 2.13: [[cφ, s sφ], [s sφ, −cφ]] (cγ2, sγ2)ᵀ = (cγ3, cos(α2 − α3) sγ3)ᵀ
        let (m11, m12, m22) = (cp, s * sp, -cp);
        let det2 = m11 * m22 - m12 * m12;
        if det2.abs() < SINGULAR_TOL {
            bail!(Singular "eq. 2.13 is singular at phi = {phi}, theta = {theta} (det = {det2:e})");
        }
        let (v1, v2) = (cos_g3, (self.alpha2 - self.alpha3).cos() * sin_g3);
        let cg2 = (v1 * m22 - m12 * v2) / det2;
        let sg2 = (m11 * v2 - m12 * v1) / det2;
        Ok((sg2.atan2(cg2), g3, g5))
    }

    /// Full pose: six joint angles, six link rotations and the wing angles.
    ///
    /// # Errors
    /// As [`Self::dependent_angles`], plus [`Error::InvalidParameter`] for a non-finite `psi`.
    pub fn pose(&self, phi: f64, theta: f64, psi: f64) -> Result<ShoulderPose> {
        check_finite("psi", psi)?;
        let (g2, g3, g5) = self.dependent_angles(phi, theta)?;
        let r3 = rot_x(phi);
        let r2 = rot_y(theta);
        let r4 = r3 * rot_y(g5);
        let r5 = r2 * rot_axis(&self.s2, g2);
        let r6 = r4 * rot_z(psi);
        Ok(ShoulderPose {
            joint_angles: [phi, g2, g3, theta, g5, psi],
            link_rotations: [Matrix3::identity(), r2, r3, r4, r5, r6],
            wing_angles: Vector3::new(phi, g5, psi),
        })
    }

    /// First and second partials of γ2, γ3, γ5 with respect to `(φ, θ)`.
    ///
    /// # Errors
    /// As [`Self::dependent_angles`]; [`Error::Singular`] where the closure system is singular
    /// (the mechanism is at a singular configuration and the partials are unbounded).
    pub fn partials(&self, phi: f64, theta: f64) -> Result<ShoulderPartials> {
        let (g2, _g3, g5) = self.dependent_angles(phi, theta)?;
        self.partials_at(phi, theta, g2, g5)
    }

    /// As [`Self::partials`] when `γ2, γ5` are already known (avoids re-solving the pose).
    pub fn partials_at(&self, phi: f64, theta: f64, g2: f64, g5: f64) -> Result<ShoulderPartials> {
        let x = Vector3::x();
        let y = Vector3::y();
        let r3 = rot_x(phi);
        let s2g = rot_y(theta) * self.s2.as_ref(); // ŝ2¹, fixed in link 2
        let y3g = r3 * y; // ŷ3¹ (joint-5 axis), fixed in link 3
        let s3g = r3 * rot_y(g5) * self.s3.as_ref(); // ŝ3¹, fixed in links 4 and 5
        let a = Matrix3::from_columns(&[s2g, s3g, -y3g]);
        let det = a.determinant();
        if det.abs() < SINGULAR_TOL {
            bail!(Singular
                "shoulder closure is singular at phi = {phi}, theta = {theta}, gamma2 = {g2} \
                 (det = {det:e}); the partials are unbounded");
        }
        let lu = a.lu();
        let solve = |rhs: &Vector3<f64>| -> Vector3<f64> {
            lu.solve(rhs)
                .expect("non-singular: determinant checked above")
        };
        // A g_φ = x̂, A g_θ = −ŷ with g = (γ2, γ3, γ5).
        let g_phi = solve(&x);
        let g_theta = solve(&-y);

        // ∂A/∂φ and ∂A/∂θ applied to a vector g (columns rotate with their links).
        let omega4_phi = x + y3g * g_phi[2];
        let omega4_theta = y3g * g_theta[2];
        let a_phi = |g: &Vector3<f64>| -> Vector3<f64> {
            omega4_phi.cross(&s3g) * g[1] - x.cross(&y3g) * g[2]
        };
        let a_theta = |g: &Vector3<f64>| -> Vector3<f64> {
            y.cross(&s2g) * g[0] + omega4_theta.cross(&s3g) * g[1]
        };
        let g_phiphi = -solve(&a_phi(&g_phi));
        let g_phitheta = -solve(&a_theta(&g_phi));
        let g_thetatheta = -solve(&a_theta(&g_theta));

        let hess =
            |k: usize| Matrix2::new(g_phiphi[k], g_phitheta[k], g_phitheta[k], g_thetatheta[k]);
        Ok(ShoulderPartials {
            gamma2: Vector2::new(g_phi[0], g_theta[0]),
            gamma3: Vector2::new(g_phi[1], g_theta[1]),
            gamma5: Vector2::new(g_phi[2], g_theta[2]),
            gamma2_hessian: hess(0),
            gamma3_hessian: hess(1),
            gamma5_hessian: hess(2),
        })
    }

    /// The Jacobian `J6` of eq. A.9: `ω⁶ = J6 ṗ`, angular velocity of the wing in frame 6.
    ///
    /// Columns: `∂γ5/∂φ ŷ4⁶ + x̂3⁶`, `∂γ5/∂θ ŷ4⁶`, `ẑ6⁶`.
    pub fn jacobian(&self, pose: &ShoulderPose, partials: &ShoulderPartials) -> Matrix3<f64> {
        let r6_t = pose.link_rotations[5].transpose();
        let y4 = r6_t * (pose.link_rotations[2] * Vector3::y()); // ŷ4 = ŷ3 (joint 5 axis)
        let x3 = r6_t * Vector3::x(); // x̂3¹ = x̂
        Matrix3::from_columns(&[
            y4 * partials.gamma5[0] + x3,
            y4 * partials.gamma5[1],
            Vector3::z(),
        ])
    }
}
