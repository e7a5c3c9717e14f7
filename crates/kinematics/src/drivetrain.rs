//! Planar drivetrains: actuator coordinates `q = (q1, q2)` to stroke angles `φ = (φL, φR)`.
//!
//! Every drivetrain returns the stroke angles, the Jacobian `J = ∂φ/∂q` and the Hessians
//! `H_k = ∂²φ_k/∂q²`, so that `φ̈ = J q̈ + h(q, q̇)` with `h_k = q̇ᵀ H_k q̇`
//! ([`DrivetrainEval::velocity_product`]). Output order is (left, right), as in eq. 3.21.
//! Sign convention of eq. 2.15: positive `q1` gives negative stroke angles on both wings;
//! positive `q2` raises the right whippletree end (right stroke decreases, left increases).
//!
//! # Topology (Fig. 2.7a is not in the text; this is our design, consistent with §2.3.1–2.3.2)
//!
//! ```text
//!            q2 (whippletree rotation)
//!   E_L o=================o=================o E_R      whippletree, length L0 = hL + hR,
//!       |      hL         W (pivot, moves    |         centre pivot W driven along y by the
//!       |                    by q1 along y)  | rod L2  actuator (q1)
//!       |                                    |
//!       o------* G_L              G_R *------o          crank L3 from ground pivot G to the
//!        crank L3                     crank L3           rod end, horizontal at rest
//!   (wing L on the crank)         (wing R on the crank)
//! ```
//!
//! Each side is a rod-crank: the rod (length L2) connects the whippletree end to the tip of the
//! output crank (length L3) that pivots on ground and carries the wing. At rest the rod is
//! vertical and the crank horizontal (perpendicular: best transmission angle, equal gain up and
//! down), so the small-motion gain is exactly `T = 1/L3` rad/mm and the linearisation of the
//! linkage at rest is eq. 2.15 with `L = L0/2` (checked in the tests).
//!
//! * **HMF four-bar** (§2.3.1): the central link is rigid (`q2 ≡ 0`) and drives both rods; with
//!   the thesis' L3 = 400 µm, L2 = 800 µm a 400 µm stroke gives 60.0° (±30°).
//! * **Drag PARITY linkage** (§2.3.2, §3.3.2 lengths L0..L4 = 5000, 2500, 800, 400, 800 µm):
//!   L0 = whippletree length, L1 = 2500 µm = each whippletree arm (L0/2, pivot unbiased),
//!   L2 = rod, L3 = crank; L4 = 800 µm is the wing-side output link, which does not enter the
//!   planar map under the massless-mechanism assumption. With these lengths ±200 µm gives
//!   ±30° (−29.7°/+30.3°), not the thesis' "approximately ±35°", which would need a crank of
//!   ≈350 µm: the crank length is a parameter.
//! * **Biased pivot** (§2.4.2): arms `hL = L0 r/(1+r)`, `hR = L0/(1+r)` for arm ratio `r = hL/hR`.

use nalgebra::{Matrix2, Vector2};
use paritysim_error::{
    Error, Result, bail, check_angle_rad, check_in_closed, check_length_mm, check_offset_mm,
    check_positive, plausible,
};

/// Result of evaluating a drivetrain at `(q1, q2)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrivetrainEval {
    /// `(φL, φR)`, rad.
    pub stroke: Vector2<f64>,
    /// `J[k][i] = ∂φ_k/∂q_i` (rad/mm for q1, rad/rad for q2).
    pub jacobian: Matrix2<f64>,
    /// `H_k[i][j] = ∂²φ_k/∂q_i∂q_j` for k = left, right.
    pub hessian: [Matrix2<f64>; 2],
}

impl DrivetrainEval {
    /// `h_k = q̇ᵀ H_k q̇`, the velocity-product term in `φ̈ = J q̈ + h`.
    #[inline]
    pub fn velocity_product(&self, q_dot: &Vector2<f64>) -> Vector2<f64> {
        Vector2::new(
            q_dot.dot(&(self.hessian[0] * q_dot)),
            q_dot.dot(&(self.hessian[1] * q_dot)),
        )
    }
}

/// What a rod-crank's out-of-domain error names (`what`): callers that attribute the failure
/// to a spec field recognise it by this text.
pub const ROD_CRANK: &str = "rod-crank linkage";

/// One side's rod-crank (see the module sketch). Lengths in mm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RodCrank {
    crank: f64,
    rod: f64,
}

/// Crank angle `β` of a rod-crank and its derivatives w.r.t. the rod-top displacement.
#[derive(Clone, Copy, Debug, PartialEq)]
struct SideEval {
    beta: f64,
    grad: Vector2<f64>,
    hess: Matrix2<f64>,
}

impl RodCrank {
    /// The §3.3.2 / §2.3.1 side: crank L3 = 0.4 mm, rod L2 = 0.8 mm.
    pub const THESIS: RodCrank = RodCrank {
        crank: 0.4,
        rod: 0.8,
    };

    /// Validates both lengths against [`plausible::LENGTH_MM`] (mm).
    pub fn new(crank_mm: f64, rod_mm: f64) -> Result<Self> {
        Ok(Self {
            crank: check_length_mm("crank_mm", crank_mm)?,
            rod: check_length_mm("rod_mm", rod_mm)?,
        })
    }

    /// Crank length L3 (mm).
    pub fn crank(&self) -> f64 {
        self.crank
    }

    /// Rod length L2 (mm).
    pub fn rod(&self) -> f64 {
        self.rod
    }

    /// Largest lift of the rod top along the rod (`dx = 0`) before the linkage toggles (mm):
    /// the crank pivot and the rod top are at most `L2 + L3` apart (triangle inequality, the
    /// `|k| < 1` of `Self::solve`), so `(L2 + dy)² + L3² < (L2 + L3)²`, i.e.
    /// `dy < √(L2² + 2 L2 L3) − L2`.
    pub fn reach(&self) -> f64 {
        let (l3, l2) = (self.crank, self.rod);
        (l2 * l2 + 2.0 * l2 * l3).sqrt() - l2
    }

    /// Solves `|top − tip(β)| = rod` for the crank angle given the rod-top displacement
    /// `(dx, dy)` from rest, by implicit differentiation of
    /// `F = (X − L3 cos β)² + (Y − L3 sin β)² − L2²`.
    fn solve(&self, dx: f64, dy: f64) -> Result<SideEval> {
        let (l3, l2) = (self.crank, self.rod);
        let (x, y) = (l3 + dx, l2 + dy);
        let r = x.hypot(y);
        let k = (x * x + y * y + l3 * l3 - l2 * l2) / (2.0 * l3 * r);
        // Beyond |k| = 1 the rod cannot reach; near it the linkage toggles (infinite gain).
        if k.is_nan() || k.abs() >= 1.0 - 1e-9 || !r.is_finite() {
            return Err(Error::OutOfDomain {
                what: ROD_CRANK.into(),
                detail: format!(
                    "rod top displaced by ({dx}, {dy}) mm cannot be reached by crank {l3} mm \
                     and rod {l2} mm (toggle or beyond)"
                ),
            });
        }
        // β = atan2(y, x) − acos(k), by angle subtraction: one sqrt and one atan2 instead of
        // atan2 + acos + sin_cos (this sits inside the right-hand side).
        let (ca, sa) = (x / r, y / r);
        let (ck, sk) = (k, (1.0 - k * k).sqrt());
        let (sb, cb) = (sa * ck - ca * sk, ca * ck + sa * sk);
        let beta = sb.atan2(cb);
        let f_x = 2.0 * (x - l3 * cb);
        let f_y = 2.0 * (y - l3 * sb);
        let f_b = 2.0 * l3 * (x * sb - y * cb);
        let f_xb = 2.0 * l3 * sb;
        let f_yb = -2.0 * l3 * cb;
        let f_bb = 2.0 * l3 * (x * cb + y * sb);
        let b_x = -f_x / f_b;
        let b_y = -f_y / f_b;
        // β_ab = −(F_ab + F_aβ β_b + F_bβ β_a + F_ββ β_a β_b) / F_β, with F_XX = F_YY = 2, F_XY = 0.
        let b_xx = -(2.0 + 2.0 * f_xb * b_x + f_bb * b_x * b_x) / f_b;
        let b_yy = -(2.0 + 2.0 * f_yb * b_y + f_bb * b_y * b_y) / f_b;
        let b_xy = -(f_xb * b_y + f_yb * b_x + f_bb * b_x * b_y) / f_b;
        Ok(SideEval {
            beta,
            grad: Vector2::new(b_x, b_y),
            hess: Matrix2::new(b_xx, b_xy, b_xy, b_yy),
        })
    }

    /// Stroke angle `φ = −β` of a side whose whippletree end sits at arm `arm` (mm) with sign
    /// `side` (+1 right, −1 left), with its gradient and Hessian in `(q1, q2)`.
    fn side_stroke(
        &self,
        q1: f64,
        q2: f64,
        arm: f64,
        side: f64,
    ) -> Result<(f64, Vector2<f64>, Matrix2<f64>)> {
        let (s2, c2) = q2.sin_cos();
        // Rod-top displacement (dx, dy) and its q-derivatives.
        let dx = arm * (c2 - 1.0);
        let dy = q1 + side * arm * s2;
        let e = self.solve(dx, dy)?;
        // ∂(dx, dy)/∂q: rows (dx, dy), columns (q1, q2).
        let d = Matrix2::new(0.0, -arm * s2, 1.0, side * arm * c2);
        let grad = d.transpose() * e.grad;
        // Only ∂²/∂q2² of (dx, dy) is non-zero.
        let dxx = -arm * c2;
        let dyy = -side * arm * s2;
        let mut hess = d.transpose() * e.hess * d;
        hess[(1, 1)] += e.grad[0] * dxx + e.grad[1] * dyy;
        Ok((-e.beta, -grad, -hess))
    }
}

/// HMF symmetric four-bar (§2.3.1): 1 DOF, `q2` is ignored (held at zero).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HmfFourBar {
    side: RodCrank,
}

/// Two independent four-bars, one actuator per wing (beyond the thesis: the dual-actuator
/// layout of later flapping robots, issue 17): `q1` drives the left rod-crank, `q2` the
/// right one, `φL = f(q1)`, `φR = f(q2)` with `f` the HMF side (2 DOF, diagonal Jacobian).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DualFourBar {
    side: RodCrank,
}

/// Drag PARITY linear map of eq. 2.15 with a (possibly biased) whippletree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearDifferential {
    transmission_ratio: f64,
    left_arm: f64,
    right_arm: f64,
    polynomial: OddPolynomial,
}

/// Drag PARITY nonlinear linkage (§2.3.2): whippletree plus two rod-cranks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinkageDifferential {
    side: RodCrank,
    left_arm: f64,
    right_arm: f64,
}

/// An odd polynomial transmission (beyond the thesis, issue 35; modified RoboBee-class
/// transmissions): a side's stroke is `φ = τ1 σ + τ2 σ³/3 + a5 σ⁵ + a7 σ⁷ + a9 σ⁹` of its
/// actuator-side displacement `σ` (mm). Stored in terms of the linear stroke `ℓ = τ1 σ` (what the
/// linear map gives): `φ = P(ℓ) = ℓ (1 + ℓ² (b3 + ℓ² (b5 + ℓ² (b7 + ℓ² b9))))` with
/// `b3 = τ2 / (3 τ1³)`, `b5 = a5 / τ1⁵`, ..., so that zero higher terms give `φ = ℓ` bit for
/// bit (the linear map's numbers).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct OddPolynomial {
    b: [f64; 4],
}

/// Most higher odd terms (`σ⁵, σ⁷, σ⁹`) an [`OddPolynomial`] takes.
pub const MAX_HIGHER_ODD: usize = 3;

/// What a polynomial transmission's fold-over error names (`what`).
pub const POLYNOMIAL: &str = "polynomial transmission";

impl OddPolynomial {
    /// The linear map (`φ = ℓ`).
    pub const LINEAR: OddPolynomial = OddPolynomial { b: [0.0; 4] };

    /// `φ = τ1 σ + τ2 σ³/3 + Σ_j higher[j] σ^(2j+5)` with `τ1 = transmission_ratio` (rad/mm, > 0),
    /// `τ2 = cubic_ratio` (rad/mm³) and `higher` the coefficients of `σ⁵, σ⁷, σ⁹` (rad/mm⁵, ...).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `cubic_ratio` or `higher_odd_ratios[j]` when not
    /// finite, or `higher_odd_ratios` when it has more than [`MAX_HIGHER_ODD`] entries.
    pub fn new(transmission_ratio: f64, cubic_ratio: f64, higher: &[f64]) -> Result<Self> {
        let t = check_positive("transmission_ratio", transmission_ratio)?;
        let tau2 = paritysim_error::check_finite("cubic_ratio", cubic_ratio)?;
        if higher.len() > MAX_HIGHER_ODD {
            bail!(invalid "higher_odd_ratios", higher.len(), format!(
                "at most {MAX_HIGHER_ODD} coefficients (of sigma^5, sigma^7, sigma^9)"
            ));
        }
        let mut b = [tau2 / (3.0 * t.powi(3)), 0.0, 0.0, 0.0];
        for (j, &a) in higher.iter().enumerate() {
            if !a.is_finite() {
                bail!(invalid format!("higher_odd_ratios[{j}]"), a, "a finite number");
            }
            b[j + 1] = a / t.powi(2 * j as i32 + 5);
        }
        if !b.iter().all(|x| x.is_finite()) {
            bail!(invalid "cubic_ratio", cubic_ratio, "such that the coefficients over powers of transmission_ratio stay finite");
        }
        Ok(Self { b })
    }

    /// The coefficients `(b3, b5, b7, b9)` of `ℓ³, ℓ⁵, ℓ⁷, ℓ⁹` (see the type).
    pub fn coefficients(&self) -> [f64; 4] {
        self.b
    }

    /// Whether this is the linear map (`φ = ℓ`).
    pub fn is_linear(&self) -> bool {
        self.b == [0.0; 4]
    }

    /// `(P, P', P'')` at the linear stroke `ℓ` (rad).
    ///
    /// # Errors
    /// [`Error::OutOfDomain`] where `P'(ℓ) <= 0`: the transmission folds over (a softening
    /// polynomial beyond its turning point).
    #[inline]
    pub fn evaluate(&self, l: f64) -> Result<(f64, f64, f64)> {
        let [b3, b5, b7, b9] = self.b;
        let l2 = l * l;
        let p = l * (1.0 + l2 * (b3 + l2 * (b5 + l2 * (b7 + l2 * b9))));
        let p1 = 1.0 + l2 * (3.0 * b3 + l2 * (5.0 * b5 + l2 * (7.0 * b7 + l2 * (9.0 * b9))));
        let p2 = l * (6.0 * b3 + l2 * (20.0 * b5 + l2 * (42.0 * b7 + l2 * (72.0 * b9))));
        if p1.is_nan() || p1 <= 0.0 || !p.is_finite() {
            return Err(Error::OutOfDomain {
                what: POLYNOMIAL.into(),
                detail: format!(
                    "the stroke map folds over (d phi / d sigma = {p1} <= 0) at a linear stroke of {l} rad \
                     (a softening drivetrain.cubic_ratio: keep sigma below sqrt(tau1 / |tau2|))"
                ),
            });
        }
        Ok((p, p1, p2))
    }
}

/// One actuator on a linear (or polynomial) transmission (beyond the thesis, issue 35): the
/// RoboBee-class single drive, `φ = P(−T q1)` for one wing, or for two wings tied `φL = φR`
/// (the linearised HMF). 1 DOF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SingleLinear {
    transmission_ratio: f64,
    polynomial: OddPolynomial,
}

/// One actuator per wing on linear (or polynomial) transmissions (beyond the thesis, issue 35:
/// every RoboBee since 2013): `φL = P(−T q1)`, `φR = P(−T q2)`, 2 DOF, diagonal Jacobian.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DualLinear {
    transmission_ratio: f64,
    polynomial: OddPolynomial,
}

/// The rows `J_k` of a linear map with a polynomial on each side: `φ_k = P(J_k q)`.
#[inline]
fn polynomial_map(
    rows: [[f64; 2]; 2],
    polynomial: &OddPolynomial,
    q1: f64,
    q2: f64,
) -> Result<DrivetrainEval> {
    let mut stroke = Vector2::zeros();
    let mut jacobian = Matrix2::zeros();
    let mut hessian = [Matrix2::zeros(); 2];
    for (k, [a, b]) in rows.into_iter().enumerate() {
        let (p, p1, p2) = polynomial.evaluate(a * q1 + b * q2)?;
        stroke[k] = p;
        jacobian[(k, 0)] = p1 * a;
        jacobian[(k, 1)] = p1 * b;
        hessian[k] = Matrix2::new(p2 * a * a, p2 * a * b, p2 * a * b, p2 * b * b);
    }
    Ok(DrivetrainEval {
        stroke,
        jacobian,
        hessian,
    })
}

impl SingleLinear {
    /// `φ = P(−T q1)` with `T = transmission_ratio` (rad/mm) in [1e-6, 1e3].
    pub fn new(transmission_ratio: f64, polynomial: OddPolynomial) -> Result<Self> {
        check_in_closed("transmission_ratio", transmission_ratio, 1e-6, 1e3)?;
        Ok(Self {
            transmission_ratio,
            polynomial,
        })
    }

    /// `T` (rad/mm).
    pub fn transmission_ratio(&self) -> f64 {
        self.transmission_ratio
    }

    /// The polynomial of the transmission.
    pub fn polynomial(&self) -> OddPolynomial {
        self.polynomial
    }
}

impl DualLinear {
    /// `φL = P(−T q1)`, `φR = P(−T q2)` with `T = transmission_ratio` (rad/mm) in [1e-6, 1e3].
    pub fn new(transmission_ratio: f64, polynomial: OddPolynomial) -> Result<Self> {
        check_in_closed("transmission_ratio", transmission_ratio, 1e-6, 1e3)?;
        Ok(Self {
            transmission_ratio,
            polynomial,
        })
    }

    /// `T` (rad/mm).
    pub fn transmission_ratio(&self) -> f64 {
        self.transmission_ratio
    }

    /// The polynomial of the transmission (both sides).
    pub fn polynomial(&self) -> OddPolynomial {
        self.polynomial
    }

    /// The linear rows `J_k` (`ℓ_k = J_k q`).
    pub fn rows(&self) -> [[f64; 2]; 2] {
        let t = self.transmission_ratio;
        [[-t, 0.0], [0.0, -t]]
    }
}

/// Splits a whippletree of `length` (mm) into `(left, right)` arms with `ratio = left/right`.
fn split_arms(length: f64, ratio: f64) -> Result<(f64, f64)> {
    check_length_mm("whippletree_length_mm", length)?;
    check_positive("arm_ratio", ratio)?;
    let arms = (length * ratio / (1.0 + ratio), length / (1.0 + ratio));
    // A vanishing arm makes the drivetrain Jacobian singular at rest (q2 no longer moves it).
    if arms.0.min(arms.1) < plausible::LENGTH_MM.0 {
        bail!(invalid "arm_ratio", ratio, format!(
            "such that both arms of the {length} mm whippletree are at least {:e} mm",
            plausible::LENGTH_MM.0
        ));
    }
    Ok(arms)
}

/// Limit on `|q2|`: beyond ±π/2 the whippletree folds over.
const Q2_LIMIT: f64 = std::f64::consts::FRAC_PI_2;

impl HmfFourBar {
    /// HMF four-bar with the given side linkage.
    pub fn new(side: RodCrank) -> Self {
        Self { side }
    }

    /// Side linkage.
    pub fn side(&self) -> RodCrank {
        self.side
    }
}

impl DualFourBar {
    /// One rod-crank per wing, both of the given geometry.
    pub fn new(side: RodCrank) -> Self {
        Self { side }
    }

    /// Side linkage (both sides).
    pub fn side(&self) -> RodCrank {
        self.side
    }
}

impl LinearDifferential {
    /// Eq. 2.15 with transmission ratio `T` (rad/mm), mean arm `L` (mm) and arm ratio
    /// `r = hL/hR` (1 = centred pivot): `φL = −T q1 + T hL q2`, `φR = −T q1 − T hR q2` with
    /// `hL = 2L r/(1+r)`, `hR = 2L/(1+r)`.
    pub fn new(transmission_ratio: f64, arm_length_mm: f64, arm_ratio: f64) -> Result<Self> {
        // A vanishing ratio makes the Jacobian (det = -T^2 (hL + hR)) singular.
        check_in_closed("transmission_ratio", transmission_ratio, 1e-6, 1e3)?;
        let (left_arm, right_arm) = split_arms(
            2.0 * check_length_mm("arm_length_mm", arm_length_mm)?,
            arm_ratio,
        )?;
        Ok(Self {
            transmission_ratio,
            left_arm,
            right_arm,
            polynomial: OddPolynomial::LINEAR,
        })
    }

    /// With a polynomial transmission on each side: `φ_k = P(ℓ_k)` where `ℓ_k` is the stroke of
    /// eq. 2.15 (the rod-top displacement times `T`).
    pub fn with_polynomial(mut self, polynomial: OddPolynomial) -> Self {
        self.polynomial = polynomial;
        self
    }

    /// The polynomial of the transmission (both sides; linear for eq. 2.15).
    pub fn polynomial(&self) -> OddPolynomial {
        self.polynomial
    }

    /// The rows of eq. 2.15's Jacobian (`ℓ_k = J_k q`).
    pub fn rows(&self) -> [[f64; 2]; 2] {
        let t = self.transmission_ratio;
        [[-t, t * self.left_arm], [-t, -t * self.right_arm]]
    }

    /// Eq. 2.15 at `(q1, q2)`, ignoring any polynomial: constant Jacobian, no second
    /// derivatives.
    #[inline]
    pub fn evaluate(&self, q1: f64, q2: f64) -> DrivetrainEval {
        let t = self.transmission_ratio;
        let j = Matrix2::new(-t, t * self.left_arm, -t, -t * self.right_arm);
        DrivetrainEval {
            stroke: j * Vector2::new(q1, q2),
            jacobian: j,
            hessian: [Matrix2::zeros(); 2],
        }
    }

    /// `T` (rad/mm).
    pub fn transmission_ratio(&self) -> f64 {
        self.transmission_ratio
    }

    /// `(hL, hR)` (mm).
    pub fn arms(&self) -> (f64, f64) {
        (self.left_arm, self.right_arm)
    }
}

impl LinkageDifferential {
    /// Linkage with whippletree `length` L0 (mm) and arm ratio `r = hL/hR`.
    pub fn new(side: RodCrank, whippletree_length_mm: f64, arm_ratio: f64) -> Result<Self> {
        let (left_arm, right_arm) = split_arms(whippletree_length_mm, arm_ratio)?;
        Ok(Self {
            side,
            left_arm,
            right_arm,
        })
    }

    /// The §3.3.2 whippletree length L0 (mm).
    pub const THESIS_WHIPPLETREE_LENGTH_MM: f64 = 5.0;

    /// The §3.3.2 linkage: L0 = 5 mm, L2 = 0.8 mm, L3 = 0.4 mm, centred pivot.
    pub fn thesis() -> Self {
        Self {
            side: RodCrank::THESIS,
            left_arm: Self::THESIS_WHIPPLETREE_LENGTH_MM / 2.0,
            right_arm: Self::THESIS_WHIPPLETREE_LENGTH_MM / 2.0,
        }
    }

    /// Side linkage.
    pub fn side(&self) -> RodCrank {
        self.side
    }

    /// `(hL, hR)` (mm).
    pub fn arms(&self) -> (f64, f64) {
        (self.left_arm, self.right_arm)
    }
}

/// Any planar drivetrain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Drivetrain {
    /// HMF four-bar, 1 DOF.
    HmfFourBar(HmfFourBar),
    /// Drag PARITY, linear map of eq. 2.15.
    LinearDifferential(LinearDifferential),
    /// Drag PARITY, nonlinear linkage.
    LinkageDifferential(LinkageDifferential),
    /// Two four-bars, one actuator per wing (`q1` left, `q2` right), 2 DOF.
    DualFourBar(DualFourBar),
    /// One actuator on a linear or polynomial transmission, 1 DOF.
    SingleLinear(SingleLinear),
    /// One actuator per wing on linear or polynomial transmissions, 2 DOF.
    DualLinear(DualLinear),
}

impl Drivetrain {
    /// Number of kinematic degrees of freedom (1 for the HMF, 2 for Drag PARITY).
    pub fn dof(&self) -> usize {
        match self {
            Drivetrain::HmfFourBar(_) | Drivetrain::SingleLinear(_) => 1,
            _ => 2,
        }
    }

    /// The rod-crank of each side (the linkages), None for the linear map.
    pub fn rod_crank(&self) -> Option<RodCrank> {
        match self {
            Drivetrain::HmfFourBar(d) => Some(d.side),
            Drivetrain::LinkageDifferential(d) => Some(d.side),
            Drivetrain::DualFourBar(d) => Some(d.side),
            Drivetrain::LinearDifferential(_)
            | Drivetrain::SingleLinear(_)
            | Drivetrain::DualLinear(_) => None,
        }
    }

    /// Whether each wing has its own drive (`q1` left, `q2` right: the dual drivetrains).
    pub fn is_dual(&self) -> bool {
        matches!(self, Drivetrain::DualFourBar(_) | Drivetrain::DualLinear(_))
    }

    /// The polynomial of a linear-map drivetrain's transmission (None for the linkages).
    pub fn polynomial(&self) -> Option<OddPolynomial> {
        match self {
            Drivetrain::LinearDifferential(d) => Some(d.polynomial),
            Drivetrain::SingleLinear(d) => Some(d.polynomial),
            Drivetrain::DualLinear(d) => Some(d.polynomial),
            _ => None,
        }
    }

    /// Short name (`hmf_four_bar`, `linear_differential`, `linkage_differential`, ...).
    pub fn name(&self) -> &'static str {
        match self {
            Drivetrain::HmfFourBar(_) => "hmf_four_bar",
            Drivetrain::LinearDifferential(_) => "linear_differential",
            Drivetrain::LinkageDifferential(_) => "linkage_differential",
            Drivetrain::DualFourBar(_) => "dual_four_bar",
            Drivetrain::SingleLinear(_) => "single_linear",
            Drivetrain::DualLinear(_) => "dual_linear",
        }
    }

    /// Stroke angles, Jacobian and Hessians at `(q1, q2)` (mm, rad).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless `|q1| <=` [`paritysim_error::plausible::OFFSET_MM`] and
    /// `|q2| <=` [`paritysim_error::plausible::ANGLE_RAD`]; [`Error::OutOfDomain`] when a linkage
    /// cannot reach the pose (rod too short, toggle) or `|q2| >= π/2`.
    #[inline]
    pub fn evaluate(&self, q1: f64, q2: f64) -> Result<DrivetrainEval> {
        // The checks build their errors out of line: this sits in every right-hand side.
        if !(q1.abs() <= paritysim_error::plausible::OFFSET_MM
            && q2.abs() <= paritysim_error::plausible::ANGLE_RAD)
        {
            check_offset_mm("q1", q1)?;
            check_angle_rad("q2", q2)?;
        }
        // The linear map inline (it sits in every right-hand side and sample); the linkages,
        // with their trigonometry and Newton solves, out of line.
        match self {
            Drivetrain::LinearDifferential(d) if d.polynomial.is_linear() => Ok(d.evaluate(q1, q2)),
            _ => self.evaluate_linkage(q1, q2),
        }
    }

    #[inline(never)]
    fn evaluate_linkage(&self, q1: f64, q2: f64) -> Result<DrivetrainEval> {
        match self {
            Drivetrain::HmfFourBar(d) => {
                let (phi, grad, hess) = d.side.side_stroke(q1, 0.0, 0.0, 1.0)?;
                // q2 is not a coordinate of the HMF: zero column and zero second derivatives.
                let j = Matrix2::new(grad[0], 0.0, grad[0], 0.0);
                let h = Matrix2::new(hess[(0, 0)], 0.0, 0.0, 0.0);
                Ok(DrivetrainEval {
                    stroke: Vector2::new(phi, phi),
                    jacobian: j,
                    hessian: [h, h],
                })
            }
            Drivetrain::LinkageDifferential(d) => {
                if q2.abs() >= Q2_LIMIT {
                    bail!(invalid "q2", q2, "in (-pi/2, pi/2) rad (whippletree folds over)");
                }
                let (pl, gl, hl) = d.side.side_stroke(q1, q2, d.left_arm, -1.0)?;
                let (pr, gr, hr) = d.side.side_stroke(q1, q2, d.right_arm, 1.0)?;
                Ok(DrivetrainEval {
                    stroke: Vector2::new(pl, pr),
                    jacobian: Matrix2::new(gl[0], gl[1], gr[0], gr[1]),
                    hessian: [hl, hr],
                })
            }
            Drivetrain::DualFourBar(d) => {
                // Each side is the HMF side on its own actuator coordinate.
                let (pl, gl, hl) = d.side.side_stroke(q1, 0.0, 0.0, 1.0)?;
                let (pr, gr, hr) = d.side.side_stroke(q2, 0.0, 0.0, 1.0)?;
                Ok(DrivetrainEval {
                    stroke: Vector2::new(pl, pr),
                    jacobian: Matrix2::new(gl[0], 0.0, 0.0, gr[0]),
                    hessian: [
                        Matrix2::new(hl[(0, 0)], 0.0, 0.0, 0.0),
                        Matrix2::new(0.0, 0.0, 0.0, hr[(0, 0)]),
                    ],
                })
            }
            Drivetrain::LinearDifferential(d) if d.polynomial.is_linear() => Ok(d.evaluate(q1, q2)),
            Drivetrain::LinearDifferential(d) => polynomial_map(d.rows(), &d.polynomial, q1, q2),
            Drivetrain::DualLinear(d) => polynomial_map(d.rows(), &d.polynomial, q1, q2),
            Drivetrain::SingleLinear(d) => {
                let t = d.transmission_ratio;
                let (p, p1, p2) = d.polynomial.evaluate(-t * q1)?;
                // q2 is not a coordinate: zero column, both wings on the one drive.
                let j = Matrix2::new(-t * p1, 0.0, -t * p1, 0.0);
                let h = Matrix2::new(p2 * t * t, 0.0, 0.0, 0.0);
                Ok(DrivetrainEval {
                    stroke: Vector2::new(p, p),
                    jacobian: j,
                    hessian: [h, h],
                })
            }
        }
    }
}
