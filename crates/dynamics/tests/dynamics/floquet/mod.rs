//! floquet tests (submodule of the one dynamics integration binary): the shared devices and
//! independent references here, the subjects in `hill.rs`, `orbit.rs` and `disturbance.rs`.
//!
//! §2.6: the eq. 2.25 monodromy against Liouville (eq. 2.45), the κ = 0 closed form (eq. 2.50)
//! and an independent adaptive integrator; docs/errata.md#7 to #10 each checked numerically. Full
//! model: shooting against long simulation, multipliers against independent differences of the
//! stroboscopic map and against kick growth in `simulate`, and a Liouville identity for the
//! whippletree block. §2.7: eq. 2.59 against the nonlinear disturbance response.

use std::f64::consts::{FRAC_PI_2, PI};

use nalgebra::{Complex, DMatrix, Matrix2};
use paritysim_dynamics::floquet::*;
use paritysim_dynamics::integrate::{Integrator, Method, OdeSystem, RungeKutta};
use paritysim_dynamics::{State, SteadyState};
use paritysim_kinematics::drivetrain::LinearDifferential;

use super::*;

// ------------------------------------------------------------------ helpers

/// Modified Bessel function I0 by its power series Σ (x/2)^{2k}/(k!)² (independent of the code).
fn bessel_i0(x: f64) -> f64 {
    let (mut term, mut sum, mut k) = (1.0, 1.0, 1.0);
    while term > 1e-18 * sum {
        term *= (0.5 * x) * (0.5 * x) / (k * k);
        sum += term;
        k += 1.0;
    }
    sum
}

/// A small deterministic generator (xorshift64*), uniform in [lo, hi).
struct Rng(u64);

impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let bits = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11;
        lo + (hi - lo) * (bits as f64 / (1u64 << 53) as f64)
    }
}

/// Roots of ρ² − 2aρ + b by the textbook formula in complex arithmetic (independent of
/// `multipliers`).
fn roots(a: f64, b: f64) -> [Complex<f64>; 2] {
    let d = Complex::new(a * a - b, 0.0).sqrt();
    [Complex::new(a, 0.0) + d, Complex::new(a, 0.0) - d]
}

/// The §3.3 Drag PARITY device (examples/drag_parity.toml): nonlinear linkage, C_N(90°) drag,
/// 100 V at 110 Hz, balance-beam stiffness `k2`.
fn section_3_3(omega_left: f64, k2: f64) -> Device {
    section_3_3_at(omega_left, k2, 100.0)
}

/// The same at `volts` (a cut wing at 100 V strokes beyond the linkage's reach; 70 V is safe).
fn section_3_3_at(omega_left: f64, k2: f64, volts: f64) -> Device {
    two_wing_device(
        [
            fixed_wing(WingAero::stroke_drag(omega_left, 3.4609).unwrap()),
            fixed_wing(WingAero::stroke_drag(31.3, 3.4609).unwrap()),
        ],
        "drag_parity_fixed",
        Drivetrain::LinkageDifferential(LinkageDifferential::thesis()),
        k2,
        Actuator::thesis(Waveform::sine(volts, 110.0, 0.0, 0.0).unwrap()),
        Formulation::Auto,
    )
}

/// Eq. 2.15 with T = 2.5 rad/mm, L = 2.5 mm (the linearisation of the §3.3 linkage), eq. 2.16
/// drag (C = 1), 50 V.
fn linear_map() -> Drivetrain {
    Drivetrain::LinearDifferential(LinearDifferential::new(2.5, 2.5, 1.0).unwrap())
}

fn eq_2_16_device(drivetrain: Drivetrain, k2: f64) -> Device {
    parity_device_with(31.3, k2, "drag_parity_fixed", Formulation::Auto, drivetrain)
}

fn options() -> ShootingOptions {
    ShootingOptions::default()
}

/// Entry `s` of the flat layout `[coords (6), rates (6)]`.
fn slot(y: &mut State, s: usize) -> &mut f64 {
    if s < 6 {
        &mut y.coords[s]
    } else {
        &mut y.rates[s - 6]
    }
}

mod budget;
mod disturbance;
mod hill;
mod orbit;
