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
use paritysim_aero::Branch;
use paritysim_error::{Error, Result};
use paritysim_kinematics::SphericalShoulder;

mod free_deviation;
mod record;
mod springs;
mod stroke_plane;

pub use paritysim_aero::WingAero;
pub use record::WingTermsRecord;
pub use springs::{JointSpring, TunableHinge};

/// Largest |entry| of a wing's inertia tensor (mg·mm²): the spec's documented range; a larger
/// one is not an insect-scale wing and overflows the mass matrix into NaN (issue 14).
pub const MAX_INERTIA_ENTRY: f64 = 1e5;

/// Smallest principal moment of a wing's inertia (mg·mm²): a million times below the thesis
/// wings' smallest (about 1); a vanishing one makes the mass matrix numerically singular and
/// the first step NaN or an underflow (issue 14).
pub const MIN_PRINCIPAL_INERTIA: f64 = 1e-6;

/// A wing: shoulder, inertia about the spherical centre (frame 6), six joint springs, aero.
#[derive(Clone, Debug, PartialEq)]
pub struct Wing {
    shoulder: SphericalShoulder,
    inertia: Matrix3<f64>,
    springs: [JointSpring; 6],
    aero: WingAero,
    tunable_hinge: Option<TunableHinge>,
    /// Viscous damping of the wing hinge `bψ` (mN·mm·ms/rad): a torque `−bψ ψ̇` on ψ.
    hinge_damping: f64,
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

impl Wing {
    /// A wing with a full inertia tensor (mg·mm², frame 6, about the spherical centre); an
    /// aero law with added mass adds its [`WingAero::added_inertia`] to it.
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
            // The law's added mass is inertia (Whitney & Wood 2010, crates/aero/src/whitney_wood.rs).
            inertia: inertia + aero.added_inertia(),
            springs,
            aero,
            tunable_hinge: None,
            hinge_damping: 0.0,
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

    /// With viscous damping `bψ` (mN·mm·ms/rad) of the wing hinge: a torque `−bψ ψ̇` on ψ
    /// (0 by default). The general and stroke-plane forms and free flight take it; the
    /// free-deviation form declines such a wing's device.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `damping` when negative or not finite.
    pub fn with_hinge_damping(mut self, damping: f64) -> Result<Self> {
        self.hinge_damping = paritysim_error::check_non_negative("damping", damping)?;
        Ok(self)
    }

    /// The hinge's viscous damping `bψ` (mN·mm·ms/rad).
    #[inline]
    pub fn hinge_damping(&self) -> f64 {
        self.hinge_damping
    }

    /// The tunable hinge, if any.
    pub fn tunable_hinge(&self) -> Option<&TunableHinge> {
        self.tunable_hinge.as_ref()
    }

    /// Shoulder.
    pub fn shoulder(&self) -> &SphericalShoulder {
        &self.shoulder
    }

    /// Inertia tensor (frame 6): the structural one given to [`Self::new`] plus the aero law's
    /// added inertia ([`WingAero::added_inertia`]), the one every form integrates.
    pub fn inertia(&self) -> &Matrix3<f64> {
        &self.inertia
    }

    /// The structural inertia given to [`Self::new`] (without the aero law's added inertia).
    pub fn structural_inertia(&self) -> Matrix3<f64> {
        self.inertia - self.aero.added_inertia()
    }

    /// Joint springs `γ1..γ6`.
    pub fn springs(&self) -> &[JointSpring; 6] {
        &self.springs
    }

    /// Aerodynamic model.
    pub fn aero(&self) -> &WingAero {
        &self.aero
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
