//! Joint springs and the §3.4 tunable hinge.

use paritysim_error::{Error, Result, check_finite, check_non_negative};

/// A torsion spring at a shoulder joint: `τ = k (γ − γ0) + k3 (γ − γ0)³`.
///
/// `k` in mN·mm/rad, `k3` in mN·mm/rad³ (a hardening law when `k3 > 0`), `γ0` in rad.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct JointSpring {
    stiffness: f64,
    cubic: f64,
    rest_angle: f64,
}

impl JointSpring {
    /// A linear spring (A.7). `stiffness >= 0`, finite rest angle.
    pub fn linear(stiffness: f64, rest_angle: f64) -> Result<Self> {
        Self::nonlinear(stiffness, 0.0, rest_angle)
    }

    /// A spring with an added cubic term (`cubic >= 0`: hardening, never negative stiffness).
    pub fn nonlinear(stiffness: f64, cubic: f64, rest_angle: f64) -> Result<Self> {
        Ok(Self {
            stiffness: check_non_negative("stiffness", stiffness)?,
            cubic: check_non_negative("cubic", cubic)?,
            rest_angle: check_finite("rest_angle", rest_angle)?,
        })
    }

    /// `∂V/∂γ`.
    #[inline]
    pub fn torque(&self, gamma: f64) -> f64 {
        let d = gamma - self.rest_angle;
        self.stiffness * d + self.cubic * d * d * d
    }

    /// `∂²V/∂γ² = k + 3 k3 (γ − γ0)²` (the spring's contribution to a Jacobian).
    #[inline]
    pub fn slope(&self, gamma: f64) -> f64 {
        let d = gamma - self.rest_angle;
        self.stiffness + 3.0 * self.cubic * d * d
    }

    /// Stored energy `V(γ)` (µJ).
    #[inline]
    pub fn energy(&self, gamma: f64) -> f64 {
        let d = gamma - self.rest_angle;
        0.5 * self.stiffness * d * d + 0.25 * self.cubic * d.powi(4)
    }

    /// Linear stiffness (mN·mm/rad).
    pub fn stiffness(&self) -> f64 {
        self.stiffness
    }

    /// Cubic coefficient (mN·mm/rad³).
    pub fn cubic(&self) -> f64 {
        self.cubic
    }

    /// Rest angle (rad).
    pub fn rest_angle(&self) -> f64 {
        self.rest_angle
    }
}

/// The tunable wing hinge of §2.5.1: a hinge whose stiffness rises with wing deviation,
/// `V = ½ k(θ) ψ²` with `k(θ) = k0 + k1 θ + k2 θ²` (mN·mm/rad; θ the shoulder's input deviation).
/// Generalised forces: `∂V/∂ψ = k(θ) ψ`, `∂V/∂θ = ½ k'(θ) ψ²`. The thesis gives no law; this
/// quadratic family covers a signed (k1) and a symmetric (k2) stiffening.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TunableHinge {
    pub(crate) k0: f64,
    pub(crate) k1: f64,
    pub(crate) k2: f64,
}

impl TunableHinge {
    /// Requires `k0 > 0` and `k2 >= 0`, and `k(θ) > 0` for all θ (`k1² < 4 k0 k2`, or `k1 = 0`).
    pub fn new(k0: f64, k1: f64, k2: f64) -> Result<Self> {
        paritysim_error::check_positive("k0", k0)?;
        check_finite("k1", k1)?;
        check_non_negative("k2", k2)?;
        if k1 != 0.0 && k1 * k1 >= 4.0 * k0 * k2 {
            return Err(Error::invalid(
                "k1",
                k1,
                format!(
                    "|k1| < 2 sqrt(k0 k2) = {} so that k(theta) > 0 for every theta",
                    2.0 * (k0 * k2).sqrt()
                ),
            ));
        }
        Ok(Self { k0, k1, k2 })
    }

    /// `k(θ)`.
    #[inline]
    pub fn stiffness(&self, theta: f64) -> f64 {
        self.k0 + (self.k1 + self.k2 * theta) * theta
    }
}
