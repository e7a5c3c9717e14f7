//! Which metrics and trajectory columns a device offers, and checking a request against them.

use paritysim_error::{Error, Result};

use crate::device::Device;
use crate::metrics;
use crate::trajectory::column_table;

/// The metric names [`simulate`](crate::simulate()) reports for this device, in order.
pub fn metric_names(device: &Device) -> Vec<String> {
    metrics::names(device)
}

/// The trajectory column names [`simulate`](crate::simulate()) records for this device
/// (without `time_ms`), in order.
pub fn trajectory_columns(device: &Device) -> Vec<String> {
    column_table(device).into_iter().map(|c| c.name).collect()
}

/// Checks requested names against the allowed ones; `None` selects them all.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `field` and listing the valid names.
pub fn select(field: &str, requested: Option<&[String]>, valid: &[String]) -> Result<Vec<String>> {
    let Some(requested) = requested else {
        return Ok(valid.to_vec());
    };
    for name in requested {
        if !valid.contains(name) {
            // A force metric the device does not offer: say why before listing the others.
            let why = if field == "metrics" && name == "actuator_power_per_weight" {
                "a weight: actuator_power_per_weight needs a `body` section (its mass_mg); \
                 otherwise "
            } else if field == "metrics" && metrics::is_force_metric(name) {
                if name == "lift_to_weight" && valid.iter().any(|v| v == "lift_mean") {
                    "a weight: lift_to_weight needs a `body` section (its mass_mg); otherwise "
                } else {
                    "blade-element wings (wings[*].aero.kind = \"blade_element\"): the force \
                     metrics need a force model, and stroke drag (eq. 2.16) is a torque only; \
                     otherwise "
                }
            } else {
                ""
            };
            return Err(Error::invalid(
                field.to_string(),
                format!("{name:?}"),
                format!("{why}one of: {}", valid.join(", ")),
            ));
        }
    }
    Ok(requested.to_vec())
}
