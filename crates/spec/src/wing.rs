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
    /// Second link angle (rad), in [0, pi) and at most `alpha2 - 1e-6` (the closure is singular
    /// as `alpha2 - alpha3 -> 0`).
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
    /// Ω1 (mg·mm²), in [0, 1e5].
    #[schemars(range(min = 0.0, max = 1e5), extend("x-unit" = "mg mm^2"))]
    pub omega1: f64,
    /// Ω2 (mg·mm), in [-1e6, 1e6].
    #[schemars(range(min = -1e6, max = 1e6), extend("x-unit" = "mg mm"))]
    pub omega2: f64,
    /// Ω3 (mg·mm²), in [-1e6, 1e6].
    #[schemars(range(min = -1e6, max = 1e6), extend("x-unit" = "mg mm^2"))]
    pub omega3: f64,
    /// Ω4 (mg·mm²), in [-1e6, 1e6].
    #[schemars(range(min = -1e6, max = 1e6), extend("x-unit" = "mg mm^2"))]
    pub omega4: f64,
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
            model: CoefficientModel::default(),
            rotational_damping: None,
            normal_force_law: NormalForceLaw::default(),
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
