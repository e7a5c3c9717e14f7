//! What the asked metrics need from a sample: the metric-name knowledge the lean
//! [`crate::trajectory::StrokeSample`] and the accumulator share (its own file so neither
//! imports the other for it).

/// Metrics read from the work integrals (`lift_per_power` reads the forces too).
const WORK_METRICS: [&str; 7] = [
    "work_actuator_per_cycle",
    "work_aero_per_cycle",
    "mean_actuator_power",
    "aero_power_mean",
    "actuator_power_mean",
    "actuator_power_per_weight",
    "lift_per_power",
];

/// What a [`crate::trajectory::StrokeSample`] computes beyond the stroke kinematics, as the
/// asked metrics need.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StrokeNeeds {
    /// The actuator force (`actuator_force_peak`).
    pub force: bool,
    /// The body reaction torques: per-wing and net `{roll,yaw,pitch}_{mean,rms,peak}` (the
    /// stroke accelerations, so one drivetrain solve per sample; the force comes with them).
    pub torques: bool,
    /// The work integrals (`work_*_per_cycle`, `mean_actuator_power`, `*_power_mean`,
    /// `lift_per_power`): the recorded window integrates them.
    pub work: bool,
    /// The wings' aerodynamic forces ([`is_force_metric`]: `lift_mean`, ...; `lift_per_power`,
    /// `lift_to_weight`): evaluated from the sample's `(p, ṗ)`.
    pub forces: bool,
}

impl StrokeNeeds {
    /// Everything (every metric).
    pub const ALL: Self = Self {
        force: true,
        torques: true,
        work: true,
        forces: true,
    };

    /// What the metrics `names` need (`None`: all of them). Unknown names count as torque
    /// metrics (they are reported NaN by the caller's selection).
    pub fn of(names: Option<&[String]>) -> Self {
        let Some(names) = names else {
            return Self::ALL;
        };
        let mut needs = Self {
            force: false,
            torques: false,
            work: false,
            forces: false,
        };
        for name in names {
            if is_force_metric(name) {
                needs.forces = true;
            }
            if name == "actuator_force_peak" {
                needs.force = true;
            } else if WORK_METRICS.contains(&name.as_str()) {
                needs.work = true;
            } else if !is_stroke_metric(name) && !is_force_metric(name) {
                needs.torques = true;
            }
        }
        // The torques solve the drivetrain dynamics, which evaluate the force anyway.
        needs.force |= needs.torques;
        needs
    }

    /// Whether samples computing this much give metric `name`.
    pub fn provides(&self, name: &str) -> bool {
        if name == "actuator_force_peak" {
            self.force
        } else if name == "lift_per_power" {
            self.work && self.forces
        } else if WORK_METRICS.contains(&name) {
            self.work
        } else if is_force_metric(name) {
            self.forces
        } else {
            is_stroke_metric(name) || self.torques
        }
    }
}

/// Metrics a [`crate::trajectory::StrokeSample`] suffices for (fixed wings in drivetrain coordinates): stroke
/// angles, drag roll torques, Table 3.2, `q2_amplitude`, `actuator_force_peak` (the rotation
/// metrics are those of ψ ≡ 0).
pub fn is_stroke_metric(name: &str) -> bool {
    const WING: [&str; 8] = [
        "stroke_amplitude",
        "stroke_peak_to_peak",
        "stroke_mean",
        "rotation_amplitude",
        "rotation_mean",
        "rotation_phase_lag",
        "roll_aero_peak",
        "roll_aero_mean",
    ];
    const DEVICE: [&str; 7] = [
        "actuator_force_peak",
        "q2_amplitude",
        "delta_tau_peak",
        "tau_l_peak",
        "tau_r_peak",
        "imbalance_instantaneous_pct",
        "imbalance_peak_pct",
    ];
    let wing = ["left_", "right_", "wing_"]
        .iter()
        .find_map(|p| name.strip_prefix(p));
    match wing {
        Some(rest) => WING.contains(&rest),
        None => DEVICE.contains(&name),
    }
}

/// Force metrics (the wings' aerodynamic force in the body frame, `crate::metrics::forces`):
/// `{left,right,wing}_{lift,aero_force_y,aero_force_z}_{mean,rms,peak}`, their net
/// `{lift,aero_force_y,aero_force_z}_{mean,rms,peak}`, `aero_force_peak`, `lift_per_power`
/// and `lift_to_weight`.
pub fn is_force_metric(name: &str) -> bool {
    if matches!(
        name,
        "aero_force_peak" | "lift_per_power" | "lift_to_weight"
    ) {
        return true;
    }
    let rest = ["left_", "right_", "wing_"]
        .iter()
        .find_map(|p| name.strip_prefix(p))
        .unwrap_or(name);
    ["lift_", "aero_force_y_", "aero_force_z_"]
        .iter()
        .find_map(|a| rest.strip_prefix(a))
        .is_some_and(|stat| matches!(stat, "mean" | "rms" | "peak"))
}

/// Why a device does not offer the force or weight metric `name` (`valid`: the metrics it
/// offers), as the start of an error's "must be" text, or `None` for any other name.
pub fn unavailable_reason(name: &str, valid: &[String]) -> Option<&'static str> {
    let weighed = matches!(name, "lift_to_weight" | "actuator_power_per_weight");
    if weighed && (name == "actuator_power_per_weight" || valid.iter().any(|v| v == "lift_mean")) {
        Some("a weight: the ratios to the weight need a `body` section (its mass_mg); otherwise ")
    } else if is_force_metric(name) {
        Some(
            "blade-element wings (wings[*].aero.kind = \"blade_element\"): the force metrics \
             need a force model, and stroke drag (eq. 2.16) is a torque only; otherwise ",
        )
    } else {
        None
    }
}
