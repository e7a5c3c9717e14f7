//! Whether a device has a soft direction: a combination of its coordinates that almost no
//! force restores (the whippletree's offset when the balance spring is 0 or nearly so). Its
//! orbits then come in a family or nearly so (a Floquet multiplier at or near 1), and where
//! a sweep's chained Newton lands along it depends on the neighbour: only the variational
//! equations at the orbit tell how close to 1 that multiplier is (docs/concepts.md).

use nalgebra::DMatrix;

use crate::integrate::State;

use super::Device;

/// A direction is soft when the restoring acceleration per unit displacement along it, times
/// the period squared, is below this. Measured on the §3.4 1-Cut (docs/findings.md §26):
/// `σ T²` = 0 (K2 = 0), 1.6e-5 (1e-3), 3.1e-3 (0.2), 7.8e-3 (0.5), 3.1e-2 (2), 0.16 (10),
/// with `1 − μ` of the slow multiplier 0, 2.6e-6, 5.2e-4, 1.3e-3, 5.2e-3, 2.6e-2: about
/// `σ T² / 6`. A sweep counts `|1 − μ| ≤ 1e-3` as a family (`NEUTRAL_MULTIPLIER_TOL`), so this
/// limit covers it with a margin of 16 for more damped directions.
pub(crate) const SOFT_LIMIT: f64 = 0.1;

impl Device {
    /// Whether the device has a soft direction: the smallest singular value of
    /// `∂(accelerations)/∂(coordinates)` at rest (central differences), times `T²`, below 0.1
    /// (`SOFT_LIMIT`). `false` without a drive period or when the probe cannot be evaluated.
    pub fn has_soft_direction(&self) -> bool {
        let Some(period) = self.period() else {
            return false;
        };
        let n = self.n_dof();
        let p = *self.spec().constraints.particular();
        let Ok(rest) = self.state_from(&p, &paritysim_constraints::Vec6::zeros()) else {
            return false;
        };
        let accelerations = |y: &State| -> Option<[f64; crate::integrate::MAX_DOF]> {
            let mut dydt = State::default();
            crate::integrate::OdeSystem::rhs(self, 0.0, y, &mut dydt).ok()?;
            Some(dydt.rates)
        };
        let mut stiffness = DMatrix::zeros(n, n);
        for k in 0..n {
            let h = 1e-6 * (1.0 + rest.coords[k].abs());
            let (mut plus, mut minus) = (rest, rest);
            plus.coords[k] += h;
            minus.coords[k] -= h;
            let (Some(a), Some(b)) = (accelerations(&plus), accelerations(&minus)) else {
                return false;
            };
            for i in 0..n {
                stiffness[(i, k)] = (a[i] - b[i]) / (2.0 * h);
            }
        }
        if stiffness.iter().any(|v| !v.is_finite()) {
            return false;
        }
        let weakest = stiffness.singular_values().min();
        weakest * period * period < SOFT_LIMIT
    }
}
