//! §2.6.4: Brockett's criterion (eqs. 2.57–2.58).

use std::f64::consts::PI;

use paritysim_error::{Result, bail, check_finite, check_positive};

use super::hill::check_hill;

/// The outcome of Brockett's sufficient condition for bounded solutions of
/// `ẍ + g(t)ẋ + x = 0`, `g(t + T) = g(t)`, `|g| ≤ 2δ` (eqs. 2.56–2.58).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Brockett {
    /// δ (half the bound on |g|).
    pub delta: f64,
    /// Period T.
    pub period: f64,
    /// `∫_0^T g dt`.
    pub damping_integral: f64,
    /// The smallest positive integer n whose interval of eq. 2.57 contains T, if any.
    pub n: Option<u64>,
    /// That interval `[2(n−1)(π − asin s)/s, 2n asin(s)/s]`, `s = √(1 − δ²)`.
    pub interval: Option<(f64, f64)>,
    /// Eq. 2.58: `∫ g ≥ 0`.
    pub damping_condition: bool,
    /// Both conditions hold: all solutions are guaranteed bounded. `false` guarantees nothing.
    pub bounded: bool,
}

/// Brockett's criterion (eqs. 2.57–2.58) for damping bound δ (`|g| ≤ 2δ`), period `T` and
/// `∫_0^T g dt`. For δ ≥ 1 eq. 2.57 has no interval and nothing is guaranteed.
///
/// # Errors
/// [`Error::InvalidParameter`](paritysim_error::Error::InvalidParameter) for δ < 0, T ≤ 0 or non-finite values.
pub fn brockett(delta: f64, period: f64, damping_integral: f64) -> Result<Brockett> {
    if !(delta.is_finite() && delta >= 0.0) {
        bail!(invalid "delta", delta, "finite and >= 0");
    }
    check_positive("period", period)?;
    check_finite("damping_integral", damping_integral)?;
    let damping_condition = damping_integral >= 0.0;
    let (mut n, mut interval) = (None, None);
    if delta < 1.0 {
        let s = (1.0 - delta * delta).sqrt();
        let asin = s.asin();
        let upper = |n: f64| 2.0 * n * asin / s;
        let lower = |n: f64| 2.0 * (n - 1.0) * (PI - asin) / s;
        // The upper ends grow with n: the smallest admissible n is the only candidate, since
        // the lower ends grow too (π − asin s ≥ asin s).
        let n_min = (period / upper(1.0)).ceil().max(1.0);
        // Closed intervals, with a relative rounding guard of 1e-12 at their ends (for δ = 1/2
        // the n = 2 interval is a single point).
        for cand in [n_min - 1.0, n_min] {
            let tol = 1e-12 * period;
            if cand >= 1.0 && lower(cand) <= period + tol && period <= upper(cand) + tol {
                n = Some(cand as u64);
                interval = Some((lower(cand), upper(cand)));
                break;
            }
        }
    }
    Ok(Brockett {
        delta,
        period,
        damping_integral,
        n,
        interval,
        damping_condition,
        bounded: damping_condition && n.is_some(),
    })
}

/// Brockett's criterion applied to eq. 2.25 after rescaling time by `√κ`: `g = (β0/√κ)|cos|`,
/// `T = π√κ`, `δ = |β0|/(2√κ)`, `∫g = 2β0`.
///
/// # Errors
/// [`Error::InvalidParameter`](paritysim_error::Error::InvalidParameter) unless κ > 0 (the criterion needs a restoring spring).
pub fn brockett_hill(beta0: f64, kappa: f64) -> Result<Brockett> {
    check_hill(beta0, kappa)?;
    check_positive("kappa", kappa)?;
    let root = kappa.sqrt();
    brockett(beta0.abs() / (2.0 * root), PI * root, 2.0 * beta0)
}
