//! Quasi-steady blade-element model of §3.2.4: wind-relative state (eq. 3.4) and the moments
//! `M_N, M_T, M_rd, M_r` (eqs. 3.8–3.11), plus lift/drag forces and body-axis torques.
//!
//! # Frames
//! The wing angles `(φ, θ, ψ)` are the wing's intrinsic x-y-z Euler angles (stroke, deviation,
//! rotation: `φ_w, θ_w, ψ_w` of §3.2.3), so the wing frame 6 is
//! `R_6^1 = R_x(φ) R_y(θ) R_z(ψ)` (eqs. 2.2–2.5 with `γ5 = θ_w`; for the (α2, α3) = (90°, 0°)
//! shoulder `θ_w ≈ θ` near mid-stroke, docs/errata.md#6). The ground/body frame 1 is the shoulder
//! ground. In the wing frame: `x̂` chordwise toward the leading edge, `ẑ` spanwise along the
//! hinge, `ŷ = ẑ × x̂` the wing normal. The wing's angular velocity in the wing frame is
//!
//! ```text
//! ω = R_z(ψ)ᵀ (φ̇ cos θ, θ̇, φ̇ sin θ) + (0, 0, ψ̇)
//!   = (φ̇ cos θ cos ψ + θ̇ sin ψ,  −φ̇ cos θ sin ψ + θ̇ cos ψ,  φ̇ sin θ + ψ̇).
//! ```
//!
//! A blade element at span `z` moves with `z ω × ẑ = z (ω_y, −ω_x, 0)`: everything
//! translational depends on `(ω_x, ω_y)` only, and the model can be evaluated from `ω` alone
//! ([`BladeElementModel::moments_omega`]; `ω = J6 ṗ` with the Jacobian of eq. A.9).
//!
//! # Wind-relative coordinates and α (eq. 3.4, docs/errata.md#5)
//! In the hinge frame the element velocity is `z (θ̇, −φ̇ cos θ, 0)`. Write it as
//! `−z φ̇_rw (−sin δ, cos δ, 0)`: `φ̇_rw = sgn(φ̇ cos θ) √((φ̇ cos θ)² + θ̇²)` is the
//! **wind-relative stroke velocity** and `δ = atan(θ̇ / (φ̇ cos θ))` the tilt of the relative
//! wind; `ψ_rw = ψ − δ` (wrapped to (−π, π]) is the **wind-relative rotation**, zero with the
//! wing perpendicular to the relative wind; `ψ̇_rw = ω_z = ψ̇ + φ̇ sin θ` is the spanwise
//! rotation rate used by the rotational damping. With `θ = θ̇ = 0` these are `φ̇_rw = φ̇`,
//! `ψ_rw = ψ`, `ψ̇_rw = ψ̇`.
//!
//! **One sign convention.** With the frames of eqs. 2.2–2.4 and the leading edge at `+x`, a
//! positive `ψ` at positive stroke velocity tilts the leading edge *backwards*. We define α as
//! the geometric angle between the chord (toward the leading edge) and the velocity, which gives
//!
//! ```text
//! α = π/2 + ψ_rw sgn(φ̇_rw)        (|ψ_rw| <= π/2; in general α = acos(−sgn(φ̇_rw) sin ψ_rw))
//! ```
//!
//! i.e. eq. 3.4 with the sign of `ψ_rw` flipped (docs/errata.md#5). The leading edge leads when
//! `ψ` has the opposite sign of `φ̇`: passive rotation makes `ψ` lag `φ` by ~90° and gives
//! `α = 90° − |ψ|` (α ≈ 30° mid-stroke at |ψ| = 60°, α = 90° at stroke reversal).
//!
//! # Moments (torque vector in the wing frame, mN·mm)
//! With `W² = ω_x² + ω_y² = φ̇_rw²`, `σ = sgn(ω_x)` (= `sgn φ̇_rw` while `|ψ_rw| < π/2`) and
//! the centre of pressure `x_cp(z) = l(z) − d̂_cp c(z)`, integrating `r × dF` over the strips:
//!
//! ```text
//! M_N  = −Ω1 σ W² C_N(α)                       about x̂   (eq. 3.8)
//! M_T  = −Ω1 W² C_T(α)                          about ŷ   (eq. 3.9, see below)
//! M_r  = −(Ω3 d̂_cp(α) − Ω4) σ W² C_N(α)         about ẑ   (eq. 3.11)
//! M_rd = −Ω2 C_rd ω_z |ω_z|                      about ẑ   (eq. 3.10)
//! ```
//!
//! `C_T` is referred to the chord (positive toward the trailing edge, [`crate::coefficients`]);
//! with that definition the derivation gives no `sgn(φ̇_rw)` in `M_T`: a chordwise drag pushes
//! toward the trailing edge on both half-strokes, so its moment about the wing normal keeps its
//! sign in the wing frame. The printed eq. 3.9 carries `sgn(φ̇_rw)`, which is only consistent
//! with a `C_T` signed by the stroke direction. Not yet an item of docs/errata.md; flagged in the tests.
//!
//! Power checks (tested): `(M_N, M_T)·(ω_x, ω_y) = −Ω1 |W|³ C_D(α) <= 0` and
//! `M_rd ω_z = −Ω2 C_rd |ω_z|³ <= 0`. All four moments are odd in `ω`.
//!
//! docs/errata.md#12 (drag torque `Ω φ̇²` of eq. 2.16 vs `Ω C_N φ̇²` of eq. 3.8) is exposed as
//! [`NormalForceLaw`].

use std::f64::consts::{FRAC_PI_2, PI};

use nalgebra::{Matrix3, Vector3};
use paritysim_error::{Error, Result, bail, check_finite, check_non_negative};

mod held;
pub use held::HeldBranch;

use crate::coefficients::{
    CoefficientModel, CoefficientSet, DEFAULT_ROTATIONAL_DAMPING, center_of_pressure,
    from_normal_tangential,
};

/// The aerodynamic wing parameters of eqs. 3.12–3.15 (mg·mm²) and the force parameter.
///
/// Build from a planform with [`crate::Planform::omegas`], or from published numbers (e.g.
/// Table 3.3) with [`Omegas::new`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Omegas {
    /// Ω1 = ½ρ∬z³dA (eq. 3.12): stroke moments `M_N`, `M_T`.
    pub omega1: f64,
    /// Ω2 = ½ρ∬|x|³dA (eq. 3.13): rotational damping `M_rd`.
    pub omega2: f64,
    /// Ω3 = ½ρ∫z²c²dz (eq. 3.14): centre-of-pressure part of `M_r`.
    pub omega3: f64,
    /// Ω4 = ½ρ∫z²lc dz (eq. 3.15): leading-edge offset part of `M_r`.
    pub omega4: f64,
    /// `½ρ∬z²dA` (mg·mm): lift and drag *forces* are this times `W² C_L`, `W² C_D`. `None` when
    /// only the moments are known (Table 3.3); [`BladeElementModel::loads`] then fails.
    pub force: Option<f64>,
}

impl Omegas {
    /// Published Ω1..Ω4 without a planform (no force parameter).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless `omega1 > 0`, `omega2 >= 0`, `omega3 >= 0` and
    /// `omega4` is finite.
    pub fn new(omega1: f64, omega2: f64, omega3: f64, omega4: f64) -> Result<Self> {
        let o = Self {
            omega1,
            omega2,
            omega3,
            omega4,
            force: None,
        };
        o.validate()?;
        Ok(o)
    }

    /// Adds the force parameter `½ρ∬z²dA` (mg·mm).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`force`) unless finite and >= 0.
    pub fn with_force(mut self, force: f64) -> Result<Self> {
        check_non_negative("force", force)?;
        self.force = Some(force);
        Ok(self)
    }

    /// Checks the ranges listed in [`Self::new`] (and `force >= 0` when present).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `omegas.omegaK` or `omegas.force`.
    pub fn validate(&self) -> Result<()> {
        let r = (|| -> Result<()> {
            paritysim_error::check_positive("omega1", self.omega1)?;
            check_non_negative("omega2", self.omega2)?;
            check_non_negative("omega3", self.omega3)?;
            check_finite("omega4", self.omega4)?;
            if let Some(f) = self.force {
                check_non_negative("force", f)?;
            }
            Ok(())
        })();
        r.map_err(|e| e.in_field("omegas"))
    }
}

/// Which coefficient multiplies `Ω1 φ̇_rw²` in the normal moment (docs/errata.md#12).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NormalForceLaw {
    /// `M_N = −Ω1 sgn(φ̇_rw) φ̇_rw² C_N(α)`, eqs. 3.8–3.11 as printed (default).
    #[default]
    Coefficient,
    /// `M_N = −Ω1 sgn(φ̇_rw) φ̇_rw²` (eq. 2.16, the "drag parameter" Ω of §2.6 and §3.3 with
    /// the coefficient absorbed): `C_N ≡ 1`, `C_T ≡ 0` everywhere (so `C_L = cos α`,
    /// `C_D = sin α` in [`BladeElementModel::loads`]).
    Unit,
}

impl NormalForceLaw {
    /// The name [`NormalForceLaw::from_name`] reads.
    pub fn name(self) -> &'static str {
        match self {
            NormalForceLaw::Coefficient => "coefficient",
            NormalForceLaw::Unit => "unit",
        }
    }

    /// By name: `coefficient` or `unit`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (field `normal_force_law`) for another name.
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "coefficient" => Ok(NormalForceLaw::Coefficient),
            "unit" => Ok(NormalForceLaw::Unit),
            other => Err(Error::invalid(
                "normal_force_law",
                format!("{other:?}"),
                "one of \"coefficient\", \"unit\"",
            )),
        }
    }
}

/// Wing angles (rad) and rates (rad/ms): stroke `φ`, deviation `θ` (= `θ_w`), rotation `ψ`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WingState {
    /// Stroke angle φ (rad).
    pub phi: f64,
    /// Deviation angle θ_w (rad).
    pub theta: f64,
    /// Rotation angle ψ (rad).
    pub psi: f64,
    /// φ̇ (rad/ms).
    pub phi_dot: f64,
    /// θ̇_w (rad/ms).
    pub theta_dot: f64,
    /// ψ̇ (rad/ms).
    pub psi_dot: f64,
}

/// Wind-relative coordinates of §3.2.4 (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WindRelative {
    /// φ̇_rw (rad/ms), signed like `φ̇ cos θ` (like `θ̇` when that is 0).
    pub phi_dot_rw: f64,
    /// ψ_rw (rad) in (−π, π]: rotation from the attitude perpendicular to the relative wind.
    pub psi_rw: f64,
    /// ψ̇_rw = ω_z = ψ̇ + φ̇ sin θ (rad/ms).
    pub psi_dot_rw: f64,
    /// Angle of attack α ∈ [0, π] (rad); π/2 by convention when the wing does not translate.
    pub alpha: f64,
}

#[inline]
fn wrap_pi(a: f64) -> f64 {
    if a > -PI && a <= PI {
        return a;
    }
    let r = a.rem_euclid(2.0 * PI);
    if r > PI { r - 2.0 * PI } else { r }
}

impl WingState {
    /// A validated state.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first non-finite field.
    pub fn new(
        phi: f64,
        theta: f64,
        psi: f64,
        phi_dot: f64,
        theta_dot: f64,
        psi_dot: f64,
    ) -> Result<Self> {
        check_finite("phi", phi)?;
        check_finite("theta", theta)?;
        check_finite("psi", psi)?;
        check_finite("phi_dot", phi_dot)?;
        check_finite("theta_dot", theta_dot)?;
        check_finite("psi_dot", psi_dot)?;
        Ok(Self {
            phi,
            theta,
            psi,
            phi_dot,
            theta_dot,
            psi_dot,
        })
    }

    /// A state without deviation (`θ = θ̇ = 0`).
    ///
    /// # Errors
    /// As [`Self::new`].
    pub fn planar(phi: f64, psi: f64, phi_dot: f64, psi_dot: f64) -> Result<Self> {
        Self::new(phi, 0.0, psi, phi_dot, 0.0, psi_dot)
    }

    /// Angular velocity of the wing in the wing frame (rad/ms), see the module docs.
    #[inline]
    pub fn angular_velocity(&self) -> Vector3<f64> {
        let (st, ct) = self.theta.sin_cos();
        let (sp, cp) = self.psi.sin_cos();
        let a = self.phi_dot * ct;
        Vector3::new(
            a * cp + self.theta_dot * sp,
            -a * sp + self.theta_dot * cp,
            self.phi_dot * st + self.psi_dot,
        )
    }

    /// `R_6^1 = R_x(φ) R_y(θ) R_z(ψ)`: wing-frame vectors to the body (shoulder ground) frame.
    pub fn rotation(&self) -> Matrix3<f64> {
        let (sf, cf) = self.phi.sin_cos();
        let (st, ct) = self.theta.sin_cos();
        let (sp, cp) = self.psi.sin_cos();
        let rx = Matrix3::new(1.0, 0.0, 0.0, 0.0, cf, -sf, 0.0, sf, cf);
        let ry = Matrix3::new(ct, 0.0, st, 0.0, 1.0, 0.0, -st, 0.0, ct);
        let rz = Matrix3::new(cp, -sp, 0.0, sp, cp, 0.0, 0.0, 0.0, 1.0);
        rx * ry * rz
    }

    /// The wind-relative coordinates `(φ̇_rw, ψ_rw, ψ̇_rw, α)`.
    pub fn wind_relative(&self) -> WindRelative {
        let s = self.phi_dot * self.theta.cos();
        let d = self.theta_dot;
        let w = s.hypot(d);
        let sign = if s >= 0.0 { 1.0 } else { -1.0 };
        let delta = if w > 0.0 {
            (sign * d).atan2(s.abs())
        } else {
            0.0
        };
        let omega = self.angular_velocity();
        WindRelative {
            phi_dot_rw: sign * w,
            psi_rw: wrap_pi(self.psi - delta),
            psi_dot_rw: omega.z,
            alpha: alpha_from_omega(&omega),
        }
    }
}

/// `sgn` with `sgn(0) = 0`: a wing moving exactly edgewise (`ω_x = 0`, α = 0 or π) has no
/// normal velocity and gets no normal force, even where a fit has `C_N(0) = C_L(0) ≠ 0`.
#[inline]
fn sign(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// α ∈ [0, π] from the wing-frame angular velocity (π/2 when `ω_x = ω_y = 0`).
#[inline]
fn alpha_from_omega(omega: &Vector3<f64>) -> f64 {
    if omega.x == 0.0 && omega.y == 0.0 {
        FRAC_PI_2
    } else {
        omega.x.abs().atan2(omega.y)
    }
}

/// The smooth branch of the blade-element model on one side of each of its three switching
/// surfaces, in the wing-frame angular velocity `ω`: the stroke reversal `ω_x = 0` (where
/// `σ = sgn ω_x` flips: `M_N` jumps by `2 Ω1 W² C_N(0)`, α has a kink), `ω_y = 0` (α = π/2,
/// where a fit extended by symmetry jumps, [`CoefficientModel::jumps_at_right_angle`]) and
/// `ω_z = 0` (the rotational damping `ω_z |ω_z|`). On its own side a branch gives the model's
/// values; past a surface it continues them analytically (σ held, α continued through 0 and π,
/// `ω_z |ω_z| → ±ω_z²`), which is what an integrator with event location evaluates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Branch {
    /// `ω_x >= 0`: σ = +1.
    pub chordwise_positive: bool,
    /// `ω_y >= 0`: the α <= π/2 branch of the coefficients.
    pub normal_positive: bool,
    /// `ω_z >= 0`.
    pub spanwise_positive: bool,
}

impl Branch {
    /// The branch `ω` lies on.
    #[inline]
    pub fn of(omega: &Vector3<f64>) -> Self {
        Self {
            chordwise_positive: omega.x >= 0.0,
            normal_positive: omega.y >= 0.0,
            spanwise_positive: omega.z >= 0.0,
        }
    }
}

/// α on a branch of σ: `atan2(σ ω_x, ω_y)` continued through 0 (negative) and π (past π).
#[inline]
fn branch_alpha(sigma_wx: f64, wy: f64) -> f64 {
    let a = sigma_wx.atan2(wy);
    if a < -FRAC_PI_2 { a + 2.0 * PI } else { a }
}

#[inline]
fn unit_sign(positive: bool) -> f64 {
    if positive { 1.0 } else { -1.0 }
}

/// The four moments of eqs. 3.8–3.11 (mN·mm) at one state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AeroMoments {
    /// `M_N`, about the wing's chordwise axis `x̂` (eq. 3.8).
    pub normal: f64,
    /// `M_T`, about the wing normal `ŷ` (eq. 3.9).
    pub tangential: f64,
    /// `M_r`, about the hinge `ẑ` (eq. 3.11).
    pub rotational: f64,
    /// `M_rd`, about the hinge `ẑ` (eq. 3.10).
    pub rotational_damping: f64,
    /// The angle of attack used (rad).
    pub alpha: f64,
}

impl AeroMoments {
    /// Eqs. 3.8, 3.9 and 3.11 from the chordwise sign `σ`, `W² = ω_x² + ω_y²`, `(C_N, C_T)`
    /// and the centre of pressure `d_cp` (eq. 3.7): the one assembly of every path.
    #[inline]
    fn of_strip(
        o: &Omegas,
        sigma: f64,
        w2: f64,
        (cn, ct): (f64, f64),
        d_cp: f64,
        rotational_damping: f64,
        alpha: f64,
    ) -> Self {
        Self {
            normal: -o.omega1 * sigma * w2 * cn, // eq. 3.8
            tangential: -o.omega1 * w2 * ct,     // eq. 3.9
            rotational: -(o.omega3 * d_cp - o.omega4) * sigma * w2 * cn, // eq. 3.11
            rotational_damping,
            alpha,
        }
    }

    /// Torque vector in the wing frame: `(M_N, M_T, M_r + M_rd)`.
    #[inline]
    pub fn torque(&self) -> Vector3<f64> {
        Vector3::new(
            self.normal,
            self.tangential,
            self.rotational + self.rotational_damping,
        )
    }
}

/// Lift and drag forces and torques about the spherical centre, in the body frame.
///
/// Body axes (Fig. 2.10, as the text describes them): **roll** is the stroke axis `x̂₁` (the
/// drag torque is always roll-aligned, §2.5.1), **yaw** is `ŷ₁`, the deviation axis at
/// mid-stroke about which lift acts, **pitch** is `ẑ₁`, the spanwise axis through the wing
/// roots at `φ = θ = 0`. Vectors are `[roll, yaw, pitch]` components.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AeroLoads {
    /// Lift force (mN).
    pub lift: Vector3<f64>,
    /// Drag force (mN).
    pub drag: Vector3<f64>,
    /// Torque of the lift about the spherical centre (mN·mm).
    pub lift_torque: Vector3<f64>,
    /// Torque of the drag about the spherical centre (mN·mm).
    pub drag_torque: Vector3<f64>,
    /// Rotational damping torque `M_rd ẑ₆` (mN·mm); its net force is neglected.
    pub damping_torque: Vector3<f64>,
    /// The wing-frame moments at the same state.
    pub moments: AeroMoments,
}

impl AeroLoads {
    /// Total aerodynamic torque on the wing in the body frame (mN·mm); equals
    /// `R_6^1 · moments.torque()`.
    pub fn torque(&self) -> Vector3<f64> {
        self.lift_torque + self.drag_torque + self.damping_torque
    }

    /// Roll component of [`Self::torque`] (mN·mm).
    pub fn roll(&self) -> f64 {
        self.torque().x
    }

    /// Yaw component of [`Self::torque`] (mN·mm).
    pub fn yaw(&self) -> f64 {
        self.torque().y
    }

    /// Pitch component of [`Self::torque`] (mN·mm).
    pub fn pitch(&self) -> f64 {
        self.torque().z
    }
}

/// A wing's quasi-steady aerodynamics: Ω1..Ω4, a coefficient model, `C_rd` and the
/// [`NormalForceLaw`]. Immutable, `Send + Sync`; [`Self::moments`] allocates nothing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BladeElementModel<C: CoefficientModel = CoefficientSet> {
    omegas: Omegas,
    coefficients: C,
    rotational_damping: f64,
    law: NormalForceLaw,
}

impl<C: CoefficientModel> BladeElementModel<C> {
    /// A model with `C_rd = `[`DEFAULT_ROTATIONAL_DAMPING`] and [`NormalForceLaw::Coefficient`].
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for out-of-range [`Omegas`] (see [`Omegas::validate`]).
    pub fn new(omegas: Omegas, coefficients: C) -> Result<Self> {
        omegas.validate()?;
        Ok(Self {
            omegas,
            coefficients,
            rotational_damping: DEFAULT_ROTATIONAL_DAMPING,
            law: NormalForceLaw::Coefficient,
        })
    }

    /// Replaces `C_rd` (eq. 3.10).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`rotational_damping`) unless finite and >= 0.
    pub fn with_rotational_damping(mut self, c_rd: f64) -> Result<Self> {
        check_non_negative("rotational_damping", c_rd)?;
        self.rotational_damping = c_rd;
        Ok(self)
    }

    /// Replaces the normal-force law (docs/errata.md#12).
    pub fn with_normal_force_law(mut self, law: NormalForceLaw) -> Self {
        self.law = law;
        self
    }

    /// The parameters.
    pub fn omegas(&self) -> &Omegas {
        &self.omegas
    }

    /// The coefficient model.
    pub fn coefficient_model(&self) -> &C {
        &self.coefficients
    }

    /// `C_rd`.
    pub fn rotational_damping(&self) -> f64 {
        self.rotational_damping
    }

    /// The normal-force law.
    pub fn normal_force_law(&self) -> NormalForceLaw {
        self.law
    }

    /// `(C_N, C_T)` under the configured law.
    #[inline]
    fn normal_tangential(&self, alpha: f64) -> (f64, f64) {
        match self.law {
            NormalForceLaw::Coefficient => {
                let c = self.coefficients.coefficients(alpha);
                (c.normal, c.tangential)
            }
            NormalForceLaw::Unit => (1.0, 0.0),
        }
    }

    /// `(C_N, C_T)` on one side of α = π/2 (see [`Branch`]).
    #[inline]
    fn normal_tangential_branch(&self, alpha: f64, below: bool) -> (f64, f64) {
        match self.law {
            NormalForceLaw::Coefficient => {
                let (cl, cd) = self.coefficients.lift_drag_branch(alpha, below);
                crate::coefficients::to_normal_tangential(alpha, cl, cd)
            }
            NormalForceLaw::Unit => (1.0, 0.0),
        }
    }

    /// The model's three switching functions at `ω` (see [`Branch`]): `(ω_x, ω_y, ω_z)`, with
    /// `1` in place of a surface where this model is smooth (`ω_y` unless the coefficients
    /// jump at 90°, `ω_z` without rotational damping).
    #[inline]
    pub fn switching_functions(&self, omega: &Vector3<f64>) -> [f64; 3] {
        let right_angle =
            self.law == NormalForceLaw::Coefficient && self.coefficients.jumps_at_right_angle();
        let damped = self.omegas.omega2 * self.rotational_damping != 0.0;
        [
            omega.x,
            if right_angle { omega.y } else { 1.0 },
            if damped { omega.z } else { 1.0 },
        ]
    }

    /// [`Self::moments_omega`] on a [`Branch`] (its values on the branch's own side).
    #[inline]
    pub fn moments_omega_branch(&self, omega: &Vector3<f64>, branch: Branch) -> AeroMoments {
        let o = &self.omegas;
        let (wx, wy, wz) = (omega.x, omega.y, omega.z);
        let w2 = wx * wx + wy * wy;
        let sz = unit_sign(branch.spanwise_positive);
        let rotational_damping = -o.omega2 * self.rotational_damping * sz * wz * wz; // eq. 3.10
        if w2 == 0.0 {
            return AeroMoments {
                rotational_damping,
                alpha: FRAC_PI_2,
                ..AeroMoments::default()
            };
        }
        let sigma = unit_sign(branch.chordwise_positive);
        let alpha = branch_alpha(sigma * wx, wy);
        let (cn, ct) = self.normal_tangential_branch(alpha, branch.normal_positive);
        let d_cp = 0.82 / PI * alpha + 0.05; // eq. 3.7, |α| = α on the branch's own side
        AeroMoments::of_strip(o, sigma, w2, (cn, ct), d_cp, rotational_damping, alpha)
    }

    /// [`Self::moments_omega`] (`branch` None) or [`Self::moments_omega_branch`] of a wing on
    /// its stroke plane (deviation θ ≡ 0): `ω = φ̇ (cos ψ, −sin ψ, 0) + ψ̇ ẑ`, so that
    /// `W² = φ̇²`, `α = π/2 + σ ψ`, `sin α = cos ψ` and `cos α = −σ sin ψ` (for |ψ| < π/2,
    /// `cos ψ > 0`): no `atan2` and no `sin_cos(α)`. `(sin ψ, cos ψ)` are the caller's. On a
    /// branch, σ is held and α continues in ψ (analytic in the state; the moments carry `W²`,
    /// which vanishes at the stroke reversal).
    #[inline]
    pub fn moments_stroke_plane(
        &self,
        phi_dot: f64,
        psi: f64,
        (sin_psi, cos_psi): (f64, f64),
        psi_dot: f64,
        branch: Option<Branch>,
    ) -> AeroMoments {
        let o = &self.omegas;
        let (wx, wy, wz) = (cos_psi * phi_dot, -sin_psi * phi_dot, psi_dot);
        let w2 = wx * wx + wy * wy;
        let damping = match branch {
            None => wz * wz.abs(),
            Some(b) => unit_sign(b.spanwise_positive) * wz * wz,
        };
        let rotational_damping = -o.omega2 * self.rotational_damping * damping; // eq. 3.10
        if w2 == 0.0 {
            return AeroMoments {
                rotational_damping,
                alpha: FRAC_PI_2,
                ..AeroMoments::default()
            };
        }
        let sigma = match branch {
            None => sign(wx),
            Some(b) => unit_sign(b.chordwise_positive),
        };
        let alpha = FRAC_PI_2 + sigma * psi;
        let below = match branch {
            None => alpha <= FRAC_PI_2,
            Some(b) => b.normal_positive,
        };
        let (cn, ct) = match self.law {
            NormalForceLaw::Coefficient => {
                let (cl, cd) = self.coefficients.lift_drag_branch(alpha, below);
                let (sin_a, cos_a) = (cos_psi, -sigma * sin_psi);
                (cl * cos_a + cd * sin_a, cd * cos_a - cl * sin_a)
            }
            NormalForceLaw::Unit => (1.0, 0.0),
        };
        let d_cp = 0.82 / PI * alpha + 0.05; // eq. 3.7 (α in (0, π))
        AeroMoments::of_strip(o, sigma, w2, (cn, ct), d_cp, rotational_damping, alpha)
    }

    /// The torque `(M_N, M_T, M_r + M_rd)` a stroke-plane device's right-hand side takes from
    /// this model (θ ≡ 0, `ω = φ̇ (cos ψ, −sin ψ, 0) + ψ̇ ẑ`: [`Self::moments_stroke_plane`]
    /// for `cos ψ > 0` on the branch's own side, else [`Self::moments_omega_branch`]) and its
    /// partial derivatives by `φ̇`, `ψ` and `ψ̇` (the three vectors), in closed form on the
    /// branch (σ, the side of α = π/2 and `sgn ω_z` held, as the right-hand side holds them
    /// between switches): `W² = φ̇²`, `∂α/∂ψ = σ` on either form (`α = atan2(σ ω_x, ω_y)`
    /// is homogeneous in φ̇), `(C_N, C_T)` the rotation of `(C_L, C_D)` by α, so
    /// `dC_N/dα = C_L' cos α + C_D' sin α + C_T`, `dC_T/dα = C_D' cos α − C_L' sin α − C_N`
    /// (eqs. 3.5–3.11). For the variational equations. `None` for `cos ψ <= 0` without a
    /// branch (the right-hand side's `atan2(|ω_x|, ω_y)` form, not differentiated here).
    #[inline]
    pub fn moments_stroke_plane_jacobian(
        &self,
        phi_dot: f64,
        psi: f64,
        (sin_psi, cos_psi): (f64, f64),
        psi_dot: f64,
        branch: Option<Branch>,
    ) -> Option<(Vector3<f64>, [Vector3<f64>; 3])> {
        let o = &self.omegas;
        let (wx, wy, wz) = (cos_psi * phi_dot, -sin_psi * phi_dot, psi_dot);
        let w2 = wx * wx + wy * wy;
        let (damping, damping_slope) = match branch {
            None => (wz * wz.abs(), 2.0 * wz.abs()),
            Some(b) => {
                let sz = unit_sign(b.spanwise_positive);
                (sz * wz * wz, 2.0 * sz * wz)
            }
        };
        let k_rd = -o.omega2 * self.rotational_damping; // eq. 3.10
        let d_psi_dot = Vector3::new(0.0, 0.0, k_rd * damping_slope);
        if w2 == 0.0 {
            // Every strip moment carries W² = φ̇², whose derivatives vanish with φ̇.
            let torque = Vector3::new(0.0, 0.0, k_rd * damping);
            return Some((torque, [Vector3::zeros(), Vector3::zeros(), d_psi_dot]));
        }
        let own_side = branch.is_none_or(|b| {
            b.chordwise_positive == (wx >= 0.0) && b.normal_positive == (wy >= 0.0)
        });
        let (sigma, alpha, (sin_a, cos_a), below) = match branch {
            None if cos_psi <= 0.0 => return None,
            None => {
                let sigma = sign(wx);
                let alpha = FRAC_PI_2 + sigma * psi;
                (
                    sigma,
                    alpha,
                    (cos_psi, -sigma * sin_psi),
                    alpha <= FRAC_PI_2,
                )
            }
            Some(b) => {
                let sigma = unit_sign(b.chordwise_positive);
                if cos_psi > 0.0 && own_side {
                    let alpha = FRAC_PI_2 + sigma * psi;
                    (sigma, alpha, (cos_psi, -sigma * sin_psi), b.normal_positive)
                } else {
                    let alpha = branch_alpha(sigma * wx, wy);
                    (sigma, alpha, alpha.sin_cos(), b.normal_positive)
                }
            }
        };
        let ((cn, ct), (dcn, dct)) = match self.law {
            NormalForceLaw::Coefficient => {
                let ((cl, cd), (dcl, dcd)) = self.coefficients.lift_drag_slope_branch(alpha, below);
                let (cn, ct) = (cl * cos_a + cd * sin_a, cd * cos_a - cl * sin_a);
                // d/dψ = σ d/dα.
                (
                    (cn, ct),
                    (
                        sigma * (dcl * cos_a + dcd * sin_a + ct),
                        sigma * (dcd * cos_a - dcl * sin_a - cn),
                    ),
                )
            }
            NormalForceLaw::Unit => ((1.0, 0.0), (0.0, 0.0)),
        };
        let d_cp = 0.82 / PI * alpha + 0.05; // eq. 3.7 on the branch
        let lever = o.omega3 * d_cp - o.omega4;
        let dw2 = 2.0 * phi_dot;
        let normal = -o.omega1 * sigma; // M_N = normal W² C_N (eq. 3.8)
        let tangential = -o.omega1; // M_T = tangential W² C_T (eq. 3.9)
        let torque = Vector3::new(
            normal * w2 * cn,
            tangential * w2 * ct,
            -lever * sigma * w2 * cn + k_rd * damping, // eqs. 3.11, 3.10
        );
        let d_phi_dot = Vector3::new(
            normal * dw2 * cn,
            tangential * dw2 * ct,
            -lever * sigma * dw2 * cn,
        );
        let d_psi = Vector3::new(
            normal * w2 * dcn,
            tangential * w2 * dct,
            -(o.omega3 * 0.82 / PI) * w2 * cn - lever * sigma * w2 * dcn,
        );
        Some((torque, [d_phi_dot, d_psi, d_psi_dot]))
    }

    /// [`Self::loads_omega`] on a [`Branch`] (its values on the branch's own side).
    ///
    /// # Errors
    /// As [`Self::loads`].
    #[inline]
    pub fn loads_omega_branch(
        &self,
        omega: &Vector3<f64>,
        rot: &Matrix3<f64>,
        branch: Branch,
    ) -> Result<AeroLoads> {
        let moments = self.moments_omega_branch(omega, branch);
        let sigma = unit_sign(branch.chordwise_positive);
        self.loads_from_moments(omega, rot, moments, sigma, |alpha| {
            let (cn, ct) = self.normal_tangential_branch(alpha, branch.normal_positive);
            // eq. 3.7 on the branch (α keeps its sign there).
            (cn, ct, 0.82 / PI * alpha + 0.05)
        })
    }

    /// The loads of [`Self::loads_omega`] / [`Self::loads_omega_branch`] from their moments:
    /// lift along `ℓ̂ = σ (ω_x, ω_y)/W`, drag along `û`, torques about the shoulder from the
    /// z-weighted strip forces; `coefficients(α) = (C_N, C_T, d_cp)`.
    #[inline(always)]
    fn loads_from_moments(
        &self,
        omega: &Vector3<f64>,
        rot: &Matrix3<f64>,
        moments: AeroMoments,
        sigma: f64,
        coefficients: impl Fn(f64) -> (f64, f64, f64),
    ) -> Result<AeroLoads> {
        let Some(force) = self.omegas.force else {
            bail!(invalid "omegas.force", "None",
                "set: build Omegas from a Planform or call Omegas::with_force");
        };
        let rot = *rot;
        let damping_torque = rot * Vector3::new(0.0, 0.0, moments.rotational_damping);
        let (wx, wy) = (omega.x, omega.y);
        let w2 = wx * wx + wy * wy;
        if w2 == 0.0 {
            return Ok(AeroLoads {
                lift: Vector3::zeros(),
                drag: Vector3::zeros(),
                lift_torque: Vector3::zeros(),
                drag_torque: Vector3::zeros(),
                damping_torque,
                moments,
            });
        }
        let w = w2.sqrt();
        let alpha = moments.alpha;
        let (cn, ct, d_cp) = coefficients(alpha);
        let (cl, cd) = from_normal_tangential(alpha, cn, ct);
        let lift_dir = Vector3::new(sigma * wx / w, sigma * wy / w, 0.0); // ℓ̂
        let vel_dir = Vector3::new(wy / w, -wx / w, 0.0); // û
        let o = &self.omegas;
        // Resultant of z-weighted strip forces acting at (x_cp, 0, z): Σ r × dF = W² r_eff × (C ê).
        let r_eff = Vector3::new(o.omega4 - d_cp * o.omega3, 0.0, o.omega1);
        Ok(AeroLoads {
            lift: rot * (lift_dir * (force * w2 * cl)),
            drag: rot * (vel_dir * (-force * w2 * cd)),
            lift_torque: rot * r_eff.cross(&lift_dir) * (w2 * cl),
            drag_torque: rot * r_eff.cross(&vel_dir) * (-w2 * cd),
            damping_torque,
            moments,
        })
    }

    /// The resultant force (mN) and torque about the shoulder (mN·mm) of [`Self::loads_omega_branch`]
    /// in the **wing frame** (`rot` = identity; `lift + drag` and [`AeroLoads::torque`]), lean:
    /// one `atan2` and the fit's two trigonometric calls (`sin α = σ ω_x / W`,
    /// `cos α = ω_y / W` on the branch).
    ///
    /// # Errors
    /// As [`Self::loads`].
    #[inline]
    pub fn wing_frame_wrench_branch(
        &self,
        omega: &Vector3<f64>,
        branch: Branch,
    ) -> Result<(Vector3<f64>, Vector3<f64>)> {
        let Some(force) = self.omegas.force else {
            bail!(invalid "omegas.force", "None",
                "set: build Omegas from a Planform or call Omegas::with_force");
        };
        let o = &self.omegas;
        let (wx, wy, wz) = (omega.x, omega.y, omega.z);
        let sz = unit_sign(branch.spanwise_positive);
        let damping = -o.omega2 * self.rotational_damping * sz * wz * wz; // eq. 3.10
        let w2 = wx * wx + wy * wy;
        if w2 == 0.0 {
            return Ok((Vector3::zeros(), Vector3::new(0.0, 0.0, damping)));
        }
        let w = w2.sqrt();
        let sigma = unit_sign(branch.chordwise_positive);
        let alpha = branch_alpha(sigma * wx, wy);
        let (cl, cd) = match self.law {
            NormalForceLaw::Coefficient => self
                .coefficients
                .lift_drag_branch(alpha, branch.normal_positive),
            // C_N ≡ 1, C_T ≡ 0: C_L = cos α, C_D = sin α.
            NormalForceLaw::Unit => (wy / w, sigma * wx / w),
        };
        let lift_dir = Vector3::new(sigma * wx / w, sigma * wy / w, 0.0); // ℓ̂
        let vel_dir = Vector3::new(wy / w, -wx / w, 0.0); // û
        let d_cp = 0.82 / PI * alpha + 0.05; // eq. 3.7 on the branch
        let r_eff = Vector3::new(o.omega4 - d_cp * o.omega3, 0.0, o.omega1);
        // C_L ℓ̂ − C_D û, the strip force direction times its coefficient.
        let c = lift_dir * cl - vel_dir * cd;
        let mut torque = r_eff.cross(&c) * w2;
        torque.z += damping;
        Ok((c * (force * w2), torque))
    }

    /// The moments at a wing state (eqs. 3.8–3.11). Infallible; finite input gives finite output.
    #[inline]
    pub fn moments(&self, state: &WingState) -> AeroMoments {
        self.moments_omega(&state.angular_velocity())
    }

    /// The moments from the wing-frame angular velocity `ω` (rad/ms), e.g. `ω = J6 ṗ`.
    /// Allocation-free; finite input gives finite output.
    #[inline]
    pub fn moments_omega(&self, omega: &Vector3<f64>) -> AeroMoments {
        let o = &self.omegas;
        let (wx, wy, wz) = (omega.x, omega.y, omega.z);
        let w2 = wx * wx + wy * wy;
        let rotational_damping = -o.omega2 * self.rotational_damping * wz * wz.abs(); // eq. 3.10
        if w2 == 0.0 {
            return AeroMoments {
                rotational_damping,
                alpha: FRAC_PI_2,
                ..AeroMoments::default()
            };
        }
        let alpha = wx.abs().atan2(wy);
        let sigma = sign(wx);
        let (cn, ct) = self.normal_tangential(alpha);
        let d_cp = center_of_pressure(alpha); // eq. 3.7
        // C_T is chord-referred (module docs).
        AeroMoments::of_strip(o, sigma, w2, (cn, ct), d_cp, rotational_damping, alpha)
    }

    /// Lift and drag forces and torques in the body frame (see [`AeroLoads`]).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`omegas.force`) if the model has no force parameter (built
    /// from [`Omegas::new`] without [`Omegas::with_force`]).
    pub fn loads(&self, state: &WingState) -> Result<AeroLoads> {
        self.loads_omega(&state.angular_velocity(), &state.rotation())
    }

    /// [`Self::loads`] from the wing-frame angular velocity `ω` (rad/ms) and the rotation
    /// `R_6^1` (wing frame to body frame), e.g. an effective `ω` that includes body motion.
    /// Allocation-free.
    ///
    /// # Errors
    /// As [`Self::loads`].
    #[inline]
    pub fn loads_omega(&self, omega: &Vector3<f64>, rot: &Matrix3<f64>) -> Result<AeroLoads> {
        let moments = self.moments_omega(omega);
        self.loads_from_moments(omega, rot, moments, sign(omega.x), |alpha| {
            let (cn, ct) = self.normal_tangential(alpha);
            (cn, ct, center_of_pressure(alpha))
        })
    }
}

/// The drag torque of eq. 2.16, `−Ω φ̇² sgn(φ̇)` (mN·mm for Ω in mg·mm², φ̇ in rad/ms).
#[inline]
pub fn drag_torque_eq_2_16(omega: f64, phi_dot: f64) -> f64 {
    -omega * phi_dot * phi_dot.abs()
}
