//! The analytic Jacobian of the linear-map drivetrain coordinates (`OdeSystem::variational`)
//! against central differences, finite differences of the period map, and Liouville's formula.

use nalgebra::{DMatrix, Matrix2};
use paritysim_dynamics::integrate::{Method, OdeSystem, RungeKutta};
use paritysim_dynamics::{Integrator, Result, State};
use paritysim_kinematics::drivetrain::LinearDifferential;

use super::*;

const PERIOD: f64 = 1.0 / 0.110;

fn linear_map() -> Drivetrain {
    Drivetrain::LinearDifferential(LinearDifferential::new(2.5, 2.5, 1.0).unwrap())
}

/// The §3.3 drag device at Ω^L = 0.6 Ω^R and K2 = 10.
fn drag_device() -> Device {
    parity_device_with(
        0.6 * 31.3,
        10.0,
        "drag_parity_fixed",
        Formulation::Auto,
        linear_map(),
    )
}

/// Unequal wings with hardening stroke springs off their rest angles: every term of the
/// Jacobian (cubic spring, rest angle, unequal inertias and drags) is exercised.
fn sprung_device() -> Device {
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
    two_wing_device(
        [wing(24.0, 17.0, 0.1), wing(31.0, 31.3, -0.2)],
        "drag_parity_fixed",
        linear_map(),
        35.0,
        Actuator::thesis(Waveform::sine(50.0, 110.0, 0.0, 0.3).unwrap()),
        Formulation::Auto,
    )
}

/// The sprung device with an actuator of mass, damping and cubic stiffness and a damped,
/// hardening whippletree (issue 35): the drive load's slope `∂Q/∂q` varies with `q` and its
/// damping `∂Q/∂q̇` enters the velocity block.
fn lossy_device() -> Device {
    let sprung = sprung_device();
    let spec = sprung.spec();
    let actuator = Actuator::thesis(Waveform::sine(50.0, 110.0, 0.0, 0.3).unwrap())
        .with_dynamics(30.0, 12.0, 4.0e3)
        .unwrap();
    let transmission = Transmission::new(linear_map(), 35.0)
        .unwrap()
        .with_balance_losses(0.8, 60.0)
        .unwrap();
    Device::new(DeviceSpec {
        actuator: Some(actuator),
        transmission: Some(transmission),
        ..spec.clone()
    })
    .unwrap()
}

/// The device with only its right-hand side: the variational equations fall back to central
/// differences.
struct WithoutJacobian<'a>(&'a Device);

impl OdeSystem for WithoutJacobian<'_> {
    fn rhs(&self, t: f64, y: &State, dydt: &mut State) -> Result<()> {
        self.0.rhs(t, y, dydt)
    }
    fn n_active(&self) -> usize {
        self.0.n_dof()
    }
}

fn state(v: [f64; 4]) -> State {
    let mut y = State::default();
    y.coords[..2].copy_from_slice(&v[..2]);
    y.rates[..2].copy_from_slice(&v[2..]);
    y
}

fn compact_rhs(device: &Device, t: f64, v: [f64; 4]) -> [f64; 4] {
    let mut d = State::default();
    device.rhs(t, &state(v), &mut d).unwrap();
    [d.coords[0], d.coords[1], d.rates[0], d.rates[1]]
}

/// Deterministic uniform numbers in [-1, 1) (a 64-bit LCG).
fn uniform(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    (*seed >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

#[test]
fn analytic_jacobian_equals_central_differences_on_random_states() {
    let mut seed = 12;
    let eye: Vec<f64> = DMatrix::<f64>::identity(4, 4).iter().copied().collect();
    for device in [drag_device(), sprung_device(), lossy_device()] {
        let mut checked = 0;
        while checked < 200 {
            let v = [
                0.4 * uniform(&mut seed),
                0.5 * uniform(&mut seed),
                2.0 * uniform(&mut seed),
                3.0 * uniform(&mut seed),
            ];
            // Away from the φ̇ = 0 kink of the drag, where the Jacobian jumps.
            let rates = [-2.5 * v[2] + 6.25 * v[3], -2.5 * v[2] - 6.25 * v[3]];
            if rates.iter().any(|r| r.abs() < 0.05) {
                continue;
            }
            checked += 1;
            let t = PERIOD * (0.5 + 0.5 * uniform(&mut seed));
            let mut jac = [0.0; 16];
            device
                .variational(t, &state(v), 2, &eye, &mut jac)
                .expect("the linear map has an analytic Jacobian")
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
fn only_the_linear_map_has_an_analytic_jacobian() {
    let linkage = parity_device(0.6 * 31.3, 10.0, "drag_parity_fixed", Formulation::Auto);
    let (phi, mut dphi) = ([0.0; 16], [0.0; 16]);
    assert!(
        linkage
            .variational(0.0, &State::default(), 2, &phi, &mut dphi)
            .is_none()
    );
    // The null-space form of the same linear-map device integrates other coordinates.
    let null_space = parity_device_with(
        0.6 * 31.3,
        10.0,
        "drag_parity_fixed",
        Formulation::NullSpace,
        linear_map(),
    );
    assert!(
        null_space
            .variational(0.0, &State::default(), 2, &phi, &mut dphi)
            .is_none()
    );
}

/// A state on the way to the orbit (one period from rest), where both wings move.
fn start(device: &Device, rk: &RungeKutta) -> State {
    rk.advance(device, 0.0, &State::default(), PERIOD)
        .unwrap()
        .without_work()
}

#[test]
fn monodromy_equals_finite_differences_of_the_period_map_and_the_difference_fallback() {
    let rk = RungeKutta::new(Method::Dop853, 1e-10, 1e-12, 100_000)
        .unwrap()
        .with_work(false);
    for device in [drag_device(), sprung_device(), lossy_device()] {
        let y0 = start(&device, &rk);
        let (_, _, grid) = rk
            .flow_with_sensitivity_and_steps(&device, 0.0, &y0, PERIOD)
            .unwrap();
        // On a fixed grid the period map is a smooth function of y0: Φ is its derivative.
        let (_, phi) = rk
            .flow_with_sensitivity_on_grid(&device, &grid, &y0)
            .unwrap();
        let (_, phi_differences) = rk
            .flow_with_sensitivity_on_grid(&WithoutJacobian(&device), &grid, &y0)
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
                assert!(
                    (phi[(i, j)] - phi_differences[(i, j)]).abs() <= 1e-8 * size,
                    "Φ[{i}][{j}]: {} vs {} by differences",
                    phi[(i, j)],
                    phi_differences[(i, j)]
                );
            }
        }
    }
}

/// The device's state `(q, q̇)` with `∫ tr J dt` in a third coordinate, `tr J` computed
/// from the spec (wing inertias, the drivetrain's Jacobian, the drag coefficients), not from
/// the device's constants: `tr J = tr(M_q⁻¹ ∂Q/∂q̇)`, `M_q = Σ I_k J_kᵀ J_k`,
/// `∂Q/∂q̇ = Σ −2 Ω_k |φ̇_k| J_kᵀ J_k` (only the rate rows of `J` carry a diagonal).
struct WithTrace<'a> {
    device: &'a Device,
    inertia: [f64; 2],
    omega: [f64; 2],
}

impl WithTrace<'_> {
    fn trace(&self, y: &State) -> f64 {
        let Some(tr) = &self.device.spec().transmission else {
            unreachable!()
        };
        let jac: Matrix2<f64> = tr
            .kinematics()
            .evaluate(y.coords[0], y.coords[1])
            .unwrap()
            .jacobian;
        let rate = jac * nalgebra::Vector2::new(y.rates[0], y.rates[1]);
        let (mut mass, mut damping) = (Matrix2::zeros(), Matrix2::zeros());
        for k in 0..2 {
            let row = jac.row(k).transpose();
            let outer = row * row.transpose();
            mass += self.inertia[k] * outer;
            damping += -2.0 * self.omega[k] * rate[k].abs() * outer;
        }
        (mass.try_inverse().unwrap() * damping).trace()
    }
}

impl OdeSystem for WithTrace<'_> {
    fn rhs(&self, t: f64, y: &State, dydt: &mut State) -> Result<()> {
        let mut inner = y.without_work();
        inner.coords[2] = 0.0;
        self.device.rhs(t, &inner, dydt)?;
        dydt.coords[2] = self.trace(&inner);
        Ok(())
    }
    fn n_active(&self) -> usize {
        3
    }
}

#[test]
fn liouville_det_monodromy_equals_exp_of_the_integrated_trace() {
    let rk = RungeKutta::new(Method::Dop853, 1e-13, 1e-15, 1_000_000)
        .unwrap()
        .with_work(false);
    for (device, inertia, omega) in [
        (drag_device(), [29.0, 29.0], [0.6 * 31.3, 31.3]),
        (sprung_device(), [24.0, 31.0], [17.0, 31.3]),
    ] {
        let y0 = start(&device, &rk);
        let (_, phi) = rk.flow_with_sensitivity(&device, 0.0, &y0, PERIOD).unwrap();
        let traced = WithTrace {
            device: &device,
            inertia,
            omega,
        };
        let tight = RungeKutta::new(Method::Dop853, 1e-13, 1e-15, 1_000_000).unwrap();
        let end = tight.advance(&traced, 0.0, &y0, PERIOD).unwrap();
        let log_det = phi.determinant().ln();
        let integral = end.coords[2];
        // The drag contracts phase space strongly over a period (|∫ tr J| of order 10).
        assert!(integral < -1.0, "{integral}");
        // Φ is not error-controlled, and its coefficient jumps at each φ̇ = 0: measured
        // 2.6e-7 relative at rtol 1e-11, 1.2e-8 at 1e-13 (the §3.3 device).
        assert!(
            (log_det - integral).abs() <= 1e-7 * integral.abs(),
            "ln det Φ = {log_det} vs ∫ tr J = {integral}"
        );
    }
}
