//! One actuator per wing on linear or polynomial transmissions (beyond the thesis, issue 35):
//! the layout of every RoboBee since 2013.

use paritysim_error::Result;
use paritysim_kinematics::Drivetrain as Kinematics;
use paritysim_kinematics::drivetrain::DualLinear as Linear;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::DrivetrainConfig;
use super::polynomial::polynomial;

/// A linear (or polynomial) drive per wing: `φL = P(−q1)`, `φR = P(−q2)` with
/// `P(σ) = τ1 σ + τ2 σ³/3 + a5 σ⁵ + ...` (2 DOF; both driven by the `[actuator]`, scaled per
/// side by `actuator.side_gain` and `actuator.side_offset_v`, each with the actuator's
/// stiffness). Use with `configuration = "drag_parity"` or `"drag_parity_fixed"` (independent
/// strokes).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct DualLinear {
    /// Transmission ratio τ1 (rad/mm), in [1e-6, 100].
    #[schemars(range(min = 1e-6, max = 100.0), extend("x-unit" = "rad/mm"))]
    pub transmission_ratio: f64,
    /// Cubic transmission term τ2 (rad/mm³) of `φ = τ1 σ + τ2 σ³/3`, in [-1e4, 1e4]; 0 is the
    /// linear map. A negative τ2 folds over at `σ = √(τ1/|τ2|)` (refused there).
    #[schemars(range(min = -1e4, max = 1e4), extend("x-unit" = "rad/mm^3"))]
    pub cubic_ratio: f64,
    /// Coefficients of `σ⁵, σ⁷, σ⁹` (rad/mm⁵, rad/mm⁷, rad/mm⁹), at most 3, each in [-1e6, 1e6].
    #[schemars(
        inner(range(min = -1e6, max = 1e6)),
        length(max = 3),
        extend("x-unit" = "rad/mm^(2j+5)")
    )]
    pub higher_odd_ratios: Vec<f64>,
}

impl Default for DualLinear {
    fn default() -> Self {
        Self {
            transmission_ratio: 2.5,
            cubic_ratio: 0.0,
            higher_odd_ratios: Vec::new(),
        }
    }
}

impl DrivetrainConfig for DualLinear {
    fn kinematics(&self) -> Result<Kinematics> {
        let p = polynomial(
            self.transmission_ratio,
            self.cubic_ratio,
            &self.higher_odd_ratios,
        )?;
        Ok(Kinematics::DualLinear(Linear::new(
            self.transmission_ratio,
            p,
        )?))
    }
}
