//! The linearised differential of eq. 2.15.

use paritysim_error::Result;
use paritysim_kinematics::Drivetrain as Kinematics;
use paritysim_kinematics::drivetrain::LinearDifferential as Linear;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::DrivetrainConfig;
use super::polynomial::polynomial;

/// `φ_{L,R} = T (q1 ± h_{L,R} q2)`-type linear differential (eq. 2.15), 2 DOF.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct LinearDifferential {
    /// Transmission ratio T (rad/mm), in [1e-6, 100].
    #[schemars(range(min = 1e-6, max = 100.0), extend("x-unit" = "rad/mm"))]
    pub transmission_ratio: f64,
    /// Mean arm length L (mm), in [1e-6, 100].
    #[schemars(range(min = 1e-6, max = 100.0), extend("x-unit" = "mm"))]
    pub arm_length_mm: f64,
    /// Arm ratio hL/hR, in (0, 100].
    #[schemars(range(max = 100.0), extend("exclusiveMinimum" = 0.0, "x-unit" = "1"))]
    pub arm_ratio: f64,
    /// Balance-beam spring K2 on `q2` (mN·mm/rad), in [0, 1e4] (docs/errata.md#14).
    #[schemars(range(min = 0.0, max = 1e4), extend("x-unit" = "mN mm/rad"))]
    pub balance_spring: f64,
    /// Preload torque P on the whippletree `q2` (mN·mm), in [-100, 100]: the drive load on `q2`
    /// is `P − K2 q2`, so a whippletree at rest settles at `q2 = P / K2` (needs K2 > 0 to hold).
    #[schemars(range(min = -100.0, max = 100.0), extend("x-unit" = "mN mm"))]
    pub balance_preload: f64,
    /// Cubic transmission term τ2 (rad/mm³), in [-1e4, 1e4]: each wing's stroke is
    /// `τ1 σ + τ2 σ³/3` of its rod-top displacement `σ` (eq. 2.15's stroke over τ1); 0 is
    /// eq. 2.15. A negative τ2 folds over at `σ = √(τ1/|τ2|)` (refused there).
    #[schemars(range(min = -1e4, max = 1e4), extend("x-unit" = "rad/mm^3"))]
    pub cubic_ratio: f64,
    /// Coefficients of `σ⁵, σ⁷, σ⁹` (rad/mm⁵, rad/mm⁷, rad/mm⁹), at most 3, each in [-1e6, 1e6].
    #[schemars(
        inner(range(min = -1e6, max = 1e6)),
        length(max = 3),
        extend("x-unit" = "rad/mm^(2j+5)")
    )]
    pub higher_odd_ratios: Vec<f64>,
    /// Viscous damping `b2` of the whippletree `q2` (the stroke flexure / balance spring;
    /// mN·mm·ms/rad), in [0, 1e3]: a torque `−b2 q̇2`; 0 (the default) adds nothing.
    #[schemars(range(min = 0.0, max = 1e3), extend("x-unit" = "mN mm ms/rad"))]
    pub balance_damping: f64,
    /// Cubic (hardening) stiffness `K2c` of the balance spring on `q2` (mN·mm/rad³), in
    /// [0, 1e6]: a torque `−K2c q2³`; 0 (the default) adds nothing.
    #[schemars(range(min = 0.0, max = 1e6), extend("x-unit" = "mN mm/rad^3"))]
    pub balance_cubic: f64,
}

impl Default for LinearDifferential {
    fn default() -> Self {
        Self {
            transmission_ratio: 2.5,
            arm_length_mm: 2.5,
            arm_ratio: 1.0,
            balance_spring: 0.0,
            balance_preload: 0.0,
            cubic_ratio: 0.0,
            higher_odd_ratios: Vec::new(),
            balance_damping: 0.0,
            balance_cubic: 0.0,
        }
    }
}

impl DrivetrainConfig for LinearDifferential {
    fn kinematics(&self) -> Result<Kinematics> {
        let p = polynomial(
            self.transmission_ratio,
            self.cubic_ratio,
            &self.higher_odd_ratios,
        )?;
        Ok(Kinematics::LinearDifferential(
            Linear::new(self.transmission_ratio, self.arm_length_mm, self.arm_ratio)?
                .with_polynomial(p),
        ))
    }

    fn balance_spring(&self) -> f64 {
        self.balance_spring
    }

    fn balance_preload(&self) -> f64 {
        self.balance_preload
    }

    fn balance_damping(&self) -> f64 {
        self.balance_damping
    }

    fn balance_cubic(&self) -> f64 {
        self.balance_cubic
    }
}
