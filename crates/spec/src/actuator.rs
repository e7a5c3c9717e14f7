//! The piezo actuator and its drive waveform (§3.2.2 item 4, §3.3.1).

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Sine drive `offset_v + amplitude_v sin(2π frequency_hz t + phase)` (eq. 3.24).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Sine {
    /// Amplitude (V), in [0, 1e4] (bimorphs run at a few hundred volts; the bound leaves room
    /// for deliberately overdriven studies).
    #[schemars(range(min = 0.0, max = 1e4), extend("x-unit" = "V"))]
    pub amplitude_v: f64,
    /// Drive frequency (Hz), in (0, 1e4].
    #[schemars(range(max = 1e4), extend("exclusiveMinimum" = 0.0, "x-unit" = "Hz"))]
    pub frequency_hz: f64,
    /// DC offset (V), in [-1e4, 1e4].
    #[schemars(range(min = -1e4, max = 1e4), extend("x-unit" = "V"))]
    pub offset_v: f64,
    /// Phase (rad), in [-2pi, 2pi].
    #[schemars(range(min = -std::f64::consts::TAU, max = std::f64::consts::TAU), extend("x-unit" = "rad"))]
    pub phase: f64,
}

impl Default for Sine {
    fn default() -> Self {
        // §3.3.1: 100 V at 110 Hz.
        Self {
            amplitude_v: 100.0,
            frequency_hz: 110.0,
            offset_v: 0.0,
            phase: 0.0,
        }
    }
}

/// One period of voltage samples, linearly interpolated and repeated.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Sampled {
    /// Sample times in `[0, period_ms)`, strictly increasing (ms).
    #[schemars(inner(range(min = 0.0, max = 1e6)), extend("x-unit" = "ms"))]
    pub times_ms: Vec<f64>,
    /// Voltages (V), each in [-1e4, 1e4].
    #[schemars(inner(range(min = -1e4, max = 1e4)), extend("x-unit" = "V"))]
    pub voltages_v: Vec<f64>,
    /// Period (ms), in (0, 1e6].
    #[schemars(range(max = 1e6), extend("exclusiveMinimum" = 0.0, "x-unit" = "ms"))]
    pub period_ms: f64,
}

/// Drive voltage, tagged by `kind`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Waveform {
    /// Sine (eq. 3.24).
    Sine(Sine),
    /// Sampled period.
    Sampled(Sampled),
}

impl Default for Waveform {
    fn default() -> Self {
        Waveform::Sine(Sine::default())
    }
}

/// How the DC part of the drive voltage enters (docs/errata.md#14).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum DcOffset {
    /// As a static force.
    #[default]
    AsForce,
    /// Not at all (bias only).
    Ignore,
}

/// Piezo actuator: force = `force_per_volt` × V(t), in parallel with `stiffness` (and, when set,
/// a cubic stiffness, viscous damping and an effective mass on `q1`): the drive load on `q1` is
/// `F(t) − K1 q1 − K1c q1³ − b1 q̇1`, with `m q̈1` added to the drivetrain's inertia.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default, deny_unknown_fields)]
pub struct Actuator {
    /// Drive voltage.
    pub waveform: Waveform,
    /// Blocked force per volt (mN/V), in [0, 100] (§3.3.1: 120 mN at 100 V).
    #[schemars(range(min = 0.0, max = 100.0), extend("x-unit" = "mN/V"))]
    pub force_per_volt: f64,
    /// Actuator stiffness K1 on `q1` (mN/mm), in [0, 1e5] (§3.3.1: 467).
    #[schemars(range(min = 0.0, max = 1e5), extend("x-unit" = "mN/mm"))]
    pub stiffness: f64,
    /// DC offset law.
    pub dc_offset: DcOffset,
    /// Per side (left, right) of a `dual_four_bar` or `dual_linear` drivetrain (one drive per wing): scale of
    /// the drive force, each in [0, 1e3]; [1, 1] for any other drivetrain.
    #[schemars(inner(range(min = 0.0, max = 1e3)), extend("x-unit" = "1"))]
    pub side_gain: [f64; 2],
    /// Per side of a `dual_four_bar` or `dual_linear` drivetrain: added DC voltage (V, a static force
    /// `force_per_volt × side_offset_v`), each in [-1e4, 1e4]; [0, 0] for any other drivetrain.
    #[schemars(inner(range(min = -1e4, max = 1e4)), extend("x-unit" = "V"))]
    pub side_offset_v: [f64; 2],
    /// Effective mass `m` on `q1` (mg), in [0, 1e3]: the actuator's and linkage's inertia
    /// reflected to the actuator tip (kinetic energy `½ m q̇1²`; through the transmission it
    /// adds `m / T²` to the stroke inertia of a linear map). 0 (the default): massless (§3.2.2
    /// item 5). Taken by the drivetrain-coordinate and general forms (others decline).
    #[schemars(range(min = 0.0, max = 1e3), extend("x-unit" = "mg"))]
    pub mass_mg: f64,
    /// Viscous damping `b1` on `q1` (mN·ms/mm), in [0, 1e4]: a force `−b1 q̇1` (structural
    /// loss of the actuator). 0 (the default) adds nothing.
    #[schemars(range(min = 0.0, max = 1e4), extend("x-unit" = "mN ms/mm"))]
    pub damping: f64,
    /// Cubic (hardening) stiffness `K1c` on `q1` (mN/mm³), in [0, 1e8]: a force `−K1c q1³`, so
    /// the resonance rises with amplitude (ω² ≈ ω0² + ¾ (K_c / m) A² at amplitude A). 0 (the
    /// default) adds nothing.
    #[schemars(range(min = 0.0, max = 1e8), extend("x-unit" = "mN/mm^3"))]
    pub cubic_stiffness: f64,
}

/// §3.3.1 actuator stiffness (mN/mm), defined by the engine.
pub const THESIS_ACTUATOR_STIFFNESS: f64 = paritysim_dynamics::actuator::THESIS_STIFFNESS;
/// §3.3.1 force per volt (mN/V), defined by the engine.
pub const THESIS_FORCE_PER_VOLT: f64 = paritysim_dynamics::actuator::THESIS_FORCE_PER_VOLT;

impl Default for Actuator {
    fn default() -> Self {
        Self {
            waveform: Waveform::default(),
            force_per_volt: THESIS_FORCE_PER_VOLT,
            stiffness: THESIS_ACTUATOR_STIFFNESS,
            dc_offset: DcOffset::default(),
            side_gain: [1.0, 1.0],
            side_offset_v: [0.0, 0.0],
            mass_mg: 0.0,
            damping: 0.0,
            cubic_stiffness: 0.0,
        }
    }
}
