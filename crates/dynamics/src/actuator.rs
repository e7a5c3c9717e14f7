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

    /// `V(t)` (V).
    #[inline]
    pub fn voltage(&self, t: f64) -> f64 {
        match self {
            Waveform::Sine {
                amplitude_v,
                frequency_khz,
                offset_v,
                phase,
            } => {
                offset_v
                    + amplitude_v * drive_sin(std::f64::consts::TAU * frequency_khz * t + phase)
            }
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
        })
    }

    /// The §3.3.1 actuator (467 mN/mm, 1.2 mN/V) with the given waveform.
    pub fn thesis(waveform: Waveform) -> Self {
        Self {
            force_per_volt: THESIS_FORCE_PER_VOLT,
            stiffness: THESIS_STIFFNESS,
            waveform,
            dc_offset: DcOffset::AsForce,
        }
    }

    /// Force (mN) at time `t` (ms).
    #[inline]
    pub fn force(&self, t: f64) -> f64 {
        let v = self.waveform.voltage(t);
        let v = match self.dc_offset {
            DcOffset::AsForce => v,
            DcOffset::Ignore => v - self.waveform.offset(),
        };
        self.force_per_volt * v
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

/// `sin x` for the drive waveform, evaluated in every right-hand side (a sixth of a §3.3 trial's
/// instructions went to libm's `sin`): Cody–Waite reduction by π/2 in three parts (exact
/// products for `|x| < 2^19 π/2 ≈ 8.2·10⁵` rad; 10⁵ periods of any drive are 6.3·10⁵) and
/// fdlibm's `__kernel_sin` / `__kernel_cos` minimax polynomials on `[−π/4, π/4]` (the
/// algorithm and constants of FreeBSD's msun `k_sin.c`, `k_cos.c`, `e_rem_pio2.c`, public
/// domain): within 1 ulp of the correctly rounded value (tested against `f64::sin`), about
/// 30 instructions instead of ~100. Larger or non-finite arguments use `f64::sin`.
#[inline]
pub(crate) fn drive_sin(x: f64) -> f64 {
    const INV_PIO2: f64 = std::f64::consts::FRAC_2_PI;
    // π/2 = PIO2_1 + PIO2_2 + PIO2_3 (+ 8.5e-32), the first two with 33 significant bits.
    const PIO2_1: f64 = 1.5707963267341256; // 0x3FF921FB_54400000
    const PIO2_2: f64 = 6.077100506303966e-11; // 0x3DD0B461_1A600000
    const PIO2_3: f64 = 2.0222662487111665e-21; // 0x3BA3198A_2E000000
    if x.is_nan() || x.abs() >= 8.2e5 {
        return x.sin();
    }
    // Round to the nearest integer by the 1.5·2^52 shift (`f64::round` is a libm call on
    // x86-64 without SSE4.1); exact for |x · 2/π| < 2^51.
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    let n = (x * INV_PIO2 + SHIFT) - SHIFT;
    let r = ((x - n * PIO2_1) - n * PIO2_2) - n * PIO2_3;
    let quadrant = (n as i64) & 3;
    let z = r * r;
    match quadrant {
        0 => kernel_sin(r, z),
        1 => kernel_cos(z),
        2 => -kernel_sin(r, z),
        _ => -kernel_cos(z),
    }
}

/// fdlibm `__kernel_sin(r, 0, 0)` on `|r| ≤ π/4` (`z = r²`).
#[inline(always)]
fn kernel_sin(r: f64, z: f64) -> f64 {
    const S1: f64 = -0.16666666666666632; // 0xBFC55555_55555549
    const S2: f64 = 0.00833333333332249; // 0x3F811111_1110F8A6
    const S3: f64 = -0.0001984126982985795; // 0xBF2A01A0_19C161D5
    const S4: f64 = 2.7557313707070068e-6; // 0x3EC71DE3_57B1FE7D
    const S5: f64 = -2.5050760253406863e-8; // 0xBE5AE5E6_8A2B9CEB
    const S6: f64 = 1.58969099521155e-10; // 0x3DE5D93A_5ACFD57C
    let poly = S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)));
    r + z * r * (S1 + z * poly)
}

/// fdlibm `__kernel_cos(r, 0)` on `|r| ≤ π/4` (`z = r²`).
#[inline(always)]
fn kernel_cos(z: f64) -> f64 {
    const C1: f64 = 0.0416666666666666; // 0x3FA55555_5555554C
    const C2: f64 = -0.001388888888887411; // 0xBF56C16C_16C15177
    const C3: f64 = 2.480158728947673e-5; // 0x3EFA01A0_19CB1590
    const C4: f64 = -2.7557314351390663e-7; // 0xBE927E4F_809C52AD
    const C5: f64 = 2.087572321298175e-9; // 0x3E21EE9E_BDB4B1C4
    const C6: f64 = -1.1359647557788195e-11; // 0xBDA8FAE9_BE8838D4
    let poly = z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    let half = 0.5 * z;
    let w = 1.0 - half;
    w + (((1.0 - w) - half) + z * poly)
}

#[cfg(test)]
mod tests {
    use super::drive_sin;

    /// Distance in units in the last place of the reference.
    fn ulps(a: f64, reference: f64) -> f64 {
        let ulp = f64::EPSILON * reference.abs().max(f64::MIN_POSITIVE);
        // Below 2^-1022 one ulp is the smallest subnormal.
        (a - reference).abs() / ulp.max(5e-324)
    }

    #[test]
    fn drive_sin_is_within_one_ulp_of_libm() {
        // A deterministic spread over the reduction's range: small, quadrant edges, 10^5
        // periods of a 110 Hz drive, both signs.
        let mut worst: f64 = 0.0;
        let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
        for k in 0..400_000 {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let unit = (state >> 11) as f64 / (1u64 << 53) as f64;
            let scale = [1e-8, 1.0, 10.0, 1e3, 7e5][k % 5];
            let x = (2.0 * unit - 1.0) * scale;
            worst = worst.max(ulps(drive_sin(x), x.sin()));
        }
        for n in -2000..2000 {
            let x = n as f64 * std::f64::consts::FRAC_PI_4;
            assert!((drive_sin(x) - x.sin()).abs() <= 4.0 * f64::EPSILON, "{x}");
        }
        // libm is within ~0.5 ulp of the true value, fdlibm's kernels within 1.
        assert!(worst <= 1.5, "worst {worst} ulp");
        for x in [1e6, -3e7, f64::INFINITY, f64::NAN] {
            assert!(
                drive_sin(x).to_bits() == x.sin().to_bits() || x.is_nan() && drive_sin(x).is_nan()
            );
        }
    }
}
