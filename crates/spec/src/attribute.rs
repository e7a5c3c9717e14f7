//! Model failures that only show while running, attributed to the spec field most responsible
//! for them with the range that avoids them (issue 14): the error keeps its kind (and Python
//! class, `.time`, `.state`) and gains the field ([`Error::Attributed`]).
//!
//! - The rod-crank driven past its reach (the HMF four-bar, the PARITY linkage): the drive
//!   amplitude, with the static bound `force_per_volt · (|offset| + |amplitude|) / stiffness <
//!   reach` ([`RodCrank::reach`]); resonance can make the stroke reach the limit below it.
//! - The shoulder's joint limit (eq. 2.10) during a run: the drive amplitude too (the stroke
//!   grew past the limit).
//! - The step and wall-time budgets: `options.max_steps`, `options.max_wall_ms`.

use paritysim_error::Error;
use paritysim_kinematics::drivetrain::{ROD_CRANK, RodCrank};

use crate::actuator::{Actuator, DcOffset, Waveform};
use crate::spec::Simulation;

/// What the shoulder's out-of-domain error names (`paritysim_kinematics::shoulder`).
const SHOULDER_POSE: &str = "shoulder pose is out of its domain";

impl Simulation {
    /// `err` (from running this spec) attributed to the field most responsible for it, when
    /// one is known; otherwise, or when `err` already names a field, `err` unchanged.
    pub fn attribute(&self, err: Error) -> Error {
        if err.field().is_some() {
            return err;
        }
        let text = err.to_string();
        if text.contains("`options.max_wall_ms`") {
            let ms = self.options.max_wall_ms;
            return err.attributed(
                "options.max_wall_ms",
                ms,
                format!("more than {ms} ms for this point (at most 8.64e7 ms), or a cheaper point"),
            );
        }
        if text.contains("`options.max_steps`") {
            let steps = self.options.max_steps;
            return err.attributed(
                "options.max_steps",
                steps,
                format!("more than {steps} steps for this point (at most 1e9), or a cheaper point"),
            );
        }
        let Some(actuator) = &self.actuator else {
            return err;
        };
        if text.contains(&format!("{ROD_CRANK} is out of its domain")) {
            let rod_crank = self
                .drivetrain
                .as_ref()
                .and_then(|d| d.kinematics().ok())
                .and_then(|k| k.rod_crank());
            if let Some(side) = rod_crank {
                return attribute_reach(err, actuator, side);
            }
        }
        if text.contains(SHOULDER_POSE) {
            let (field, value) = drive_field(actuator);
            return err.attributed(
                field,
                value,
                "smaller: the stroke it drives leaves the shoulder's joint limit (eq. 2.10; \
                 or widen it with wings[i].shoulder.alpha3 - alpha2)",
            );
        }
        err
    }
}

/// The field that sets the drive's size and its value.
fn drive_field(actuator: &Actuator) -> (&'static str, String) {
    match &actuator.waveform {
        Waveform::Sine(s) => ("actuator.waveform.amplitude_v", s.amplitude_v.to_string()),
        Waveform::Sampled(s) => {
            let peak = s.voltages_v.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            ("actuator.waveform.voltages_v", format!("peak {peak} V"))
        }
    }
}

/// The rod-crank left its reach: the drive amplitude with its static bound.
fn attribute_reach(err: Error, actuator: &Actuator, side: RodCrank) -> Error {
    let reach = side.reach();
    let (field, value) = drive_field(actuator);
    let (offset, amplitude) = match &actuator.waveform {
        Waveform::Sine(s) => (s.offset_v, s.amplitude_v.abs()),
        Waveform::Sampled(s) => {
            let peak = s.voltages_v.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            (0.0, peak)
        }
    };
    let offset = match actuator.dc_offset {
        DcOffset::AsForce => offset.abs(),
        DcOffset::Ignore => 0.0,
    };
    let geometry = format!(
        "the rod-crank (crank_mm = {}, rod_mm = {}) reaches a lift of {reach:.4} mm before it \
         toggles (sqrt(L2^2 + 2 L2 L3) - L2)",
        side.crank(),
        side.rod()
    );
    let (k, fpv) = (actuator.stiffness, actuator.force_per_volt);
    let allowed = if k > 0.0 && fpv > 0.0 {
        // Static actuator stroke fpv·(|offset| + |amplitude|)/K against the reach.
        let limit = reach * k / fpv - offset;
        let static_stroke = fpv * (offset + amplitude) / k;
        if limit <= 0.0 {
            format!(
                "none at this offset: {geometry}, and the static stroke of the offset alone, \
                 force_per_volt * |offset_v| / stiffness = {:.4} mm, exceeds it",
                fpv * offset / k
            )
        } else if amplitude >= limit {
            format!(
                "|amplitude| < {limit:.4} V: {geometry}, and the static actuator stroke \
                 force_per_volt * (|offset| + |amplitude|) / stiffness = {static_stroke:.4} mm \
                 exceeds it"
            )
        } else {
            format!(
                "|amplitude| < {limit:.4} V by the static estimate (static stroke \
                 {static_stroke:.4} mm against the reach: {geometry}); near resonance the \
                 dynamic stroke reaches it already at this value, so lower it or move the \
                 frequency away from resonance"
            )
        }
    } else {
        format!("smaller: {geometry}")
    };
    err.attributed(field, value, allowed)
}
