//! §2.6.1: from physical parameters to (β0, κ1, κ2) (docs/errata.md#7), and §2.7's LTI model
//! (eq. 2.59).

use std::f64::consts::PI;

use nalgebra::Complex;
use paritysim_error::{Result, bail, check_finite, check_positive};

/// The physical parameters of the linearised Drag PARITY model of §2.6.1 (units mg-mm-ms-rad).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct PhysicalParameters {
    /// Wing inertia about the stroke axis I (mg·mm²).
    pub inertia: f64,
    /// Drag parameter Ω of eq. 2.16 (mg·mm²; `Ω1 C_N(90°)` for eq. 3.8, docs/errata.md#12).
    pub drag: f64,
    /// Transmission ratio T (rad/mm).
    pub transmission_ratio: f64,
    /// Whippletree arm L (mm).
    #[serde(rename = "arm_length_mm")]
    pub arm_length: f64,
    /// Actuator stiffness K1 (mN/mm).
    pub k1: f64,
    /// Balance-beam stiffness K2 (mN·mm/rad).
    pub k2: f64,
    /// Wing stroke amplitude Φ = T·A (rad).
    pub stroke_amplitude: f64,
    /// Flapping frequency (Hz).
    pub frequency_hz: f64,
}

/// The non-dimensional parameters of eqs. 2.23–2.24.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct HillParameters {
    /// `β0 = 2ΩTA/I = 2ΩΦ/I` (docs/errata.md#7; the printed `2ΩA/I` lacks T).
    pub beta0: f64,
    /// `κ1 = K1/(2 I T² ω0²)`.
    pub kappa1: f64,
    /// `κ2 = K2/(2 I T² L² ω0²)`.
    pub kappa2: f64,
}

impl PhysicalParameters {
    fn validate(&self) -> Result<()> {
        check_positive("inertia", self.inertia)?;
        check_positive("transmission_ratio", self.transmission_ratio)?;
        check_positive("arm_length", self.arm_length)?;
        check_positive("frequency_hz", self.frequency_hz)?;
        for (name, v) in [
            ("drag", self.drag),
            ("k1", self.k1),
            ("k2", self.k2),
            ("stroke_amplitude", self.stroke_amplitude),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                bail!(invalid name, v, "finite and >= 0");
            }
        }
        Ok(())
    }

    /// Angular drive frequency ω0 (rad/ms).
    pub fn omega0(&self) -> f64 {
        2.0 * PI * self.frequency_hz * 1e-3
    }

    /// (β0, κ1, κ2) of §2.6.1 with the factors corrected by docs/errata.md#7: the drag force on q2
    /// is `−4ΩT³L²|q̇1|q̇2`, so linearising about `q1 = A sin ω0t` and dividing by the modal
    /// inertia `2IT²L²` gives the damping `2ΩTA ω0 |cos τ|/I` per unit ω0.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`](paritysim_error::Error::InvalidParameter) for a non-positive inertia, T, L or frequency, or negative
    /// drag, stiffnesses or amplitude.
    pub fn hill(&self) -> Result<HillParameters> {
        self.validate()?;
        let w2 = self.omega0().powi(2);
        let t2 = self.transmission_ratio.powi(2);
        let i = self.inertia;
        Ok(HillParameters {
            beta0: 2.0 * self.drag * self.stroke_amplitude / i,
            kappa1: self.k1 / (2.0 * i * t2 * w2),
            kappa2: self.k2 / (2.0 * i * t2 * self.arm_length.powi(2) * w2),
        })
    }

    /// Eq. 2.59's LTI model for sinusoidal flapping: `κ0 = K2/(2IT²L²)` and β* the cycle
    /// average of `2Ω|φ̇|/I`, i.e. `(2/π) β0 ω0`.
    pub fn lti(&self) -> Result<LtiModel> {
        let h = self.hill()?;
        let w = self.omega0();
        LtiModel::new(2.0 / PI * h.beta0 * w, h.kappa2 * w * w)
    }
}

/// Eq. 2.59: `τ/τ_d = κ0/(s² + β* s + κ0)` from a wing roll disturbance torque to the body roll
/// torque, with `s` in rad/ms.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct LtiModel {
    /// Constant damping β* of the whippletree mode (1/ms).
    pub beta_star: f64,
    /// Stiffness κ0 = K2 / (modal inertia) (1/ms²).
    pub kappa0: f64,
}

impl LtiModel {
    /// `beta_star`, `kappa0` finite (negative values describe an unstable averaged mode, as
    /// the rod-crank linkage's geometric stiffness can produce; see [`DeviceLinearisation`](super::DeviceLinearisation)).
    pub fn new(beta_star: f64, kappa0: f64) -> Result<Self> {
        check_finite("beta_star", beta_star)?;
        check_finite("kappa0", kappa0)?;
        Ok(Self { beta_star, kappa0 })
    }

    /// Whether both poles are in the open left half plane (β* > 0 and κ0 > 0).
    pub fn is_stable(&self) -> bool {
        self.beta_star > 0.0 && self.kappa0 > 0.0
    }

    /// `H(iω)` at `frequency_hz` (ω = 2π f · 1e-3 rad/ms).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`](paritysim_error::Error::InvalidParameter) for a negative or non-finite frequency;
    /// [`Error::Singular`](paritysim_error::Error::Singular) at ω = 0 when κ0 = 0 (0/0),
    /// attributed to `frequency_hz`.
    pub fn transfer(&self, frequency_hz: f64) -> Result<Complex<f64>> {
        if !(frequency_hz.is_finite() && frequency_hz >= 0.0) {
            bail!(invalid "frequency_hz", frequency_hz, "finite and >= 0");
        }
        let w = 2.0 * PI * frequency_hz * 1e-3;
        let den = Complex::new(self.kappa0 - w * w, self.beta_star * w);
        if den.norm() == 0.0 {
            return Err(paritysim_error::Error::Singular(format!(
                "eq. 2.59 is 0/0 at f = {frequency_hz} Hz with kappa0 = {}",
                self.kappa0
            ))
            .attributed(
                "frequency_hz",
                frequency_hz,
                "> 0 Hz (large enough that 2 pi f beta_star does not underflow) when kappa0 = 0",
            ));
        }
        // κ0 / den by its polar form: the textbook quotient squares |den| and under- or
        // overflows for extreme but finite inputs (1e-300 or 1e308 gave NaN).
        let size = den.norm();
        let h = (den / size).conj() * (self.kappa0 / size);
        if !(h.re.is_finite() && h.im.is_finite()) {
            bail!(invalid "beta_star, kappa0", format!("{}, {}", self.beta_star, self.kappa0),
                "magnitudes whose transfer function is representable");
        }
        Ok(h)
    }
}
