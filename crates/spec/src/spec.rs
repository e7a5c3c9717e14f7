//! The top-level spec: a runnable device plus its simulation options.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::actuator::Actuator;
use crate::body::Body;
use crate::drivetrain::Drivetrain;
use crate::options::Options;
use crate::wing::Wing;

/// How the constraints are enforced.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Formulation {
    /// Drivetrain coordinates when the device allows it, else null space.
    #[default]
    Auto,
    /// Reduced coordinates `p = p_part + N z`.
    NullSpace,
    /// Lagrange-multiplier projection (eq. 3.20).
    Projection,
    /// Integrate the drivetrain coordinates directly (fixed stroking wings only).
    DrivetrainCoordinates,
}

/// Constraints `C p = c0`: a Table 3.1 `name`, or explicit `rows` (and `c0`, zeros by
/// default); neither: unconstrained.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Configuration {
    /// A Table 3.1 configuration name (e.g. `drag_parity_fixed`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Rows of `C` (3 columns per wing).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rows: Option<Vec<Vec<f64>>>,
    /// Right-hand side `c0` (one per row; zeros when absent).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub c0: Option<Vec<f64>>,
}

fn default_configuration() -> Configuration {
    Configuration {
        name: Some("drag_parity_fixed".into()),
        ..Configuration::default()
    }
}

/// A complete, runnable spec (what a TOML file under `examples/` holds).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[schemars(title = "paritysim simulation spec")]
pub struct Simulation {
    /// A label for outputs.
    #[serde(default)]
    pub name: String,
    /// Constraint formulation.
    #[serde(default)]
    pub formulation: Formulation,
    /// Constraints (default: `drag_parity_fixed`).
    #[serde(default = "default_configuration")]
    #[schemars(default = "default_configuration")]
    pub configuration: Configuration,
    /// Drivetrain from the actuator to the stroke angles (required with an actuator).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drivetrain: Option<Drivetrain>,
    /// Piezo actuator on `q1`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub actuator: Option<Actuator>,
    /// One or two wings, left first (eq. 3.21).
    #[schemars(length(min = 1, max = 2))]
    pub wings: Vec<Wing>,
    /// The airframe (absent: the fixed body of the torque stand).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body: Option<Body>,
    /// Integration and steady-state options.
    #[serde(default)]
    pub options: Options,
}

impl Simulation {
    /// A copy with the top-level field `key` read from `field` (that field's JSON), the rest
    /// as in `self`: what reading the whole spec would give when only that field changed, at
    /// the cost of the one field. `None` for a key not listed here (the caller reads the whole
    /// spec).
    pub(crate) fn with_field(&self, key: &str, field: &Value) -> Option<serde_json::Result<Self>> {
        fn read<T: for<'de> Deserialize<'de>>(
            field: &Value,
            into: &mut T,
        ) -> serde_json::Result<()> {
            *into = T::deserialize(field)?;
            Ok(())
        }
        let mut spec = self.clone();
        let read = match key {
            "wings" => read(field, &mut spec.wings),
            "drivetrain" => read(field, &mut spec.drivetrain),
            "actuator" => read(field, &mut spec.actuator),
            "body" => read(field, &mut spec.body),
            "options" => read(field, &mut spec.options),
            _ => return None,
        };
        Some(read.map(|()| spec))
    }
}
