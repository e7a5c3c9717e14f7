//! The HMF four-bar (§2.3.1): a rod-crank, 400 µm of actuator stroke gives 60° by default.

use paritysim_error::Result;
use paritysim_kinematics::drivetrain::HmfFourBar as Linkage;
use paritysim_kinematics::{Drivetrain as Kinematics, RodCrank};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::DrivetrainConfig;

/// HMF four-bar: one DOF, both wings stroke together.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct HmfFourBar {
    /// Crank length (mm), in [1e-6, 10].
    #[schemars(range(min = 1e-6, max = 10.0), extend("x-unit" = "mm"))]
    pub crank_mm: f64,
    /// Rod length (mm), in [1e-6, 100].
    #[schemars(range(min = 1e-6, max = 100.0), extend("x-unit" = "mm"))]
    pub rod_mm: f64,
}

impl Default for HmfFourBar {
    fn default() -> Self {
        Self {
            crank_mm: RodCrank::THESIS.crank(),
            rod_mm: RodCrank::THESIS.rod(),
        }
    }
}

impl DrivetrainConfig for HmfFourBar {
    fn kinematics(&self) -> Result<Kinematics> {
        Ok(Kinematics::HmfFourBar(Linkage::new(RodCrank::new(
            self.crank_mm,
            self.rod_mm,
        )?)))
    }
}
