//! Slow control of the drivetrain (thesis §5.1, eq. 5.1): a time-varying set point on the
//! whippletree (a pivot bias torque standing in for `q3 ≠ 1`) and a PD controller on the
//! body attitude running at a control rate (zero-order hold between ticks).

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
}

/// A piecewise-linear schedule `u(t)` (held constant outside the given times).
#[derive(Clone, Debug, PartialEq)]
pub struct SetPoint {
    /// What it drives.
    pub input: ControlInput,
    /// Times (ms), increasing.
    pub times: Vec<f64>,
    /// Values at those times.
    pub values: Vec<f64>,
}

impl SetPoint {
    /// A validated schedule.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for different lengths, no point, non-increasing times or
    /// non-finite values.
    pub fn new(input: ControlInput, times: Vec<f64>, values: Vec<f64>) -> Result<Self> {
        if times.is_empty() || times.len() != values.len() {
            return Err(Error::invalid(
                "set_point.values",
                values.len(),
                format!("one value per time ({} times, at least one)", times.len()),
            ));
        }
        for w in times.windows(2) {
            if w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater) {
                return Err(Error::invalid(
                    "set_point.times_ms",
                    w[1],
                    "increasing times",
                ));
            }
        }
        for v in times.iter().chain(&values) {
            check_finite("set_point", *v)?;
        }
        Ok(Self {
            input,
            times,
            values,
        })
    }

    /// `u(t)`.
    pub fn value(&self, t: f64) -> f64 {
        let k = self.times.partition_point(|&s| s <= t);
        if k == 0 {
            return self.values[0];
        }
        if k == self.times.len() {
            return self.values[k - 1];
        }
        let (t0, t1) = (self.times[k - 1], self.times[k]);
        let s = (t - t0) / (t1 - t0);
        self.values[k - 1] + s * (self.values[k] - self.values[k - 1])
    }
}

/// A PD controller on one body attitude angle: `u = −kp (angle − target) − kd rate`, sampled
/// every `1 / rate_hz` and held (saturated to `±limit`).
#[derive(Clone, Copy, Debug, PartialEq)]
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
    /// Control rate (Hz).
    pub rate_hz: f64,
    /// Saturation of the output (input unit).
    pub limit: f64,
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
        (-self.kp * (angle - self.target) - self.kd * rate).clamp(-self.limit, self.limit)
    }
}
