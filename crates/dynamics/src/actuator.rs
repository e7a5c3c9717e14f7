//! Zeroth-order piezoelectric actuator (§3.2.2 item 4): a voltage-proportional force in
//! parallel with a linear spring, acting on the drivetrain input `q1`.
//!
//! Thesis values (§3.3.1): stiffness 467 mN/mm, 120 mN amplitude at 100 V (1.2 mN/V).

use paritysim_error::{Error, Result, bail, check_finite, check_non_negative, check_positive};
use paritysim_laminate::ActuatorConstants;

/// How the DC part of the drive voltage enters (docs/errata.md#14: not specified by the thesis).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DcOffset {
    /// The offset produces a static force (shifts the equilibrium of `q1`).
    #[default]
    AsForce,
    /// The offset only biases the piezo (unipolar drive) and produces no net force.
    Ignore,
}

/// Drive voltage `V(t)`; time in ms.
#[derive(Clone, Debug, PartialEq)]
pub enum Waveform {
    /// `V(t) = offset + amplitude · sin(2π f t + phase)` (eq. 3.24), `f` in kHz (1/ms).
    Sine {
        /// Amplitude (V).
        amplitude_v: f64,
        /// Frequency (kHz = cycles per ms).
        frequency_khz: f64,
        /// DC offset (V).
        offset_v: f64,
        /// Phase (rad).
        phase: f64,
    },
    /// One period of samples, linearly interpolated and repeated with `period_ms`.
    Sampled {
        /// Sample times in `[0, period_ms)`, strictly increasing (ms).
        times_ms: Vec<f64>,
        /// Voltages (V).
        voltages_v: Vec<f64>,
        /// Period (ms).
        period_ms: f64,
    },
}

/// `sin(2π f t + φ)`: a sine drive's phase term ([`Waveform::sine_at`], [`Waveform::voltage`]).
#[inline]
fn sine_term(frequency_khz: f64, phase: f64, t: f64) -> f64 {
    (std::f64::consts::TAU * frequency_khz * t + phase).sin()
}

/// A sine drive's voltage from its [`sine_term`] ([`Waveform::voltage_of_sine`],
/// [`Waveform::voltage`]).
#[inline]
fn sine_voltage(offset_v: f64, amplitude_v: f64, sine: f64) -> f64 {
    offset_v + amplitude_v * sine
}

impl Waveform {
    /// A validated sine; `frequency_hz` in Hz (converted to kHz internally).
    pub fn sine(amplitude_v: f64, frequency_hz: f64, offset_v: f64, phase: f64) -> Result<Self> {
        check_finite("amplitude_v", amplitude_v)?;
        check_finite("offset_v", offset_v)?;
        check_finite("phase", phase)?;
        if !(frequency_hz.is_finite() && frequency_hz > 0.0 && frequency_hz <= 1.0e5) {
            bail!(invalid "frequency_hz", frequency_hz, "in (0, 1e5] Hz");
        }
        Ok(Waveform::Sine {
            amplitude_v,
            frequency_khz: frequency_hz * 1e-3,
            offset_v,
            phase,
        })
    }

    /// A validated periodic sampled waveform.
    pub fn sampled(times_ms: Vec<f64>, voltages_v: Vec<f64>, period_ms: f64) -> Result<Self> {
        check_positive("period_ms", period_ms)?;
        if times_ms.is_empty() {
            bail!(invalid "times_ms", "[]", "at least one sample");
        }
        if times_ms.len() != voltages_v.len() {
            bail!(Shape "times_ms has {} samples but voltages_v has {}", times_ms.len(), voltages_v.len());
        }
        paritysim_error::check_all_finite("times_ms", &times_ms)?;
        paritysim_error::check_all_finite("voltages_v", &voltages_v)?;
        for i in 0..times_ms.len() {
            let ok = times_ms[i] >= 0.0
                && times_ms[i] < period_ms
                && (i == 0 || times_ms[i] > times_ms[i - 1]);
            if !ok {
                return Err(Error::invalid(
                    format!("times_ms[{i}]"),
                    times_ms[i],
                    "strictly increasing within [0, period_ms)",
                ));
            }
        }
        Ok(Waveform::Sampled {
            times_ms,
            voltages_v,
            period_ms,
        })
    }

    /// Period (ms).
    pub fn period(&self) -> f64 {
        match self {
            Waveform::Sine { frequency_khz, .. } => 1.0 / frequency_khz,
            Waveform::Sampled { period_ms, .. } => *period_ms,
        }
    }

    /// Mean (DC) voltage.
    pub fn offset(&self) -> f64 {
        match self {
            Waveform::Sine { offset_v, .. } => *offset_v,
            Waveform::Sampled {
                voltages_v,
                times_ms,
                period_ms,
            } => {
                // Exact mean of the periodic piecewise-linear interpolant.
                let n = times_ms.len();
                let mut area = 0.0;
                for i in 0..n {
                    let (t0, v0) = (times_ms[i], voltages_v[i]);
                    let (t1, v1) = if i + 1 < n {
                        (times_ms[i + 1], voltages_v[i + 1])
                    } else {
                        (times_ms[0] + period_ms, voltages_v[0])
                    };
                    area += 0.5 * (v0 + v1) * (t1 - t0);
                }
                area / period_ms
            }
        }
    }

    /// `sin(2π f t + φ)` of a sine drive at `t` (`None`: a sampled drive): what
    /// [`Self::voltage`] scales and offsets ([`Self::voltage_of_sine`]).
    #[inline]
    pub fn sine_at(&self, t: f64) -> Option<f64> {
        match self {
            Waveform::Sine {
                frequency_khz,
                phase,
                ..
            } => Some(sine_term(*frequency_khz, *phase, t)),
            Waveform::Sampled { .. } => None,
        }
    }

    /// The voltage of a sine drive whose [`Self::sine_at`] is `sine` (V), by [`Self::voltage`]'s
    /// own operations (`None`: a sampled drive).
    #[inline]
    pub fn voltage_of_sine(&self, sine: f64) -> Option<f64> {
        match self {
            Waveform::Sine {
                amplitude_v,
                offset_v,
                ..
            } => Some(sine_voltage(*offset_v, *amplitude_v, sine)),
            Waveform::Sampled { .. } => None,
        }
    }

    /// Whether `other` is a sine drive with the same [`Self::sine_at`] (frequency and phase): a
    /// table of one's sines is the other's, whatever the amplitudes and offsets.
    pub fn same_sine(&self, other: &Self) -> bool {
        match (self, other) {
            (
                Waveform::Sine {
                    frequency_khz: f,
                    phase: p,
                    ..
                },
                Waveform::Sine {
                    frequency_khz: g,
                    phase: q,
                    ..
                },
            ) => f == g && p == q,
            _ => false,
        }
    }

    /// `V(t)` (V).
    #[inline]
    pub fn voltage(&self, t: f64) -> f64 {
        match self {
            Waveform::Sine {
                amplitude_v,
                frequency_khz,
                offset_v,
                phase,
            } => sine_voltage(
                *offset_v,
                *amplitude_v,
                sine_term(*frequency_khz, *phase, t),
            ),
            Waveform::Sampled {
                times_ms,
                voltages_v,
                period_ms,
            } => {
                let n = times_ms.len();
                let tau = t.rem_euclid(*period_ms);
                // Index of the last sample at or before tau (wrapping before the first).
                let k = times_ms.partition_point(|&s| s <= tau);
                let (i0, t0) = if k == 0 {
                    (n - 1, times_ms[n - 1] - period_ms)
                } else {
                    (k - 1, times_ms[k - 1])
                };
                let (i1, t1) = if k == n {
                    (0, times_ms[0] + period_ms)
                } else {
                    (k, times_ms[k])
                };
                if t1 <= t0 {
                    return voltages_v[i0];
                }
                let w = (tau - t0) / (t1 - t0);
                voltages_v[i0] * (1.0 - w) + voltages_v[i1] * w
            }
        }
    }
}

/// §3.3.1 actuator stiffness (mN/mm), defined once by `paritysim_laminate::ActuatorConstants`.
pub const THESIS_STIFFNESS: f64 = ActuatorConstants::THESIS.stiffness_mn_per_mm;
/// §3.3.1 blocked force per volt (mN/V): 120 mN at 100 V, defined by the laminate crate.
pub const THESIS_FORCE_PER_VOLT: f64 = ActuatorConstants::THESIS.force_per_volt_mn_per_v;

/// Piezo actuator: `F(t) = force_per_volt · V(t)` in parallel with `stiffness` on `q1`.
#[derive(Clone, Debug, PartialEq)]
pub struct Actuator {
    force_per_volt: f64,
    stiffness: f64,
    waveform: Waveform,
    dc_offset: DcOffset,
    /// Per side (left, right) of a dual drivetrain: force scale and added force (mN).
    sides: [(f64, f64); 2],
    /// Effective mass on `q1` (mg), viscous damping (mN·ms/mm), cubic stiffness (mN/mm³).
    mass: f64,
    damping: f64,
    cubic_stiffness: f64,
}

impl Actuator {
    /// `force_per_volt` in mN/V (>= 0), `stiffness` in mN/mm (>= 0).
    pub fn new(
        force_per_volt: f64,
        stiffness: f64,
        waveform: Waveform,
        dc_offset: DcOffset,
    ) -> Result<Self> {
        Ok(Self {
            force_per_volt: check_non_negative("force_per_volt", force_per_volt)?,
            stiffness: check_non_negative("stiffness", stiffness)?,
            waveform,
            dc_offset,
            sides: [(1.0, 0.0); 2],
            mass: 0.0,
            damping: 0.0,
            cubic_stiffness: 0.0,
        })
    }

    /// With an effective mass `mass` (mg) on `q1` (the actuator and linkage inertia reflected to
    /// the actuator tip: kinetic energy `½ m q̇1²`), viscous damping `damping` (mN·ms/mm: a
    /// force `−b1 q̇1`) and a cubic stiffness `cubic_stiffness` (mN/mm³: a force `−K1c q1³`,
    /// hardening when positive). All zero by default.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `mass_mg`, `damping` or `cubic_stiffness` when
    /// negative or not finite.
    pub fn with_dynamics(mut self, mass: f64, damping: f64, cubic_stiffness: f64) -> Result<Self> {
        self.mass = check_non_negative("mass_mg", mass)?;
        self.damping = check_non_negative("damping", damping)?;
        self.cubic_stiffness = check_non_negative("cubic_stiffness", cubic_stiffness)?;
        Ok(self)
    }

    /// Effective mass on `q1` (mg).
    pub fn mass(&self) -> f64 {
        self.mass
    }

    /// Viscous damping on `q1` (mN·ms/mm).
    pub fn damping(&self) -> f64 {
        self.damping
    }

    /// Cubic stiffness on `q1` (mN/mm³).
    pub fn cubic_stiffness(&self) -> f64 {
        self.cubic_stiffness
    }

    /// The same actuator driving each side of a dual drivetrain
    /// (`paritysim_kinematics::drivetrain::DualFourBar`: one drive per wing, same stiffness)
    /// with its own force `F_k(t) = gain[k] F(t) + offset_mn[k]` (left, right).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `side_gain[k]` (finite, in [0, 1e3]) or
    /// `side_offset[k]` (finite).
    pub fn with_sides(mut self, gain: [f64; 2], offset_mn: [f64; 2]) -> Result<Self> {
        for k in 0..2 {
            if !(gain[k].is_finite() && (0.0..=1e3).contains(&gain[k])) {
                bail!(invalid format!("side_gain[{k}]"), gain[k], "in [0, 1e3]");
            }
            if !offset_mn[k].is_finite() {
                bail!(invalid format!("side_offset[{k}]"), offset_mn[k], "a finite force (mN)");
            }
            self.sides[k] = (gain[k], offset_mn[k]);
        }
        Ok(self)
    }

    /// Whether the sides differ from the common drive (`with_sides` other than gain 1, offset 0).
    pub fn has_sides(&self) -> bool {
        self.sides != [(1.0, 0.0); 2]
    }

    /// Force (mN) of side `k` (0 left, 1 right) of a dual drivetrain at time `t` (ms).
    #[inline]
    pub fn side_force(&self, t: f64, k: usize) -> f64 {
        let (gain, offset) = self.sides[k];
        gain * self.force(t) + offset
    }

    /// The §3.3.1 actuator (467 mN/mm, 1.2 mN/V) with the given waveform.
    pub fn thesis(waveform: Waveform) -> Self {
        Self {
            force_per_volt: THESIS_FORCE_PER_VOLT,
            stiffness: THESIS_STIFFNESS,
            waveform,
            dc_offset: DcOffset::AsForce,
            sides: [(1.0, 0.0); 2],
            mass: 0.0,
            damping: 0.0,
            cubic_stiffness: 0.0,
        }
    }

    /// Force (mN) at time `t` (ms).
    #[inline]
    pub fn force(&self, t: f64) -> f64 {
        self.force_of_voltage(self.waveform.voltage(t))
    }

    /// The force of a sine drive whose [`Waveform::sine_at`] is `sine` at the time, by
    /// [`Self::force`]'s own operations: a table of sines gives its forces bit for bit
    /// (`None`: a sampled drive).
    #[inline]
    pub fn force_of_sine(&self, sine: f64) -> Option<f64> {
        (self.waveform.voltage_of_sine(sine)).map(|v| self.force_of_voltage(v))
    }

    /// The force at the drive voltage `v` (the DC treatment, then the force per volt).
    #[inline]
    fn force_of_voltage(&self, v: f64) -> f64 {
        let v = match self.dc_offset {
            DcOffset::AsForce => v,
            DcOffset::Ignore => v - self.waveform.offset(),
        };
        self.force_per_volt * v
    }

    /// Whether [`Self::force`] is the same function of time as `other`'s (the fields it reads
    /// are equal; the springs, mass and damping may differ): a table of one's forces is the
    /// other's.
    pub fn same_force(&self, other: &Self) -> bool {
        self.force_per_volt == other.force_per_volt
            && self.dc_offset == other.dc_offset
            && self.waveform == other.waveform
    }

    /// Stiffness K1 (mN/mm).
    pub fn stiffness(&self) -> f64 {
        self.stiffness
    }

    /// Force per volt (mN/V).
    pub fn force_per_volt(&self) -> f64 {
        self.force_per_volt
    }

    /// Waveform.
    pub fn waveform(&self) -> &Waveform {
        &self.waveform
    }

    /// DC-offset treatment.
    pub fn dc_offset(&self) -> DcOffset {
        self.dc_offset
    }
}
