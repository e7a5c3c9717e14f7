//! Classic forced oscillators with known bifurcations, for validation and tutorials.
//! Both take `parameters = [drive_frequency, drive_amplitude]` (rad per time unit, force).

use nalgebra::DMatrix;

use crate::ode::ForcedOde;

/// Index of the drive frequency `ω` in the parameter vector.
pub const DRIVE_FREQUENCY: usize = 0;
/// Index of the drive amplitude in the parameter vector.
pub const DRIVE_AMPLITUDE: usize = 1;

/// `x'' + δ x' + α x + β x³ = γ cos(ω t)`, state `(x, x')`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Duffing {
    /// Linear damping `δ`.
    pub damping: f64,
    /// Linear stiffness `α`.
    pub linear_stiffness: f64,
    /// Cubic stiffness `β` (0: a linear oscillator).
    pub cubic_stiffness: f64,
}

impl ForcedOde for Duffing {
    fn dim(&self) -> usize {
        2
    }
    fn period(&self, p: &[f64]) -> f64 {
        std::f64::consts::TAU / p[DRIVE_FREQUENCY]
    }
    fn rhs(&self, t: f64, x: &[f64], p: &[f64], dx: &mut [f64]) {
        let forcing = p[DRIVE_AMPLITUDE] * (p[DRIVE_FREQUENCY] * t).cos();
        dx[0] = x[1];
        dx[1] = forcing
            - self.damping * x[1]
            - self.linear_stiffness * x[0]
            - self.cubic_stiffness * x[0].powi(3);
    }
    fn jacobian(&self, _t: f64, x: &[f64], _p: &[f64], j: &mut DMatrix<f64>) {
        j[(0, 0)] = 0.0;
        j[(0, 1)] = 1.0;
        j[(1, 0)] = -self.linear_stiffness - 3.0 * self.cubic_stiffness * x[0] * x[0];
        j[(1, 1)] = -self.damping;
    }
}

/// The damped driven pendulum `θ'' + b θ' + sin θ = A cos(ω t)`, state `(θ, θ')`: period
/// doubling on the way to chaos (Baker & Gollub, *Chaotic Dynamics*, 1990).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForcedPendulum {
    /// Damping `b`.
    pub damping: f64,
}

impl ForcedOde for ForcedPendulum {
    fn dim(&self) -> usize {
        2
    }
    fn period(&self, p: &[f64]) -> f64 {
        std::f64::consts::TAU / p[DRIVE_FREQUENCY]
    }
    fn rhs(&self, t: f64, x: &[f64], p: &[f64], dx: &mut [f64]) {
        dx[0] = x[1];
        dx[1] =
            p[DRIVE_AMPLITUDE] * (p[DRIVE_FREQUENCY] * t).cos() - self.damping * x[1] - x[0].sin();
    }
    fn jacobian(&self, _t: f64, x: &[f64], _p: &[f64], j: &mut DMatrix<f64>) {
        j[(0, 0)] = 0.0;
        j[(0, 1)] = 1.0;
        j[(1, 0)] = -x[0].cos();
        j[(1, 1)] = -self.damping;
    }
}
