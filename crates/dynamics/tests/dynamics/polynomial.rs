//! Polynomial transmissions and linear drives per wing (issue 35) on the drivetrain-coordinate
//! form: its right-hand side (the linear map's equations with `φ_k = P(J_k q)`, a
//! configuration-dependent `M_q` and the velocity product) against the null-space formulation
//! of eq. 3.20 at the same `(p, ṗ)`, and its analytic Jacobian against central differences and
//! the period map.

use nalgebra::{DMatrix, Vector2};
use paritysim_dynamics::Integrator;
use paritysim_dynamics::State;
use paritysim_dynamics::integrate::{Method, OdeSystem, RungeKutta};
use paritysim_kinematics::OddPolynomial;
use paritysim_kinematics::drivetrain::{DualLinear, LinearDifferential};

use super::*;

/// Unequal wings with hardening stroke springs off their rest angles (every term exercised).
fn sprung_wings() -> [Wing; 2] {
    let wing = |inertia: f64, omega: f64, rest: f64| {
        let mut s = [JointSpring::default(); 6];
        s[0] = JointSpring::nonlinear(40.0, 25.0, rest).unwrap();
        Wing::new(
            shoulder(90.0, 0.0),
            Matrix3::from_diagonal(&Vector3::new(inertia, inertia, 1.0)),
            s,
            drag(omega),
        )
        .unwrap()
    };
    [wing(24.0, 17.0, 0.1), wing(31.0, 31.3, -0.2)]
}

/// A stiffening cubic and a quintic on the §3.3 linear differential (biased pivot).
pub(super) fn polynomial_differential() -> Device {
    let map = LinearDifferential::new(2.5, 2.5, 0.8)
        .unwrap()
        .with_polynomial(OddPolynomial::new(2.5, 30.0, &[-20.0]).unwrap());
    two_wing_device(
        sprung_wings(),
        "drag_parity_fixed",
        Drivetrain::LinearDifferential(map),
        35.0,
        Actuator::thesis(Waveform::sine(50.0, 110.0, 0.0, 0.3).unwrap()),
        Formulation::Auto,
    )
}

/// A softening cubic on a drive per wing, the sides driven unequally.
pub(super) fn polynomial_dual() -> Device {
    let map = DualLinear::new(2.67, OddPolynomial::new(2.67, -8.0, &[]).unwrap()).unwrap();
    let actuator = Actuator::thesis(Waveform::sine(50.0, 110.0, 0.0, 0.3).unwrap())
        .with_sides([1.2, 0.7], [0.5, -1.0])
        .unwrap();
    two_wing_device(
        sprung_wings(),
        "drag_parity_fixed",
        Drivetrain::DualLinear(map),
        0.0,
        actuator,
        Formulation::Auto,
    )
}

fn devices() -> [Device; 2] {
    [polynomial_differential(), polynomial_dual()]
}

fn state(v: [f64; 4]) -> State {
    let mut y = State::default();
    y.coords[..2].copy_from_slice(&v[..2]);
    y.rates[..2].copy_from_slice(&v[2..]);
    y
}

#[test]
fn polynomial_right_hand_side_equals_the_null_space_formulation() {
    for device in devices() {
        assert_eq!(device.formulation(), Formulation::DrivetrainCoordinates);
        let general = Device::new(DeviceSpec {
            formulation: Formulation::NullSpace,
            ..device.spec().clone()
        })
        .unwrap();
        let kinematics = *device.spec().transmission.as_ref().unwrap().kinematics();
        let mut worst: f64 = 0.0;
        for k in 0..200 {
            let x = k as f64;
            let v = [
                0.12 * (0.37 * x).sin(),
                0.04 * (1.3 * x).cos(),
                0.6 * (0.71 * x).cos(),
                0.3 * (2.1 * x).sin(),
            ];
            let t = 0.05 * x;
            let mut dydt = State::default();
            device.rhs(t, &state(v), &mut dydt).unwrap();
            // φ̈ = J(q) q̈ + h(q, q̇) from the kinematics' own Jacobian and Hessians.
            let e = kinematics.evaluate(v[0], v[1]).unwrap();
            let q_dot = Vector2::new(v[2], v[3]);
            let phi_ddot = e.jacobian * Vector2::new(dydt.rates[0], dydt.rates[1])
                + e.velocity_product(&q_dot);
            let (p, p_dot) = device.coordinates(&state(v)).unwrap();
            let full = general.evaluate(t, &p, &p_dot).unwrap();
            for (lean, full) in [(phi_ddot.x, full.p_ddot[0]), (phi_ddot.y, full.p_ddot[3])] {
                worst = worst.max((lean - full).abs() / full.abs().max(1e-3));
            }
            // The actuator's power: F_L q̇1 (+ F_R q̇2 on the dual drive).
            let power = device.actuator_power(t, full.drive.actuator_force, &full.drive.q_dot);
            worst = worst.max((dydt.work_actuator - power).abs() / power.abs().max(1e-3));
        }
        assert!(
            worst <= 1e-11,
            "lean vs null-space accelerations: {worst:e}"
        );
    }
}

/// Deterministic uniform numbers in [-1, 1) (a 64-bit LCG).
fn uniform(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    (*seed >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

fn compact_rhs(device: &Device, t: f64, v: [f64; 4]) -> [f64; 4] {
    let mut d = State::default();
    device.rhs(t, &state(v), &mut d).unwrap();
    [d.coords[0], d.coords[1], d.rates[0], d.rates[1]]
}

#[test]
fn polynomial_analytic_jacobian_equals_central_differences() {
    let mut seed = 35;
    let eye: Vec<f64> = DMatrix::<f64>::identity(4, 4).iter().copied().collect();
    for device in devices() {
        let kinematics = *device.spec().transmission.as_ref().unwrap().kinematics();
        let mut checked = 0;
        while checked < 200 {
            let v = [
                0.2 * uniform(&mut seed),
                0.15 * uniform(&mut seed),
                2.0 * uniform(&mut seed),
                2.0 * uniform(&mut seed),
            ];
            // Away from the φ̇ = 0 kink of the drag, where the Jacobian jumps.
            let rates =
                kinematics.evaluate(v[0], v[1]).unwrap().jacobian * Vector2::new(v[2], v[3]);
            if rates.iter().any(|r| r.abs() < 0.05) {
                continue;
            }
            checked += 1;
            let t = 9.0 * uniform(&mut seed).abs();
            let mut jac = [0.0; 16];
            device
                .variational(t, &state(v), 2, &eye, &mut jac)
                .expect("a polynomial on the linear map has an analytic Jacobian")
                .unwrap();
            for j in 0..4 {
                let delta = 1e-6 * (1.0 + v[j].abs());
                let (mut plus, mut minus) = (v, v);
                plus[j] += delta;
                minus[j] -= delta;
                let (fp, fm) = (
                    compact_rhs(&device, t, plus),
                    compact_rhs(&device, t, minus),
                );
                let column = &jac[4 * j..4 * j + 4];
                let size = column.iter().fold(1.0f64, |a, x| a.max(x.abs()));
                for i in 0..4 {
                    let difference = (fp[i] - fm[i]) / (2.0 * delta);
                    assert!(
                        (column[i] - difference).abs() <= 1e-7 * size,
                        "J[{i}][{j}] at {v:?}: {} vs {difference}",
                        column[i]
                    );
                }
            }
        }
    }
}

#[test]
fn polynomial_monodromy_equals_finite_differences_of_the_period_map() {
    let period = 1.0 / 0.110;
    let rk = RungeKutta::new(Method::Dop853, 1e-10, 1e-12, 100_000)
        .unwrap()
        .with_work(false);
    for device in devices() {
        let y0 = rk
            .advance(&device, 0.0, &State::default(), period)
            .unwrap()
            .without_work();
        let (_, _, grid) = rk
            .flow_with_sensitivity_and_steps(&device, 0.0, &y0, period)
            .unwrap();
        let (_, phi) = rk
            .flow_with_sensitivity_on_grid(&device, &grid, &y0)
            .unwrap();
        let v0 = y0.compact(2);
        let map = |v: &nalgebra::DVector<f64>| {
            let y = State::from_compact(2, v);
            rk.integrate_on_grid(&device, &grid, &y, &[], &mut |_, _, _| Ok(()))
                .unwrap()
                .compact(2)
        };
        let size = phi.amax();
        for j in 0..4 {
            let delta = 1e-6 * (1.0 + v0[j].abs());
            let (mut plus, mut minus) = (v0.clone(), v0.clone());
            plus[j] += delta;
            minus[j] -= delta;
            let column = (map(&plus) - map(&minus)) / (2.0 * delta);
            for i in 0..4 {
                assert!(
                    (phi[(i, j)] - column[i]).abs() <= 1e-7 * size,
                    "Φ[{i}][{j}]: {} vs {}",
                    phi[(i, j)],
                    column[i]
                );
            }
        }
    }
}
