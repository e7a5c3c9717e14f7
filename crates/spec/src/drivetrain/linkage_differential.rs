//! The Drag PARITY linkage differential (§3.3.2): a rod-crank driving a whippletree.

use paritysim_error::Result;
use paritysim_kinematics::drivetrain::LinkageDifferential as Linkage;
use paritysim_kinematics::{Drivetrain as Kinematics, RodCrank};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::DrivetrainConfig;

/// The §3.3.2 linkage (lengths by default), 2 DOF.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct LinkageDifferential {
    /// Crank length (mm), in [1e-6, 10].
    #[schemars(range(min = 1e-6, max = 10.0), extend("x-unit" = "mm"))]
    pub crank_mm: f64,
    /// Rod length (mm), in [1e-6, 100].
    #[schemars(range(min = 1e-6, max = 100.0), extend("x-unit" = "mm"))]
    pub rod_mm: f64,
    /// Whippletree length (mm), in [1e-6, 100].
    #[schemars(range(min = 1e-6, max = 100.0), extend("x-unit" = "mm"))]
    pub whippletree_length_mm: f64,
    /// Arm ratio hL/hR (§2.4.2), in (0, 100].
    #[schemars(range(max = 100.0), extend("exclusiveMinimum" = 0.0, "x-unit" = "1"))]
    pub arm_ratio: f64,
    /// Balance-beam spring K2 on `q2` (mN·mm/rad), in [0, 1e4] (docs/errata.md#14).
    #[schemars(range(min = 0.0, max = 1e4), extend("x-unit" = "mN mm/rad"))]
    pub balance_spring: f64,
    /// Preload torque P on the whippletree `q2` (mN·mm), in [-100, 100]: the drive load on `q2`
    /// is `P − K2 q2`, so a whippletree at rest settles at `q2 = P / K2` (needs K2 > 0 to hold).
    #[schemars(range(min = -100.0, max = 100.0), extend("x-unit" = "mN mm"))]
    pub balance_preload: f64,
    /// Viscous damping `b2` of the whippletree `q2` (the stroke flexure / balance spring;
    /// mN·mm·ms/rad), in [0, 1e3]: a torque `−b2 q̇2`; 0 (the default) adds nothing.
    #[schemars(range(min = 0.0, max = 1e3), extend("x-unit" = "mN mm ms/rad"))]
    pub balance_damping: f64,
    /// Cubic (hardening) stiffness `K2c` of the balance spring on `q2` (mN·mm/rad³), in
    /// [0, 1e6]: a torque `−K2c q2³`; 0 (the default) adds nothing.
    #[schemars(range(min = 0.0, max = 1e6), extend("x-unit" = "mN mm/rad^3"))]
    pub balance_cubic: f64,
}

impl Default for LinkageDifferential {
    fn default() -> Self {
        Self {
            crank_mm: RodCrank::THESIS.crank(),
            rod_mm: RodCrank::THESIS.rod(),
            whippletree_length_mm: Linkage::THESIS_WHIPPLETREE_LENGTH_MM,
            arm_ratio: 1.0,
            balance_spring: 0.0,
            balance_preload: 0.0,
            balance_damping: 0.0,
            balance_cubic: 0.0,
        }
    }
}

impl DrivetrainConfig for LinkageDifferential {
    fn kinematics(&self) -> Result<Kinematics> {
        Ok(Kinematics::LinkageDifferential(Linkage::new(
            RodCrank::new(self.crank_mm, self.rod_mm)?,
            self.whippletree_length_mm,
            self.arm_ratio,
        )?))
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
