//! Aerodynamic coefficient models (thesis §3.2.4, eqs. 3.5–3.7).
//!
//! # Angle of attack and force directions
//! `α ∈ [0, π]` is the geometric angle between the chord, pointing to the **leading edge**, and
//! the wing's velocity through the air: `α < π/2` while the leading edge leads, `α = π/2` with
//! the wing broadside to the flow, `α > π/2` when the leading edge trails (see
//! [`crate::blade`] for how α follows from the wing state and docs/errata.md#5).
//!
//! In the plane of the chord and the velocity `û`: drag acts along `−û`, lift along the unit
//! vector `ℓ̂ ⟂ û` on the leading-edge side (`ℓ̂·ĉ >= 0`, `ĉ` the chord toward the leading edge).
//! Writing the same force in wing axes, with `n̂` the wing normal on the side the air pushes
//! (opposite to the normal velocity) and `ĉ`:
//!
//! ```text
//! C_L ℓ̂ − C_D û = C_N n̂ − C_T ĉ
//! C_N = C_L cos α + C_D sin α        (normal, pushing against the normal motion)
//! C_T = C_D cos α − C_L sin α        (tangential, positive toward the trailing edge)
//! ```
//!
//! i.e. `(C_N, C_T)` is `(C_L, C_D)` rotated by `α`; the inverse is
//! `C_L = C_N cos α − C_T sin α`, `C_D = C_N sin α + C_T cos α` ([`from_normal_tangential`]).
//!
//! # Extension past 90°
//! The Dickinson et al. fits were measured for `α ∈ [−9°, 90°]`. For `α > 90°` (leading edge
//! trailing) the flat-plate symmetry `C_L(π − α) = −C_L(α)`, `C_D(π − α) = C_D(α)` is used. The
//! `sin 2α` form of Whitney & Wood has that symmetry built in. Both models then satisfy
//! `C_N(π − α) = C_N(α)`, `C_T(π − α) = −C_T(α)`, which makes the blade-element moments odd in
//! the wing's angular velocity. Because the published fit has `C_L(90°) = 0.10 ≠ 0`, the
//! extended Dickinson `C_L` and `C_T` jump by ±0.10 at exactly `α = 90°`; `C_N` is continuous.

use std::f64::consts::{FRAC_PI_2, PI};
use std::fmt;

use paritysim_error::{Error, Result, bail};
use paritysim_simd::{Real, cos, sin, sin_cos};

/// Default rotational damping coefficient `C_rd` of eq. 3.10: 5.0, the value used by
/// J. P. Whitney & R. J. Wood, "Aeromechanics of passive rotation in flapping flight",
/// J. Fluid Mech. 660, 197–220 (2010), who base it on tumbling-plate experiments
/// (Andersen, Pesavento & Wang 2005), the sources the thesis cites as refs. 1 and 39.
/// The thesis gives no value for §3.4 (docs/errata.md#14); this is a documented default.
pub const DEFAULT_ROTATIONAL_DAMPING: f64 = 5.0;

/// Lift, drag, normal and tangential force coefficients at one angle of attack.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coefficients {
    /// `C_L`, along `ℓ̂` (perpendicular to the velocity, leading-edge side).
    pub lift: f64,
    /// `C_D`, along `−û`.
    pub drag: f64,
    /// `C_N = C_L cos α + C_D sin α`, normal to the wing.
    pub normal: f64,
    /// `C_T = C_D cos α − C_L sin α`, along the chord toward the trailing edge.
    pub tangential: f64,
}

/// `(C_N, C_T)` from `(C_L, C_D)` at `α` (rad): a rotation by α (see the module docs).
#[inline]
pub fn to_normal_tangential(alpha: f64, lift: f64, drag: f64) -> (f64, f64) {
    let (s, c) = alpha.sin_cos();
    (lift * c + drag * s, drag * c - lift * s)
}

/// [`to_normal_tangential`] of one angle or of four in SIMD lanes, with the shared polynomial
/// `sin`/`cos` (bit for bit the same per lane).
#[inline]
pub fn to_normal_tangential_generic<R: Real>(alpha: R, lift: R, drag: R) -> (R, R) {
    let (s, c) = sin_cos(alpha);
    (lift * c + drag * s, drag * c - lift * s)
}

/// `(C_L, C_D)` from `(C_N, C_T)` at `α` (rad): the inverse rotation of
/// [`to_normal_tangential`].
#[inline]
pub fn from_normal_tangential(alpha: f64, normal: f64, tangential: f64) -> (f64, f64) {
    let (s, c) = alpha.sin_cos();
    (normal * c - tangential * s, normal * s + tangential * c)
}

/// Non-dimensional centre of pressure `d̂_cp = 0.82|α|/π + 0.05` (eq. 3.7; α in rad): the
/// distance of the centre of pressure behind the leading edge, as a fraction of the chord
/// (Dickinson et al. 1999). Over `α ∈ [0, π]` it runs from 0.05 to 0.87, so a trailing leading
/// edge (`α > π/2`) moves the centre of pressure toward the (then leading) trailing edge.
#[inline]
pub fn center_of_pressure(alpha: f64) -> f64 {
    0.82 / PI * alpha.abs() + 0.05
}

/// A lift/drag coefficient model. Implementations are pure functions of α: immutable,
/// `Send + Sync`, allocation-free.
pub trait CoefficientModel: Send + Sync + fmt::Debug {
    /// `(C_L, C_D)` at `alpha ∈ [0, π]` (rad, see the module docs for the convention). Values
    /// outside the range are not validated here (hot path); use [`checked_coefficients`].
    fn lift_drag(&self, alpha: f64) -> (f64, f64);

    /// Short stable identifier (`"dickinson1999"`, `"whitney_wood2010"`).
    fn name(&self) -> &'static str;

    /// Whether `(C_L, C_D)` jump at `α = π/2` (a fit extended past 90° by symmetry whose
    /// `C_L(90°) ≠ 0`): a switching surface of the blade-element model.
    fn jumps_at_right_angle(&self) -> bool {
        false
    }

    /// The smooth branch of [`Self::lift_drag`] on one side of `α = π/2` (`below` for
    /// `α <= π/2`), continued analytically past it (event location integrates each branch a
    /// little beyond its switching surface). Equals [`Self::lift_drag`] on its own side.
    #[inline]
    fn lift_drag_branch(&self, alpha: f64, _below: bool) -> (f64, f64) {
        self.lift_drag(alpha)
    }

    /// `(C_L, C_D)` of [`Self::lift_drag_branch`] and their slopes `(dC_L/dα, dC_D/dα)`: the
    /// analytic Jacobian of the stroke-plane equations needs them. The default differentiates
    /// the branch centrally (step 1e-6 rad: slopes to ~1e-10); the built-in models override it
    /// in closed form.
    #[inline]
    fn lift_drag_slope_branch(&self, alpha: f64, below: bool) -> ((f64, f64), (f64, f64)) {
        let h = 1e-6;
        let (lp, dp) = self.lift_drag_branch(alpha + h, below);
        let (lm, dm) = self.lift_drag_branch(alpha - h, below);
        (
            self.lift_drag_branch(alpha, below),
            ((lp - lm) / (2.0 * h), (dp - dm) / (2.0 * h)),
        )
    }

    /// All four coefficients at `alpha` (rad).
    #[inline]
    fn coefficients(&self, alpha: f64) -> Coefficients {
        let (lift, drag) = self.lift_drag(alpha);
        let (normal, tangential) = to_normal_tangential(alpha, lift, drag);
        Coefficients {
            lift,
            drag,
            normal,
            tangential,
        }
    }
}

/// [`CoefficientModel::coefficients`] with the domain checked.
///
/// # Errors
/// [`Error::InvalidParameter`] (`alpha`) unless `0 <= alpha <= π` (rad).
pub fn checked_coefficients(model: &dyn CoefficientModel, alpha: f64) -> Result<Coefficients> {
    if !(alpha.is_finite() && (0.0..=PI).contains(&alpha)) {
        bail!(invalid "alpha", alpha, "in [0, pi] rad (angle between chord and velocity)");
    }
    Ok(model.coefficients(alpha))
}

/// The Dickinson, Lehmann & Sane 1999 (Science 284, 1954) fits to a dynamically scaled fruit
/// fly wing, eqs. 3.5–3.6 of the thesis:
///
/// ```text
/// C_D = 1.92 − 1.55 cos(2.04 α − 9.82°)      (3.5)
/// C_L = 0.225 + 1.58 sin(2.13 α − 7.20°)     (3.6)
/// ```
///
/// with α **in degrees** as published. Since `2.04 α_deg` degrees equals `2.04 α_rad` radians,
/// only the offsets are converted; the functions here take α in radians. Extended past 90° by
/// flat-plate symmetry (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Dickinson1999;

impl Dickinson1999 {
    const CD_OFFSET: f64 = 9.82 * PI / 180.0;
    const CL_OFFSET: f64 = 7.20 * PI / 180.0;

    /// The published fits evaluated as printed at any α (rad), without the extension past 90°;
    /// of one angle or of four in SIMD lanes (bit for bit the same per lane: the shared
    /// polynomial `sin`/`cos` of `paritysim_simd`).
    #[inline]
    pub fn fit<R: Real>(alpha: R) -> (R, R) {
        let k = R::splat;
        let cd = k(1.92) - k(1.55) * cos(k(2.04) * alpha - k(Self::CD_OFFSET)); // eq. 3.5
        let cl = k(0.225) + k(1.58) * sin(k(2.13) * alpha - k(Self::CL_OFFSET)); // eq. 3.6
        (cl, cd)
    }

    /// The branch of the extended fit on one side of α = π/2 (`below`), continued past it: the
    /// fit at α below, at π − α (C_L negated) above; of one angle or of four in SIMD lanes.
    #[inline]
    pub fn fit_branch<R: Real>(alpha: R, below: R::Mask) -> (R, R) {
        let argument = R::select(below, alpha, R::splat(PI) - alpha);
        let (cl, cd) = Self::fit(argument);
        (R::select(below, cl, -cl), cd)
    }

    /// [`Self::fit`] and its slopes `(dC_L/dα, dC_D/dα)`.
    #[inline]
    pub fn fit_with_slope(alpha: f64) -> ((f64, f64), (f64, f64)) {
        let (sd, cd_) = sin_cos(2.04 * alpha - Self::CD_OFFSET);
        let (sl, cl_) = sin_cos(2.13 * alpha - Self::CL_OFFSET);
        (
            (0.225 + 1.58 * sl, 1.92 - 1.55 * cd_),
            (1.58 * 2.13 * cl_, 1.55 * 2.04 * sd),
        )
    }
}

impl CoefficientModel for Dickinson1999 {
    #[inline]
    fn lift_drag(&self, alpha: f64) -> (f64, f64) {
        if alpha <= FRAC_PI_2 {
            Self::fit(alpha)
        } else {
            let (cl, cd) = Self::fit(PI - alpha);
            (-cl, cd)
        }
    }

    fn name(&self) -> &'static str {
        "dickinson1999"
    }

    fn jumps_at_right_angle(&self) -> bool {
        true
    }

    #[inline]
    fn lift_drag_branch(&self, alpha: f64, below: bool) -> (f64, f64) {
        Self::fit_branch(alpha, below)
    }

    #[inline]
    fn lift_drag_slope_branch(&self, alpha: f64, below: bool) -> ((f64, f64), (f64, f64)) {
        if below {
            Self::fit_with_slope(alpha)
        } else {
            // C_L(α) = −C_L^fit(π − α), C_D(α) = C_D^fit(π − α).
            let ((cl, cd), (dcl, dcd)) = Self::fit_with_slope(PI - alpha);
            ((-cl, cd), (dcl, -dcd))
        }
    }
}

/// The harmonic form `C_L = A sin 2α`, `C_D = B − C cos 2α` used by Whitney & Wood 2010
/// (J. Fluid Mech. 660) for passive-rotation studies; the default constants are those of
/// issue #3: `C_L = 1.8 sin 2α`, `C_D = 1.9 − 1.5 cos 2α` (so `C_D ∈ [0.4, 3.4]`,
/// `C_N(90°) = 3.4`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WhitneyWood2010 {
    /// `A` in `C_L = A sin 2α`.
    pub lift_amplitude: f64,
    /// `B` in `C_D = B − C cos 2α`.
    pub drag_mean: f64,
    /// `C` in `C_D = B − C cos 2α`.
    pub drag_amplitude: f64,
}

impl Default for WhitneyWood2010 {
    fn default() -> Self {
        Self {
            lift_amplitude: 1.8,
            drag_mean: 1.9,
            drag_amplitude: 1.5,
        }
    }
}

impl WhitneyWood2010 {
    /// Custom constants.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless all are finite and `drag_mean >= |drag_amplitude|`
    /// (drag never negative).
    pub fn new(lift_amplitude: f64, drag_mean: f64, drag_amplitude: f64) -> Result<Self> {
        paritysim_error::check_finite("lift_amplitude", lift_amplitude)?;
        paritysim_error::check_finite("drag_amplitude", drag_amplitude)?;
        if !(drag_mean.is_finite() && drag_mean >= drag_amplitude.abs()) {
            bail!(invalid "drag_mean", drag_mean, format!(">= |drag_amplitude| = {}", drag_amplitude.abs()));
        }
        Ok(Self {
            lift_amplitude,
            drag_mean,
            drag_amplitude,
        })
    }
}

impl WhitneyWood2010 {
    /// `(C_L, C_D)` of one angle or of four in SIMD lanes (bit for bit the same per lane).
    #[inline]
    fn harmonic<R: Real>(&self, alpha: R) -> (R, R) {
        let k = R::splat;
        let (s2, c2) = sin_cos(k(2.0) * alpha);
        (
            k(self.lift_amplitude) * s2,
            k(self.drag_mean) - k(self.drag_amplitude) * c2,
        )
    }
}

impl CoefficientModel for WhitneyWood2010 {
    #[inline]
    fn lift_drag(&self, alpha: f64) -> (f64, f64) {
        self.harmonic(alpha)
    }

    #[inline]
    fn lift_drag_slope_branch(&self, alpha: f64, _below: bool) -> ((f64, f64), (f64, f64)) {
        let (s2, c2) = sin_cos(2.0 * alpha);
        (
            (
                self.lift_amplitude * s2,
                self.drag_mean - self.drag_amplitude * c2,
            ),
            (
                2.0 * self.lift_amplitude * c2,
                2.0 * self.drag_amplitude * s2,
            ),
        )
    }

    fn name(&self) -> &'static str {
        "whitney_wood2010"
    }
}

/// One of the built-in models, selectable by name (used by the Python bindings).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CoefficientSet {
    /// [`Dickinson1999`] (default).
    Dickinson1999(Dickinson1999),
    /// [`WhitneyWood2010`].
    WhitneyWood2010(WhitneyWood2010),
}

impl Default for CoefficientSet {
    fn default() -> Self {
        CoefficientSet::Dickinson1999(Dickinson1999)
    }
}

impl CoefficientSet {
    /// [`CoefficientModel::lift_drag_branch`] of one angle or of four in SIMD lanes (`below`
    /// per lane), written once so that every lane computes the scalar bits (the shared
    /// polynomial `sin`/`cos`).
    #[inline]
    pub fn lift_drag_branch_generic<R: Real>(&self, alpha: R, below: R::Mask) -> (R, R) {
        match self {
            CoefficientSet::Dickinson1999(_) => Dickinson1999::fit_branch(alpha, below),
            CoefficientSet::WhitneyWood2010(m) => m.harmonic(alpha),
        }
    }

    /// Names accepted by [`Self::from_name`].
    pub const NAMES: [&'static str; 2] = ["dickinson1999", "whitney_wood2010"];

    /// `"dickinson1999"` or `"whitney_wood2010"` (default constants).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`model`) for any other name.
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "dickinson1999" => Ok(CoefficientSet::Dickinson1999(Dickinson1999)),
            "whitney_wood2010" => Ok(CoefficientSet::WhitneyWood2010(WhitneyWood2010::default())),
            other => Err(Error::invalid(
                "model",
                format!("{other:?}"),
                "one of \"dickinson1999\", \"whitney_wood2010\"",
            )),
        }
    }
}

impl CoefficientModel for CoefficientSet {
    #[inline]
    fn lift_drag(&self, alpha: f64) -> (f64, f64) {
        match self {
            CoefficientSet::Dickinson1999(m) => m.lift_drag(alpha),
            CoefficientSet::WhitneyWood2010(m) => m.lift_drag(alpha),
        }
    }

    fn name(&self) -> &'static str {
        match self {
            CoefficientSet::Dickinson1999(m) => m.name(),
            CoefficientSet::WhitneyWood2010(m) => m.name(),
        }
    }

    fn jumps_at_right_angle(&self) -> bool {
        match self {
            CoefficientSet::Dickinson1999(m) => m.jumps_at_right_angle(),
            CoefficientSet::WhitneyWood2010(m) => m.jumps_at_right_angle(),
        }
    }

    #[inline]
    fn lift_drag_branch(&self, alpha: f64, below: bool) -> (f64, f64) {
        match self {
            CoefficientSet::Dickinson1999(m) => m.lift_drag_branch(alpha, below),
            CoefficientSet::WhitneyWood2010(m) => m.lift_drag_branch(alpha, below),
        }
    }

    #[inline]
    fn lift_drag_slope_branch(&self, alpha: f64, below: bool) -> ((f64, f64), (f64, f64)) {
        match self {
            CoefficientSet::Dickinson1999(m) => m.lift_drag_slope_branch(alpha, below),
            CoefficientSet::WhitneyWood2010(m) => m.lift_drag_slope_branch(alpha, below),
        }
    }
}
