//! [`WingTerms`] as a plain serde record for the bindings.

use nalgebra::{Matrix3, Vector3};
use paritysim_error::{Error, Result};

use super::WingTerms;

/// [`WingTerms`] as a plain serde record (matrices as rows; `spring` named
/// `spring_gradient`), what the bindings hand over.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct WingTermsRecord {
    /// `M(p)` (mg·mm²).
    pub mass: [[f64; 3]; 3],
    /// `c(p, ṗ)` (mN·mm).
    pub coriolis: [f64; 3],
    /// `∂V/∂p` (mN·mm).
    pub spring_gradient: [f64; 3],
    /// `J6ᵀ τ⁶` (mN·mm).
    pub aero: [f64; 3],
    /// `J6`.
    pub j6: [[f64; 3]; 3],
    /// `J6 ṗ` (rad/ms).
    pub omega: [f64; 3],
    /// `J̇6 ṗ` (rad/ms²).
    pub jdot_pdot: [f64; 3],
    /// `R_6^1`.
    pub rotation: [[f64; 3]; 3],
    /// `θ_w` (rad).
    pub theta_w: f64,
    /// Kinetic energy (µJ).
    pub kinetic: f64,
    /// Spring energy (µJ).
    pub potential: f64,
}

impl From<&WingTerms> for WingTermsRecord {
    fn from(t: &WingTerms) -> Self {
        let m = |m: &Matrix3<f64>| std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)]));
        let v = |v: &Vector3<f64>| [v[0], v[1], v[2]];
        Self {
            mass: m(&t.mass),
            coriolis: v(&t.coriolis),
            spring_gradient: v(&t.spring),
            aero: v(&t.aero),
            j6: m(&t.j6),
            omega: v(&t.omega),
            jdot_pdot: v(&t.jdot_pdot),
            rotation: m(&t.rotation),
            theta_w: t.theta_w,
            kinetic: t.kinetic,
            potential: t.potential,
        }
    }
}

impl WingTermsRecord {
    /// The terms of wing `wing` of `device` at `p = (φ, θ, ψ)`, `ṗ` (always the general terms,
    /// never the stroke-plane closed form).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a wing index past the device's wings or a non-finite
    /// `p` / `p_dot`; as [`Wing::terms`](super::Wing::terms) (outside the joint limit, singular pose).
    pub fn at(device: &crate::Device, wing: usize, p: [f64; 3], p_dot: [f64; 3]) -> Result<Self> {
        let n = device.n_wings();
        let w = device
            .spec()
            .wings
            .get(wing)
            .ok_or_else(|| Error::invalid("wing", wing, format!("in [0, {n})")))?;
        paritysim_error::check_all_finite("p", &p)?;
        paritysim_error::check_all_finite("p_dot", &p_dot)?;
        Ok(Self::from(
            &w.terms(&Vector3::from(p), &Vector3::from(p_dot))?,
        ))
    }
}
