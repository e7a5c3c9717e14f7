//! Floquet multipliers of a periodic orbit, its stability, and the test functions whose sign
//! changes mark the codimension-one bifurcations of a forced periodic orbit.

use nalgebra::{Complex, DMatrix};

/// Stability of a periodic orbit from its non-trivial multipliers `μ`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stability {
    /// Every `|μ| < 1 − tolerance`.
    Stable,
    /// Some `|μ| > 1 + tolerance`.
    Unstable,
    /// The largest `|μ|` is within the tolerance of 1 (e.g. an undamped mode).
    Marginal,
}

impl Stability {
    /// `stable`, `unstable` or `marginal`.
    pub fn name(self) -> &'static str {
        match self {
            Stability::Stable => "stable",
            Stability::Unstable => "unstable",
            Stability::Marginal => "marginal",
        }
    }
}

/// Eigenvalues of the monodromy, largest modulus first. With a cyclic coordinate its trivial
/// multiplier (exactly 1: shifting that coordinate shifts the orbit) is removed.
pub fn multipliers(monodromy: &DMatrix<f64>, cyclic: bool) -> Vec<Complex<f64>> {
    let mut mu: Vec<Complex<f64>> = monodromy
        .clone()
        .complex_eigenvalues()
        .iter()
        .copied()
        .collect();
    if cyclic && !mu.is_empty() {
        let trivial = (0..mu.len())
            .min_by(|&a, &b| (mu[a] - 1.0).norm().total_cmp(&(mu[b] - 1.0).norm()))
            .unwrap_or(0);
        mu.remove(trivial);
    }
    mu.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    mu
}

/// Stability with `tolerance` on `|μ| − 1`.
pub fn stability(multipliers: &[Complex<f64>], tolerance: f64) -> Stability {
    let largest = multipliers.iter().map(|m| m.norm()).fold(0.0, f64::max);
    if largest > 1.0 + tolerance {
        Stability::Unstable
    } else if largest < 1.0 - tolerance {
        Stability::Stable
    } else {
        Stability::Marginal
    }
}

/// `∏ (μ − 1)`: zero where a multiplier crosses +1 (fold of the orbit family).
pub fn fold_test(multipliers: &[Complex<f64>]) -> f64 {
    multipliers
        .iter()
        .fold(Complex::new(1.0, 0.0), |p, m| p * (m - 1.0))
        .re
}

/// `∏ (μ + 1)`: zero where a multiplier crosses −1 (period doubling).
pub fn period_doubling_test(multipliers: &[Complex<f64>]) -> f64 {
    multipliers
        .iter()
        .fold(Complex::new(1.0, 0.0), |p, m| p * (m + 1.0))
        .re
}

/// `∏ (|μ|² − 1)` over the complex-conjugate pairs, with the number of pairs: zero where a pair
/// crosses the unit circle (Neimark–Sacker). Comparable only between points with the same number
/// of pairs (a pair may instead split on the real axis).
pub fn neimark_sacker_test(multipliers: &[Complex<f64>]) -> (f64, usize) {
    let scale = multipliers.iter().map(|m| m.norm()).fold(1.0, f64::max);
    let pairs: Vec<&Complex<f64>> = multipliers
        .iter()
        .filter(|m| m.im > 1e-10 * scale)
        .collect();
    let product = pairs.iter().fold(1.0, |p, m| p * (m.norm_sqr() - 1.0));
    (product, pairs.len())
}
