//! Two four-bars, one actuator per wing (beyond the thesis, issue 17): the dual-actuator
//! layout of later flapping robots, here to compare per-side drive control with PARITY.

use paritysim_error::Result;
use paritysim_kinematics::drivetrain::DualFourBar as Linkage;
use paritysim_kinematics::{Drivetrain as Kinematics, RodCrank};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::DrivetrainConfig;

/// Dual four-bar: each wing its own HMF rod-crank and its own drive (`q1` left, `q2` right;
/// both driven by the `[actuator]`, scaled per side by `actuator.side_gain` and
/// `actuator.side_offset_v`). Use with `configuration = "drag_parity"` (independent strokes).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct DualFourBar {
    /// Crank length (mm), in [1e-6, 10].
    #[schemars(range(min = 1e-6, max = 10.0), extend("x-unit" = "mm"))]
    pub crank_mm: f64,
    /// Rod length (mm), in [1e-6, 100].
    #[schemars(range(min = 1e-6, max = 100.0), extend("x-unit" = "mm"))]
    pub rod_mm: f64,
}

impl Default for DualFourBar {
    fn default() -> Self {
        Self {
            crank_mm: RodCrank::THESIS.crank(),
            rod_mm: RodCrank::THESIS.rod(),
        }
    }
}

impl DrivetrainConfig for DualFourBar {
    fn kinematics(&self) -> Result<Kinematics> {
        Ok(Kinematics::DualFourBar(Linkage::new(RodCrank::new(
            self.crank_mm,
            self.rod_mm,
        )?)))
    }
}
