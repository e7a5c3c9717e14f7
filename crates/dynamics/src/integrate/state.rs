//! The integrator's state: coordinates, rates and the two work integrals.

use super::MAX_DOF;

/// Integrator state: integrated coordinates and their rates (entries past the system's
/// [`OdeSystem::n_active`](super::OdeSystem::n_active) stay zero) and the two work integrals.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct State {
    /// Integrated coordinates (null-space coordinates `x`, drivetrain coordinates `q`, or `p`).
    pub coords: [f64; MAX_DOF],
    /// Their rates.
    pub rates: [f64; MAX_DOF],
    /// Actuator work `∫ F q̇1 dt` (µJ); integrated only when asked for.
    pub work_actuator: f64,
    /// Aerodynamic work `∫ τ_aero · ṗ dt` (µJ); integrated only when asked for.
    pub work_aero: f64,
}

impl State {
    /// The state as a flat list `[coords, rates, work_actuator, work_aero]` (error reports).
    pub fn to_vec(&self) -> Vec<f64> {
        let mut v = Vec::with_capacity(2 * MAX_DOF + 2);
        v.extend_from_slice(&self.coords);
        v.extend_from_slice(&self.rates);
        v.push(self.work_actuator);
        v.push(self.work_aero);
        v
    }

    /// Whether every entry is finite.
    pub fn is_finite(&self) -> bool {
        self.coords.iter().chain(&self.rates).all(|v| v.is_finite())
            && self.work_actuator.is_finite()
            && self.work_aero.is_finite()
    }

    /// The first `n` coordinates and rates as one vector `[coords, rates]` (shooting).
    pub fn compact(&self, n: usize) -> nalgebra::DVector<f64> {
        nalgebra::DVector::from_fn(2 * n, |i, _| {
            if i < n {
                self.coords[i]
            } else {
                self.rates[i - n]
            }
        })
    }

    /// The state of a [`Self::compact`] vector (work integrals zero).
    pub fn from_compact(n: usize, v: &nalgebra::DVector<f64>) -> Self {
        let mut y = Self::default();
        for i in 0..n {
            y.coords[i] = v[i];
            y.rates[i] = v[n + i];
        }
        y
    }

    /// Appends [`Self::compact`]'s entries to `out` (samples kept flat, `2n` each).
    pub fn push_compact(&self, n: usize, out: &mut Vec<f64>) {
        out.extend_from_slice(&self.coords[..n]);
        out.extend_from_slice(&self.rates[..n]);
    }

    /// The state with both work integrals set to zero.
    pub fn without_work(mut self) -> Self {
        self.work_actuator = 0.0;
        self.work_aero = 0.0;
        self
    }
}
