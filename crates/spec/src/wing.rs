//! A wing: shoulder, inertia, named joint springs, tunable hinge and aerodynamics (§3.2.3).

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Spherical five-bar shoulder (§2.3.3): `0 <= alpha3 < alpha2 <= pi` (rad).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Shoulder {
    /// Angle between the stroke and deviation axes of the five-bar (rad), in [1e-6, pi]; pi/2
    /// gives a decoupled shoulder (eq. 2.7).
    #[schemars(range(min = 1e-6, max = std::f64::consts::PI), extend("x-unit" = "rad"))]
    pub alpha2: f64,
    /// Second link angle (rad), in [0, pi), at most `alpha2 - 1e-6` (the closure is singular
    /// as `alpha2 - alpha3 -> 0`) and above `alpha2 - pi` (eq. 2.14 is singular at
    /// `alpha2 - alpha3 = pi`: `alpha2 = pi` needs `alpha3 > 0`).
    #[schemars(range(min = 0.0, max = std::f64::consts::PI), extend("x-unit" = "rad"))]
    pub alpha3: f64,
}

impl Default for Shoulder {
    fn default() -> Self {
        Self {
            alpha2: std::f64::consts::FRAC_PI_2,
            alpha3: 0.0,
        }
    }
}

/// A joint torsion spring `tau = k (g - g0) + k3 (g - g0)^3`.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Spring {
    /// Linear stiffness `k` (mN·mm/rad), in [0, 1e4].
    #[schemars(range(min = 0.0, max = 1e4), extend("x-unit" = "mN mm/rad"))]
    pub stiffness: f64,
    /// Cubic (hardening) stiffness `k3` (mN·mm/rad³), in [0, 1e6].
    #[schemars(range(min = 0.0, max = 1e6), extend("x-unit" = "mN mm/rad^3"))]
    pub cubic: f64,
    /// Rest angle `g0` (rad), in [-pi, pi].
    #[schemars(range(min = -std::f64::consts::PI, max = std::f64::consts::PI), extend("x-unit" = "rad"))]
    pub rest_angle: f64,
}

/// The six shoulder joint springs, named by the joint they act on (joints `γ1..γ6` of
/// §2.3.3; `p = (φ, θ, ψ) = (γ1, γ4, γ6)`). Absent springs are zero.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Springs {
    /// Joint 1, the stroke angle φ.
    pub stroke: Spring,
    /// Joint 2, the passive joint about axis ŝ2.
    pub passive_s2: Spring,
    /// Joint 3, the passive joint about axis ŝ3.
    pub passive_s3: Spring,
    /// Joint 4, the input deviation θ.
    pub deviation: Spring,
    /// Joint 5, the wing deviation θ_w.
    pub wing_deviation: Spring,
    /// Joint 6, the wing hinge (rotation ψ).
    pub hinge: Spring,
    /// Viscous damping `bψ` of the wing hinge (mN·mm·ms/rad), in [0, 1e3]: a torque `−bψ ψ̇`
    /// on ψ. 0 (the default) adds nothing. Taken by the general and stroke-plane forms and free
    /// flight (the free-deviation form declines it).
    #[schemars(range(min = 0.0, max = 1e3), extend("x-unit" = "mN mm ms/rad"))]
    pub hinge_damping: f64,
}

/// The names of [`Springs`] in joint order (joint 1 first).
pub const SPRING_NAMES: [&str; 6] = [
    "stroke",
    "passive_s2",
    "passive_s3",
    "deviation",
    "wing_deviation",
    "hinge",
];

impl Springs {
    /// The springs in joint order.
    pub fn in_joint_order(&self) -> [&Spring; 6] {
        [
            &self.stroke,
            &self.passive_s2,
            &self.passive_s3,
            &self.deviation,
            &self.wing_deviation,
            &self.hinge,
        ]
    }
}

/// Coefficient model of the blade-element aerodynamics.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum CoefficientModel {
    /// Dickinson et al. 1999 (the thesis' model).
    #[default]
    Dickinson1999,
    /// Whitney & Wood 2010.
    WhitneyWood2010,
}

/// How the normal force coefficient enters the blade-element moments.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum NormalForceLaw {
    /// `C_N(α)` of the coefficient model.
    #[default]
    Coefficient,
    /// `C_N = 1`.
    Unit,
}

/// Fixed-wing quadratic drag `tau = -omega1 C sgn(φ̇) φ̇²` (eq. 2.16 with `C = 1`, eq. 3.8 at
/// 90° with `C = C_N(90°)`; docs/errata.md#12).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct StrokeDrag {
    /// Drag parameter Ω1 (mg·mm²), in [0, 1e5].
    #[schemars(range(min = 0.0, max = 1e5), extend("x-unit" = "mg mm^2"))]
    pub omega1: f64,
    /// Dimensionless multiplier `C`, in [0, 10].
    #[schemars(range(min = 0.0, max = 10.0), extend("x-unit" = "1"))]
    pub coefficient: f64,
}

impl Default for StrokeDrag {
    fn default() -> Self {
        Self {
            omega1: 31.3,
            coefficient: 1.0,
        }
    }
}

/// The quasi-steady blade-element model of §3.2.4 (eqs. 3.8-3.11).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct BladeElement {
    /// Ω1 (mg·mm², ½ρ∬z³dA), in (0, 1e5].
    #[schemars(range(max = 1e5), extend("exclusiveMinimum" = 0.0, "x-unit" = "mg mm^2"))]
    pub omega1: f64,
    /// Ω2 (mg·mm², ½ρ∬|x|³dA), in [0, 1e6].
    #[schemars(range(min = 0.0, max = 1e6), extend("x-unit" = "mg mm^2"))]
    pub omega2: f64,
    /// Ω3 (mg·mm², ½ρ∫z²c²dz), in [0, 1e6].
    #[schemars(range(min = 0.0, max = 1e6), extend("x-unit" = "mg mm^2"))]
    pub omega3: f64,
    /// Ω4 (mg·mm²), in [-1e6, 1e6].
    #[schemars(range(min = -1e6, max = 1e6), extend("x-unit" = "mg mm^2"))]
    pub omega4: f64,
    /// The force parameter `½ρ∬z²dA` of the lift and drag forces (mg·mm), in [0, 1e5];
    /// absent: `Ω1 / body.force_radius_mm` (a body-wide estimate, 12 mm by default).
    /// `Wing.from_planform` gives the outline's own (the estimate is 22 % above it on the RoboBee
    /// wing, docs/findings.md §25).
    #[schemars(range(min = 0.0, max = 1e5), extend("x-unit" = "mg mm"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub force_parameter: Option<f64>,
    /// Coefficient model.
    pub model: CoefficientModel,
    /// Rotational damping coefficient (dimensionless), in [0, 100]; absent: the aero crate's
    /// cited default.
    #[schemars(range(min = 0.0, max = 100.0), extend("x-unit" = "1"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rotational_damping: Option<f64>,
    /// Normal-force law.
    pub normal_force_law: NormalForceLaw,
}

impl Default for BladeElement {
    fn default() -> Self {
        Self {
            omega1: StrokeDrag::default().omega1,
            omega2: 0.0,
            omega3: 0.0,
            omega4: 0.0,
            force_parameter: None,
            model: CoefficientModel::default(),
            rotational_damping: None,
            normal_force_law: NormalForceLaw::default(),
        }
    }
}

/// The Whitney & Wood 2010 quasi-steady model (J. Fluid Mech. 660, 197-220): the blade element
/// of §3.2.4 (`omega1..omega4`, `model`, `rotational_damping`, `normal_force_law`, as
/// [`BladeElement`]) plus rotational lift and translational and rotational added mass, from
/// `omega5..omega8` (crates/aero/src/whitney_wood.rs). With the three multipliers 0 it is the
/// blade element.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct WhitneyWood2010 {
    /// Ω1 (mg·mm², ½ρ∬z³dA), in (0, 1e5].
    #[schemars(range(max = 1e5), extend("exclusiveMinimum" = 0.0, "x-unit" = "mg mm^2"))]
    pub omega1: f64,
    /// Ω2 (mg·mm², ½ρ∬|x|³dA), in [0, 1e6].
    #[schemars(range(min = 0.0, max = 1e6), extend("x-unit" = "mg mm^2"))]
    pub omega2: f64,
    /// Ω3 (mg·mm², ½ρ∫z²c²dz), in [0, 1e6].
    #[schemars(range(min = 0.0, max = 1e6), extend("x-unit" = "mg mm^2"))]
    pub omega3: f64,
    /// Ω4 (mg·mm²), in [-1e6, 1e6].
    #[schemars(range(min = -1e6, max = 1e6), extend("x-unit" = "mg mm^2"))]
    pub omega4: f64,
    /// The force parameter `½ρ∬z²dA` of the lift and drag forces (mg·mm), in [0, 1e5];
    /// absent: `Ω1 / body.force_radius_mm` (a body-wide estimate, 12 mm by default).
    /// `Wing.from_planform` gives the outline's own (the estimate is 22 % above it on the RoboBee
    /// wing, docs/findings.md §25).
    #[schemars(range(min = 0.0, max = 1e5), extend("x-unit" = "mg mm"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub force_parameter: Option<f64>,
    /// Ω5 = ½ρ∫ z c² x_m dz, `x_m = l − c/2` the mid-chord (mg·mm²), in [-1e6, 1e6], with
    /// `|Ω5| <= √(Ω3 Ω6)`: the added inertia's stroke-pitch product.
    #[schemars(range(min = -1e6, max = 1e6), extend("x-unit" = "mg mm^2"))]
    pub omega5: f64,
    /// Ω6 = ½ρ∫ c² x_m² dz (mg·mm²), in [0, 1e6]: the normal added mass' pitch inertia.
    #[schemars(range(min = 0.0, max = 1e6), extend("x-unit" = "mg mm^2"))]
    pub omega6: f64,
    /// Ω7 = ½ρ∫ c⁴ dz (mg·mm²), in [0, 1e6]: the pitch added inertia about mid-chord.
    #[schemars(range(min = 0.0, max = 1e6), extend("x-unit" = "mg mm^2"))]
    pub omega7: f64,
    /// Ω8 = ½ρ∫ z c (l − c/4)(¾c − l) dz (mg·mm²), in [-1e6, 1e6]: the rotational lift's
    /// moment about the hinge.
    #[schemars(range(min = -1e6, max = 1e6), extend("x-unit" = "mg mm^2"))]
    pub omega8: f64,
    /// Translational coefficient model (default: Whitney & Wood 2010's `sin 2α` fit).
    pub model: CoefficientModel,
    /// Rotational damping coefficient `C_rd` (dimensionless), in [0, 100]; absent: 5.0 (the
    /// aero crate's default, cited to Whitney & Wood 2010).
    #[schemars(range(min = 0.0, max = 100.0), extend("x-unit" = "1"))]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rotational_damping: Option<f64>,
    /// Normal-force law of the translational term.
    pub normal_force_law: NormalForceLaw,
    /// Rotational-lift multiplier `k_R` of `C_R = π(¾ − x̂₀)` (Whitney & Wood 2010 §2.2,
    /// after Sane & Dickinson 2002), in [0, 10]; 1 is the paper's theoretical value.
    #[schemars(range(min = 0.0, max = 10.0), extend("x-unit" = "1"))]
    pub rotational_lift: f64,
    /// Translational added-mass multiplier `k_t` of the flat plate's `ρπc²/4` per span, in
    /// [0, 10]; 1 is the value Whitney & Wood 2010 use.
    #[schemars(range(min = 0.0, max = 10.0), extend("x-unit" = "1"))]
    pub translational_added_mass: f64,
    /// Rotational added-mass multiplier `k_r` of the flat plate's `ρπc⁴/128` per span (pitch
    /// about mid-chord), in [0, 10]; 1 is the flat-plate value.
    #[schemars(range(min = 0.0, max = 10.0), extend("x-unit" = "1"))]
    pub rotational_added_mass: f64,
}

impl Default for WhitneyWood2010 {
    fn default() -> Self {
        Self {
            omega1: StrokeDrag::default().omega1,
            omega2: 0.0,
            omega3: 0.0,
            omega4: 0.0,
            force_parameter: None,
            omega5: 0.0,
            omega6: 0.0,
            omega7: 0.0,
            omega8: 0.0,
            model: CoefficientModel::WhitneyWood2010,
            rotational_damping: None,
            normal_force_law: NormalForceLaw::default(),
            rotational_lift: paritysim_aero::DEFAULT_ROTATIONAL_LIFT,
            translational_added_mass: paritysim_aero::DEFAULT_TRANSLATIONAL_ADDED_MASS,
            rotational_added_mass: paritysim_aero::DEFAULT_ROTATIONAL_ADDED_MASS,
        }
    }
}

/// Wing aerodynamics (absent: vacuum).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Aero {
    /// Fixed-wing stroke drag.
    StrokeDrag(StrokeDrag),
    /// Quasi-steady blade elements.
    BladeElement(BladeElement),
    /// Whitney & Wood 2010: blade elements plus rotational lift and added mass.
    WhitneyWood2010(WhitneyWood2010),
}

/// The tunable hinge of §2.5.1: `V = ½ k(θ) ψ²` with
/// `k(θ) = stiffness_at_zero + stiffness_slope θ + stiffness_curvature θ²`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TunableHinge {
    /// `k(0)` (mN·mm/rad), in (0, 1e4].
    #[schemars(range(max = 1e4), extend("exclusiveMinimum" = 0.0, "x-unit" = "mN mm/rad"))]
    pub stiffness_at_zero: f64,
    /// `k'(0)` (mN·mm/rad²), in [-1e4, 1e4]; `|slope| < 2 sqrt(k(0) curvature)` keeps k > 0.
    #[schemars(range(min = -1e4, max = 1e4), extend("x-unit" = "mN mm/rad^2"))]
    #[serde(default)]
    pub stiffness_slope: f64,
    /// `½ k''` (mN·mm/rad³), in [0, 1e5].
    #[schemars(range(min = 0.0, max = 1e5), extend("x-unit" = "mN mm/rad^3"))]
    #[serde(default)]
    pub stiffness_curvature: f64,
}

/// A wing.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Wing {
    /// Inertia tensor about the spherical centre in frame 6 (mg·mm², 3×3, symmetric positive
    /// definite), entries in [-1e5, 1e5], principal moments at least 1e-6.
    #[schemars(extend("x-unit" = "mg mm^2"))]
    pub inertia: [[f64; 3]; 3],
    /// Shoulder.
    #[serde(default)]
    pub shoulder: Shoulder,
    /// Joint springs (absent: none).
    #[serde(default)]
    pub springs: Springs,
    /// Aerodynamics (absent: vacuum).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aero: Option<Aero>,
    /// Tunable hinge (absent: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tunable_hinge: Option<TunableHinge>,
}

impl Default for Aero {
    fn default() -> Self {
        Aero::StrokeDrag(StrokeDrag::default())
    }
}
