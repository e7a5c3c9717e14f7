//! One wing on a spherical shoulder (§3.2.3, Appendix A).
//!
//! The wing (frame 6) is the only inertia (§3.2.2 item 5). With `ω = J6 ṗ` the angular
//! velocity in frame 6 (A.10) and `I` constant in frame 6, Euler's equations
//! `I ω̇ + ω × I ω = τ⁶` projected by `J6ᵀ` give the Euler-Lagrange form of A.13:
//!
//! ```text
//! M(p) = J6ᵀ I J6                                  (A.36)
//! c(p, ṗ) = J6ᵀ (I (J̇6 ṗ) + ω × I ω)               (replaces A.37–A.38, see docs/errata.md#1, #2)
//! ```
//!
//! `J̇6 ṗ` is assembled from link angular velocities (no second partials of the printed
//! A.26–A.28 are used). The tests check `M` and `c` against an independent formulation:
//! finite-differenced link rotations and Christoffel symbols of a finite-differenced `M`.

use nalgebra::{Matrix3, Vector2, Vector3};
use paritysim_aero::{BladeElementModel, Branch, CoefficientSet};
use paritysim_error::{Error, Result, check_finite, check_non_negative};
use paritysim_kinematics::SphericalShoulder;

/// Largest |entry| of a wing's inertia tensor (mg·mm²): the spec's documented range; a larger
/// one is not an insect-scale wing and overflows the mass matrix into NaN (issue 14).
pub const MAX_INERTIA_ENTRY: f64 = 1e5;

/// Smallest principal moment of a wing's inertia (mg·mm²): a million times below the thesis
/// wings' smallest (about 1); a vanishing one makes the mass matrix numerically singular and
/// the first step NaN or an underflow (issue 14).
pub const MIN_PRINCIPAL_INERTIA: f64 = 1e-6;

/// A torsion spring at a shoulder joint: `τ = k (γ − γ0) + k3 (γ − γ0)³`.
///
/// `k` in mN·mm/rad, `k3` in mN·mm/rad³ (a hardening law when `k3 > 0`), `γ0` in rad.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct JointSpring {
    stiffness: f64,
    cubic: f64,
    rest_angle: f64,
}

impl JointSpring {
    /// A linear spring (A.7). `stiffness >= 0`, finite rest angle.
    pub fn linear(stiffness: f64, rest_angle: f64) -> Result<Self> {
        Self::nonlinear(stiffness, 0.0, rest_angle)
    }

    /// A spring with an added cubic term (`cubic >= 0`: hardening, never negative stiffness).
    pub fn nonlinear(stiffness: f64, cubic: f64, rest_angle: f64) -> Result<Self> {
        Ok(Self {
            stiffness: check_non_negative("stiffness", stiffness)?,
            cubic: check_non_negative("cubic", cubic)?,
            rest_angle: check_finite("rest_angle", rest_angle)?,
        })
    }

    /// `∂V/∂γ`.
    #[inline]
    pub fn torque(&self, gamma: f64) -> f64 {
        let d = gamma - self.rest_angle;
        self.stiffness * d + self.cubic * d * d * d
    }

    /// `∂²V/∂γ² = k + 3 k3 (γ − γ0)²` (the spring's contribution to a Jacobian).
    #[inline]
    pub fn slope(&self, gamma: f64) -> f64 {
        let d = gamma - self.rest_angle;
        self.stiffness + 3.0 * self.cubic * d * d
    }

    /// Stored energy `V(γ)` (µJ).
    #[inline]
    pub fn energy(&self, gamma: f64) -> f64 {
        let d = gamma - self.rest_angle;
        0.5 * self.stiffness * d * d + 0.25 * self.cubic * d.powi(4)
    }

    /// Linear stiffness (mN·mm/rad).
    pub fn stiffness(&self) -> f64 {
        self.stiffness
    }

    /// Cubic coefficient (mN·mm/rad³).
    pub fn cubic(&self) -> f64 {
        self.cubic
    }

    /// Rest angle (rad).
    pub fn rest_angle(&self) -> f64 {
        self.rest_angle
    }
}

/// The tunable wing hinge of §2.5.1: a hinge whose stiffness rises with wing deviation,
/// `V = ½ k(θ) ψ²` with `k(θ) = k0 + k1 θ + k2 θ²` (mN·mm/rad; θ the shoulder's input deviation).
/// Generalised forces: `∂V/∂ψ = k(θ) ψ`, `∂V/∂θ = ½ k'(θ) ψ²`. The thesis gives no law; this
/// quadratic family covers a signed (k1) and a symmetric (k2) stiffening.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TunableHinge {
    k0: f64,
    k1: f64,
    k2: f64,
}

impl TunableHinge {
    /// Requires `k0 > 0` and `k2 >= 0`, and `k(θ) > 0` for all θ (`k1² < 4 k0 k2`, or `k1 = 0`).
    pub fn new(k0: f64, k1: f64, k2: f64) -> Result<Self> {
        paritysim_error::check_positive("k0", k0)?;
        check_finite("k1", k1)?;
        check_non_negative("k2", k2)?;
        if k1 != 0.0 && k1 * k1 >= 4.0 * k0 * k2 {
            return Err(Error::invalid(
                "k1",
                k1,
                format!(
                    "|k1| < 2 sqrt(k0 k2) = {} so that k(theta) > 0 for every theta",
                    2.0 * (k0 * k2).sqrt()
                ),
            ));
        }
        Ok(Self { k0, k1, k2 })
    }

    /// `k(θ)`.
    #[inline]
    pub fn stiffness(&self, theta: f64) -> f64 {
        self.k0 + (self.k1 + self.k2 * theta) * theta
    }
}

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
            } => -omega1 * coefficient * phi_dot.abs() * phi_dot,
            WingAero::BladeElement(model) => {
                model.moments_omega(&Vector3::new(phi_dot, 0.0, 0.0)).normal
            }
        }
    }

    /// Aerodynamic torque on the wing, in frame 6 (the blade element on `branch` when given).
    #[inline]
    fn torque(
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
                *stroke_axis_6 * (-omega1 * coefficient * phi_dot.abs() * phi_dot)
            }
        }
    }
}

/// A wing: shoulder, inertia about the spherical centre (frame 6), six joint springs, aero.
#[derive(Clone, Debug, PartialEq)]
pub struct Wing {
    shoulder: SphericalShoulder,
    inertia: Matrix3<f64>,
    springs: [JointSpring; 6],
    aero: WingAero,
    tunable_hinge: Option<TunableHinge>,
}

/// Everything the dynamics need from one wing at `(p, ṗ)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WingTerms {
    /// `M(p)` (mg·mm²).
    pub mass: Matrix3<f64>,
    /// `c(p, ṗ)` (mN·mm).
    pub coriolis: Vector3<f64>,
    /// `∂V/∂p` of the joint springs (mN·mm).
    pub spring: Vector3<f64>,
    /// Aerodynamic generalised torque `J6ᵀ τ⁶` (mN·mm).
    pub aero: Vector3<f64>,
    /// Aerodynamic torque in frame 6 (mN·mm).
    pub aero_frame6: Vector3<f64>,
    /// `J6` (A.9).
    pub j6: Matrix3<f64>,
    /// `ω⁶ = J6 ṗ` (rad/ms).
    pub omega: Vector3<f64>,
    /// `J̇6 ṗ` (rad/ms²).
    pub jdot_pdot: Vector3<f64>,
    /// `R_6^1`.
    pub rotation: Matrix3<f64>,
    /// Wing deviation `θ_w = γ5` (rad).
    pub theta_w: f64,
    /// Spring energy (µJ).
    pub potential: f64,
    /// Kinetic energy `½ ωᵀ I ω` (µJ).
    pub kinetic: f64,
}

/// [`WingTerms`] as a plain serde record (matrices as rows; `spring` named
/// `spring_gradient`), what the bindings hand over.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct WingTermsRecord {
    /// `M(p)` (mg·mm²).
    pub mass: [[f64; 3]; 3],
    /// `c(p, ṗ)` (mN·mm).
    pub coriolis: [f64; 3],
    /// `∂V/∂p` (mN·mm).
    pub spring_gradient: [f64; 3],
    /// `J6ᵀ τ⁶` (mN·mm).
    pub aero: [f64; 3],
    /// `J6`.
    pub j6: [[f64; 3]; 3],
    /// `J6 ṗ` (rad/ms).
    pub omega: [f64; 3],
    /// `J̇6 ṗ` (rad/ms²).
    pub jdot_pdot: [f64; 3],
    /// `R_6^1`.
    pub rotation: [[f64; 3]; 3],
    /// `θ_w` (rad).
    pub theta_w: f64,
    /// Kinetic energy (µJ).
    pub kinetic: f64,
    /// Spring energy (µJ).
    pub potential: f64,
}

impl From<&WingTerms> for WingTermsRecord {
    fn from(t: &WingTerms) -> Self {
        let m = |m: &Matrix3<f64>| std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)]));
        let v = |v: &Vector3<f64>| [v[0], v[1], v[2]];
        Self {
            mass: m(&t.mass),
            coriolis: v(&t.coriolis),
            spring_gradient: v(&t.spring),
            aero: v(&t.aero),
            j6: m(&t.j6),
            omega: v(&t.omega),
            jdot_pdot: v(&t.jdot_pdot),
            rotation: m(&t.rotation),
            theta_w: t.theta_w,
            kinetic: t.kinetic,
            potential: t.potential,
        }
    }
}

impl WingTermsRecord {
    /// The terms of wing `wing` of `device` at `p = (φ, θ, ψ)`, `ṗ` (always the general terms,
    /// never the stroke-plane closed form).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a wing index past the device's wings or a non-finite
    /// `p` / `p_dot`; as [`Wing::terms`] (outside the joint limit, singular pose).
    pub fn at(device: &crate::Device, wing: usize, p: [f64; 3], p_dot: [f64; 3]) -> Result<Self> {
        let n = device.n_wings();
        let w = device
            .spec()
            .wings
            .get(wing)
            .ok_or_else(|| Error::invalid("wing", wing, format!("in [0, {n})")))?;
        paritysim_error::check_all_finite("p", &p)?;
        paritysim_error::check_all_finite("p_dot", &p_dot)?;
        Ok(Self::from(
            &w.terms(&Vector3::from(p), &Vector3::from(p_dot))?,
        ))
    }
}

impl Wing {
    /// A wing with a full inertia tensor (mg·mm², frame 6, about the spherical centre).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `inertia` when an entry is non-finite or beyond
    /// ±[`MAX_INERTIA_ENTRY`], or the tensor is not symmetric, not positive definite or has a
    /// principal moment below [`MIN_PRINCIPAL_INERTIA`].
    pub fn new(
        shoulder: SphericalShoulder,
        inertia: Matrix3<f64>,
        springs: [JointSpring; 6],
        aero: WingAero,
    ) -> Result<Self> {
        for (k, v) in inertia.iter().enumerate() {
            if !(v.is_finite() && v.abs() <= MAX_INERTIA_ENTRY) {
                return Err(Error::invalid(
                    format!("inertia[{}][{}]", k % 3, k / 3),
                    v,
                    format!("in [-{MAX_INERTIA_ENTRY:e}, {MAX_INERTIA_ENTRY:e}] mg mm^2"),
                ));
            }
        }
        let asym = (inertia - inertia.transpose()).amax();
        if asym > 1e-12 * inertia.amax().max(1.0) {
            return Err(Error::invalid(
                "inertia",
                format!("{inertia:?}"),
                "a symmetric tensor",
            ));
        }
        let smallest = inertia.symmetric_eigenvalues().min();
        if inertia.cholesky().is_some() && smallest < MIN_PRINCIPAL_INERTIA {
            return Err(Error::invalid(
                "inertia",
                format!("{:?}", inertia.symmetric_eigenvalues().as_slice()),
                format!("principal moments of at least {MIN_PRINCIPAL_INERTIA:e} mg mm^2"),
            ));
        }
        if inertia.cholesky().is_none() {
            return Err(Error::invalid(
                "inertia",
                format!("{:?}", inertia.symmetric_eigenvalues().as_slice()),
                "positive definite (all eigenvalues > 0)",
            ));
        }
        Ok(Self {
            shoulder,
            inertia,
            springs,
            aero,
            tunable_hinge: None,
        })
    }

    /// A wing whose only inertia is `ixx` about the stroke axis plus small `iyy = izz` so the
    /// tensor is positive definite; convenient for fixed-wing studies.
    pub fn stroke_only(shoulder: SphericalShoulder, ixx: f64, aero: WingAero) -> Result<Self> {
        let ixx = paritysim_error::check_positive("ixx", ixx)?;
        Self::new(
            shoulder,
            Matrix3::from_diagonal(&Vector3::new(ixx, ixx, ixx)),
            [JointSpring::default(); 6],
            aero,
        )
    }

    /// Adds the tunable hinge of §2.5.1 (in addition to any joint-6 spring).
    pub fn with_tunable_hinge(mut self, hinge: TunableHinge) -> Self {
        self.tunable_hinge = Some(hinge);
        self
    }

    /// The tunable hinge, if any.
    pub fn tunable_hinge(&self) -> Option<&TunableHinge> {
        self.tunable_hinge.as_ref()
    }

    /// Shoulder.
    pub fn shoulder(&self) -> &SphericalShoulder {
        &self.shoulder
    }

    /// Inertia tensor (frame 6).
    pub fn inertia(&self) -> &Matrix3<f64> {
        &self.inertia
    }

    /// Joint springs `γ1..γ6`.
    pub fn springs(&self) -> &[JointSpring; 6] {
        &self.springs
    }

    /// Aerodynamic model.
    pub fn aero(&self) -> &WingAero {
        &self.aero
    }

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
        let on_axis = !matches!(self.aero, WingAero::BladeElement(_));
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

    /// Adds the tunable hinge's load (§3.4: stiffness `k(θ)` on ψ, and its `∂/∂θ` on θ) and
    /// energy to the joint springs' (one place for the general, free-deviation and
    /// stroke-plane terms).
    #[inline(always)]
    fn add_tunable_hinge(
        &self,
        theta: f64,
        psi: f64,
        spring: &mut Vector3<f64>,
        potential: &mut f64,
    ) {
        if let Some(h) = &self.tunable_hinge {
            let k = h.stiffness(theta);
            spring.z += k * psi;
            spring.y += 0.5 * (h.k1 + 2.0 * h.k2 * theta) * psi * psi;
            *potential += 0.5 * k * psi * psi;
        }
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

    /// Whether [`Self::free_deviation_terms`] applies to this wing (α2 = 90°, α3 = 0, no
    /// springs on joints 2, 3, 5).
    pub fn has_closed_form_free_deviation(&self) -> bool {
        self.has_closed_form_stroke_plane() && self.shoulder.alpha3() == 0.0
    }

    /// Whether [`Self::stroke_plane_terms`] applies to this wing (α2 = 90°, no springs on
    /// joints 2, 3, 5).
    pub fn has_closed_form_stroke_plane(&self) -> bool {
        (self.shoulder.alpha2() - std::f64::consts::FRAC_PI_2).abs() <= 1e-15
            && [1, 2, 4]
                .iter()
                .all(|&j| self.springs[j] == JointSpring::default())
    }

    /// Mass matrix, Coriolis, spring and aero terms at `(p, ṗ)`.
    ///
    /// # Errors
    /// [`Error::OutOfDomain`] outside the shoulder's joint limit, [`Error::Singular`] at a
    /// singular shoulder pose.
    pub fn terms(&self, p: &Vector3<f64>, p_dot: &Vector3<f64>) -> Result<WingTerms> {
        self.terms_on(p, p_dot, None)
    }

    /// [`Self::terms`] with the blade element on `branch` when given (event location).
    ///
    /// # Errors
    /// As [`Self::terms`].
    pub(crate) fn terms_on(
        &self,
        p: &Vector3<f64>,
        p_dot: &Vector3<f64>,
        branch: Option<Branch>,
    ) -> Result<WingTerms> {
        let (phi, theta, psi) = (p.x, p.y, p.z);
        let pose = self.shoulder.pose(phi, theta, psi)?;
        let [_, g2, g3, _, g5, _] = pose.joint_angles;
        let d = self.shoulder.partials_at(phi, theta, g2, g5)?;
        let j6 = self.shoulder.jacobian(&pose, &d);
        let r61 = pose.link_rotations[5];
        let omega = j6 * p_dot;

        // J̇6 ṗ from link angular velocities, in ground frame then rotated to frame 6.
        let rates = Vector2::new(p_dot.x, p_dot.y);
        let g5_dot = d.gamma5.dot(&rates);
        let y3 = pose.link_rotations[2] * Vector3::y();
        let z4 = pose.link_rotations[3] * Vector3::z();
        let omega4 = Vector3::x() * p_dot.x + y3 * g5_dot;
        let accel_ground = y3 * rates.dot(&(d.gamma5_hessian * rates))
            + Vector3::x().cross(&y3) * (g5_dot * p_dot.x)
            + omega4.cross(&z4) * p_dot.z;
        let jdot_pdot = r61.transpose() * accel_ground;

        let i_omega = self.inertia * omega;
        let mass = j6.transpose() * self.inertia * j6;
        let coriolis = j6.transpose() * (self.inertia * jdot_pdot + omega.cross(&i_omega));

        // A.6: Σ_j V_j'(γ_j) ∇γ_j.
        let s = &self.springs;
        let gammas = [phi, g2, g3, theta, g5, psi];
        let grads = [
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(d.gamma2[0], d.gamma2[1], 0.0),
            Vector3::new(d.gamma3[0], d.gamma3[1], 0.0),
            Vector3::new(0.0, 1.0, 0.0),
            Vector3::new(d.gamma5[0], d.gamma5[1], 0.0),
            Vector3::new(0.0, 0.0, 1.0),
        ];
        let mut spring = Vector3::zeros();
        let mut potential = 0.0;
        for j in 0..6 {
            spring += grads[j] * s[j].torque(gammas[j]);
            potential += s[j].energy(gammas[j]);
        }

        self.add_tunable_hinge(theta, psi, &mut spring, &mut potential);

        let aero_frame6 = self.aero.torque(p_dot, &omega, &r61, branch);
        Ok(WingTerms {
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
}
