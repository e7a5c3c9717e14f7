//! The odd polynomial transmission shared by the linear-map drivetrains (issue 35):
//! `φ = τ1 σ + τ2 σ³/3 + a5 σ⁵ + a7 σ⁷ + a9 σ⁹` of a side's actuator displacement σ (mm), with
//! `τ1 = transmission_ratio`, `τ2 = cubic_ratio`, `higher_odd_ratios = [a5, a7, a9]`.

use paritysim_error::Result;
use paritysim_kinematics::OddPolynomial;

/// The kinematics' polynomial of these fields (errors name `cubic_ratio` or
/// `higher_odd_ratios[j]`).
pub(super) fn polynomial(
    transmission_ratio: f64,
    cubic_ratio: f64,
    higher_odd_ratios: &[f64],
) -> Result<OddPolynomial> {
    OddPolynomial::new(transmission_ratio, cubic_ratio, higher_odd_ratios)
}
