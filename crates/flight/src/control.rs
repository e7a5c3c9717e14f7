//! Slow control of the drivetrain (thesis §5.1, eq. 5.1): time-varying set points on the
//! whippletree (a pivot bias torque, or the torque ratio `q3` itself), on the actuator (common
//! or, on a dual drivetrain, per side) and a PD controller on the body attitude running at a
//! control rate (zero-order hold between ticks).
//!
//! **Eq. 5.1 as an input** ([`ControlInput::LogQ3`], value `u = ln q3`): a whippletree load
//! `Q2 = Q1 (J01 q3 + J11) / (J00 q3 + J10)` (`J = ∂φ/∂q`, `Q1` the whole load on `q1`) makes
//! the drivetrain's stroke torques `τ = J⁻ᵀ Q` satisfy `τL/τR = q3` at every instant (without
//! a balance spring; `J00 q3 + J10 ≠ 0` for the differentials), a "virtual moving pivot":
//! for the linear differential it is the load of the arm ratio `hL/hR = 1/q3` of §2.4.2
//! without changing the linkage. `ln q3` keeps the mirror symmetry `q3 ↔ 1/q3` as `u ↔ −u`
//! and lets set points and controllers add.

use paritysim_error::{Error, Result, check_finite, check_positive};

/// What a controller (or a set point) drives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ControlInput {
    /// A bias torque on the whippletree `q2` (mN·mm): moves the balance point of the Drag
    /// PARITY differential like the biased pivot of §2.4.2 (the `q3` of eq. 5.1).
    Q2Bias,
    /// An added actuator force on `q1` (mN): the DC offset of the drive.
    ActuatorOffset,
    /// A relative change of the actuator force amplitude (1 = +100 %).
    ActuatorGain,
    /// `ln q3` of eq. 5.1: the whippletree holds `τL/τR = q3` (a 2-DOF differential).
    LogQ3,

    /// Dual drivetrain: relative change of the left drive's force (1 = +100 %).
    SideGainLeft,
    /// Dual drivetrain: relative change of the right drive's force.
    SideGainRight,
    /// Dual drivetrain: added force on the left drive (mN).
    SideOffsetLeft,
    /// Dual drivetrain: added force on the right drive (mN).
    SideOffsetRight,
    /// Dual drivetrain: `+u` on the left drive's relative force, `−u` on the right one's.
    SideGainDifference,
    /// Dual drivetrain: `+u` mN on the left drive, `−u` on the right one.
    SideOffsetDifference,
}

impl ControlInput {
    /// Every input with its spec name (`[[body.set_points]] input = "..."`).
    pub const NAMES: [(&'static str, ControlInput); 10] = [
        ("q2_bias", ControlInput::Q2Bias),
        ("actuator_offset", ControlInput::ActuatorOffset),
        ("actuator_gain", ControlInput::ActuatorGain),
        ("log_q3", ControlInput::LogQ3),
        ("side_gain_left", ControlInput::SideGainLeft),
        ("side_gain_right", ControlInput::SideGainRight),
        ("side_offset_left", ControlInput::SideOffsetLeft),
        ("side_offset_right", ControlInput::SideOffsetRight),
        ("side_gain_difference", ControlInput::SideGainDifference),
        ("side_offset_difference", ControlInput::SideOffsetDifference),
    ];

    /// Inputs from `(name, value)` pairs (an external controller's output), summed per name.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `controller[name]` for an unknown name or a
    /// non-finite value.
    pub fn inputs_from_named(pairs: &[(String, f64)]) -> Result<crate::model::Inputs> {
        let mut inputs = crate::model::Inputs::default();
        for (name, value) in pairs {
            let field = format!("controller[{name:?}]");
            let Some((_, input)) = Self::NAMES.iter().find(|(n, _)| n == name) else {
                let names: Vec<&str> = Self::NAMES.iter().map(|(n, _)| *n).collect();
                return Err(Error::invalid(
                    field,
                    value,
                    format!("one of {}", names.join(", ")),
                ));
            };
            if !value.is_finite() {
                return Err(Error::invalid(field, value, "a finite number"));
            }
            input.add_to(&mut inputs, *value);
        }
        Ok(inputs)
    }

    /// Whether the input acts through the whippletree of a 2-DOF differential (not a dual
    /// drivetrain): [`ControlInput::Q2Bias`] and [`ControlInput::LogQ3`].
    pub fn needs_whippletree(self) -> bool {
        matches!(self, ControlInput::Q2Bias | ControlInput::LogQ3)
    }

    /// Whether the input drives one side of a dual drivetrain.
    pub fn needs_dual(self) -> bool {
        matches!(
            self,
            ControlInput::SideGainLeft
                | ControlInput::SideGainRight
                | ControlInput::SideOffsetLeft
                | ControlInput::SideOffsetRight
                | ControlInput::SideGainDifference
                | ControlInput::SideOffsetDifference
        )
    }

    /// Adds `value` of this input to `inputs`.
    pub fn add_to(self, inputs: &mut crate::model::Inputs, value: f64) {
        match self {
            ControlInput::Q2Bias => inputs.q2_bias += value,
            ControlInput::ActuatorOffset => inputs.actuator_offset += value,
            ControlInput::ActuatorGain => inputs.actuator_gain += value,
            ControlInput::LogQ3 => inputs.log_q3 += value,
            ControlInput::SideGainLeft => inputs.side_gain[0] += value,
            ControlInput::SideGainRight => inputs.side_gain[1] += value,
            ControlInput::SideOffsetLeft => inputs.side_offset[0] += value,
            ControlInput::SideOffsetRight => inputs.side_offset[1] += value,
            ControlInput::SideGainDifference => {
                inputs.side_gain[0] += value;
                inputs.side_gain[1] -= value;
            }
            ControlInput::SideOffsetDifference => {
                inputs.side_offset[0] += value;
                inputs.side_offset[1] -= value;
            }
        }
    }
}

/// How a [`SetPoint`] fills the time between its nodes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Interpolation {
    /// Piecewise linear.
    #[default]
    Linear,
    /// Piecewise constant: the value of the last node at or before `t` (steps at the nodes).
    Previous,
}

/// A schedule `u(t)` (t in ms from the release): piecewise linear or piecewise constant
/// between its nodes, held constant outside them, or repeated with a period (a
/// stroke-synchronous schedule with the drive's period).
#[derive(Clone, Debug, PartialEq)]
pub struct SetPoint {
    /// What it drives.
    pub input: ControlInput,
    /// Times (ms), increasing (within `[0, period)` when periodic).
    pub times: Vec<f64>,
    /// Values at those times.
    pub values: Vec<f64>,
    /// Between the nodes.
    pub interpolation: Interpolation,
    /// Repeat period (ms), if any.
    pub period: Option<f64>,
}

impl SetPoint {
    /// A validated piecewise-linear schedule.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for different lengths, no point, non-increasing times or
    /// non-finite values.
    pub fn new(input: ControlInput, times: Vec<f64>, values: Vec<f64>) -> Result<Self> {
        if times.is_empty() || times.len() != values.len() {
            return Err(Error::invalid(
                "values",
                values.len(),
                format!("one value per time ({} times, at least one)", times.len()),
            ));
        }
        for w in times.windows(2) {
            if w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater) {
                return Err(Error::invalid("times_ms", w[1], "increasing times"));
            }
        }
        for v in times.iter().chain(&values) {
            check_finite("times_ms and values", *v)?;
        }
        Ok(Self {
            input,
            times,
            values,
            interpolation: Interpolation::Linear,
            period: None,
        })
    }

    /// The same schedule with another interpolation.
    pub fn with_interpolation(mut self, interpolation: Interpolation) -> Self {
        self.interpolation = interpolation;
        self
    }

    /// The same schedule repeated every `period_ms` (its times must lie in `[0, period_ms)`).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] (`set_point.period_ms`) for a non-positive period or a time
    /// outside `[0, period_ms)`.
    pub fn with_period(mut self, period_ms: f64) -> Result<Self> {
        check_positive("period_ms", period_ms)?;
        if let Some(t) = self.times.iter().find(|&&t| !(0.0..period_ms).contains(&t)) {
            return Err(Error::invalid(
                "times_ms",
                *t,
                format!("in [0, period_ms = {period_ms}) for a periodic schedule"),
            ));
        }
        self.period = Some(period_ms);
        Ok(self)
    }

    /// `u(t)`.
    pub fn value(&self, t: f64) -> f64 {
        let n = self.times.len();
        let tau = self.period.map_or(t, |p| t.rem_euclid(p));
        let k = self.times.partition_point(|&s| s <= tau);
        let (i0, t0, i1, t1) = match (k, self.period) {
            (0, None) => return self.values[0],
            (k, None) if k == n => return self.values[n - 1],
            (0, Some(p)) => (n - 1, self.times[n - 1] - p, 0, self.times[0]),
            (k, Some(p)) if k == n => (n - 1, self.times[n - 1], 0, self.times[0] + p),
            (k, _) => (k - 1, self.times[k - 1], k, self.times[k]),
        };
        match self.interpolation {
            Interpolation::Previous => self.values[i0],
            Interpolation::Linear if t1 <= t0 => self.values[i0],
            Interpolation::Linear => {
                let s = (tau - t0) / (t1 - t0);
                self.values[i0] + s * (self.values[i1] - self.values[i0])
            }
        }
    }

    /// The first node strictly after `t + tol` (ms; infinite when there is none): integration
    /// legs end there so that no step straddles a kink or a jump of the schedule.
    pub fn next_node(&self, t: f64, tol: f64) -> f64 {
        let Some(p) = self.period else {
            return self
                .times
                .iter()
                .copied()
                .find(|&s| s > t + tol)
                .unwrap_or(f64::INFINITY);
        };
        let base = (t / p).floor() * p;
        (0..3)
            .flat_map(|k| self.times.iter().map(move |&s| base + k as f64 * p + s))
            .find(|&s| s > t + tol)
            .unwrap_or(f64::INFINITY)
    }
}

/// A PD controller on one body attitude angle: `u = −kp (angle − target) − kd (rate −
/// target_rate)`, sampled every `1 / rate_hz` and held (saturated to `±limit`); with `kp = 0`
/// a rate controller holding `target_rate`. With a `shape` the input is `u · shape(t)`: the
/// controller sets the amplitude of a schedule (e.g. a stroke-synchronous ±1 for eq. 5.1).
#[derive(Clone, Debug, PartialEq)]
pub struct Control {
    /// What it drives.
    pub input: ControlInput,
    /// Body axis: 0 roll (x̂), 1 yaw (ŷ), 2 pitch (ẑ).
    pub axis: usize,
    /// Target angle (rad).
    pub target: f64,
    /// Proportional gain (input unit per rad).
    pub kp: f64,
    /// Derivative gain (input unit per rad/ms).
    pub kd: f64,
    /// Target rate about the axis (rad/ms).
    pub target_rate: f64,
    /// Control rate (Hz).
    pub rate_hz: f64,
    /// Saturation of the output (input unit).
    pub limit: f64,
    /// A schedule (its input is ignored) the output multiplies.
    pub shape: Option<SetPoint>,
}

impl Control {
    /// Validates the gains and the rate.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the field.
    pub fn validate(&self) -> Result<()> {
        let at = |e: Error| e.in_field("body.control");
        check_finite("kp", self.kp).map_err(at)?;
        check_finite("kd", self.kd).map_err(at)?;
        check_finite("target", self.target).map_err(at)?;
        check_finite("target_rate_rad_per_ms", self.target_rate).map_err(at)?;
        check_positive("rate_hz", self.rate_hz).map_err(at)?;
        check_positive("limit", self.limit).map_err(at)?;
        if self.axis > 2 {
            return Err(Error::invalid("body.control.axis", self.axis, "0, 1 or 2"));
        }
        Ok(())
    }

    /// Control period (ms).
    pub fn period_ms(&self) -> f64 {
        1000.0 / self.rate_hz
    }

    /// The output for attitude angle `angle` and rate `rate` about the controlled axis.
    pub fn output(&self, angle: f64, rate: f64) -> f64 {
        (-self.kp * (angle - self.target) - self.kd * (rate - self.target_rate))
            .clamp(-self.limit, self.limit)
    }
}
