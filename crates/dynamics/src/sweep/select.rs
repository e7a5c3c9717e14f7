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
            let why = if field == "metrics" {
                metrics::unavailable_reason(name, valid).unwrap_or("")
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
