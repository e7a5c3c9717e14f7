//! Integration tests of paritysim-dynamics: each checks physics against an independent
//! formulation or a conservation law, never against recorded outputs.

#[path = "dynamics/continuation.rs"]
mod continuation;
#[path = "dynamics/drive.rs"]
mod drive;
#[path = "dynamics/floquet/mod.rs"]
mod floquet;
#[path = "dynamics/lanes.rs"]
mod lanes;
#[path = "dynamics/lean.rs"]
mod lean;
#[path = "dynamics/linear_jacobian.rs"]
mod linear_jacobian;
#[path = "dynamics/metrics.rs"]
mod metrics;
#[path = "dynamics/polynomial.rs"]
mod polynomial;
#[path = "dynamics/sensitivity.rs"]
mod sensitivity;
#[path = "dynamics/steady_state.rs"]
mod steady_state;
#[path = "dynamics/sweep.rs"]
mod sweep;

use approx::assert_relative_eq;
use nalgebra::{Matrix3, Vector3};
use paritysim_constraints::{Constraints, Vec6};
use paritysim_dynamics::device::{Device, DeviceSpec, Formulation, Transmission};
use paritysim_dynamics::simulate::PerturbTarget;
use paritysim_dynamics::{
    Actuator, DcOffset, JointSpring, Perturbation, SimulationOptions, Waveform, Wing, WingAero,
    simulate,
};
use paritysim_kinematics::drivetrain::{HmfFourBar, LinkageDifferential};
use paritysim_kinematics::{Drivetrain, RodCrank, SphericalShoulder};

fn shoulder(a2: f64, a3: f64) -> SphericalShoulder {
    SphericalShoulder::new(a2.to_radians(), a3.to_radians()).unwrap()
}

/// A full, positive-definite inertia tensor with Ixz ≠ 0 (a Table 3.3-like wing, mg·mm²).
fn full_inertia() -> Matrix3<f64> {
    Matrix3::new(29.0, 0.4, -3.1, 0.4, 30.5, 0.7, -3.1, 0.7, 2.2)
}

fn springs(k: [f64; 6]) -> [JointSpring; 6] {
    k.map(|k| JointSpring::linear(k, 0.0).unwrap())
}

/// A fixed-wing study wing: stroke inertia 29 mg·mm² (§3.3.2), no joint springs.
fn fixed_wing(aero: WingAero) -> Wing {
    let inertia = Matrix3::from_diagonal(&Vector3::new(29.0, 29.0, 1.0));
    Wing::new(
        shoulder(90.0, 0.0),
        inertia,
        [JointSpring::default(); 6],
        aero,
    )
    .unwrap()
}

/// Quadratic stroke drag with unit coefficient (eq. 2.16).
fn drag(omega: f64) -> WingAero {
    WingAero::stroke_drag(omega, 1.0).unwrap()
}

/// Two wings on a drivetrain driven by an actuator.
fn two_wing_device(
    wings: [Wing; 2],
    config: &str,
    drivetrain: Drivetrain,
    k2: f64,
    actuator: Actuator,
    formulation: Formulation,
) -> Device {
    Device::new(DeviceSpec {
        wings: wings.to_vec(),
        constraints: Constraints::configuration(config).unwrap(),
        transmission: Some(Transmission::new(drivetrain, k2).unwrap()),
        actuator: Some(actuator),
        formulation,
    })
    .unwrap()
}

fn hmf_drivetrain() -> Drivetrain {
    Drivetrain::HmfFourBar(HmfFourBar::new(RodCrank::THESIS))
}

// ------------------------------------------------------------- M and c

/// Angular velocity in frame 6 from finite differences of R_6^1 (independent of J6).
fn omega_fd(sh: &SphericalShoulder, p: &Vector3<f64>, v: &Vector3<f64>) -> Vector3<f64> {
    let h = 1e-6;
    let r = |s: f64| {
        sh.pose(p.x + v.x * s, p.y + v.y * s, p.z + v.z * s)
            .unwrap()
            .link_rotations[5]
    };
    let w = r(0.0).transpose() * (r(h) - r(-h)) / (2.0 * h);
    Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)])
}

/// `M = J6ᵀ I J6` with J6's columns from finite-differenced rotations.
fn mass_fd(sh: &SphericalShoulder, inertia: &Matrix3<f64>, p: &Vector3<f64>) -> Matrix3<f64> {
    let j = Matrix3::from_columns(&[
        omega_fd(sh, p, &Vector3::x()),
        omega_fd(sh, p, &Vector3::y()),
        omega_fd(sh, p, &Vector3::z()),
    ]);
    j.transpose() * inertia * j
}

#[test]
fn mass_and_coriolis_match_christoffel_symbols() {
    let inertia = full_inertia();
    for (a2, a3) in [(90.0, 0.0), (120.0, 60.0)] {
        let sh = shoulder(a2, a3);
        let wing = Wing::new(sh, inertia, [JointSpring::default(); 6], WingAero::None).unwrap();
        let states = [
            (Vector3::new(0.3, -0.2, 0.5), Vector3::new(0.7, -0.4, 1.3)),
            (Vector3::new(-0.6, 0.35, -0.9), Vector3::new(-1.1, 0.5, 0.2)),
            (Vector3::new(0.1, 0.5, 1.2), Vector3::new(0.3, 0.9, -0.8)),
        ];
        for (p, v) in states {
            let terms = wing.terms(&p, &v).unwrap();
            let m_fd = mass_fd(&sh, &inertia, &p);
            assert_relative_eq!(terms.mass, m_fd, epsilon = 1e-6, max_relative = 1e-6);
            // c_i = Σ_jk Γ_ijk v_j v_k with Γ from finite differences of our own M(p), which the
            // line above ties to the independent M.
            let h = 1e-5;
            let dm: Vec<Matrix3<f64>> = (0..3)
                .map(|k| {
                    let e = Vector3::ith(k, h);
                    (wing.terms(&(p + e), &v).unwrap().mass
                        - wing.terms(&(p - e), &v).unwrap().mass)
                        / (2.0 * h)
                })
                .collect();
            let mut c = Vector3::zeros();
            for i in 0..3 {
                for j in 0..3 {
                    for k in 0..3 {
                        c[i] += 0.5 * (dm[k][(i, j)] + dm[j][(i, k)] - dm[i][(j, k)]) * v[j] * v[k];
                    }
                }
            }
            assert_relative_eq!(terms.coriolis, c, epsilon = 1e-6, max_relative = 1e-6);
        }
    }
}

// ------------------------------------------------------------- energy

fn free_wing_device(formulation: Formulation) -> Device {
    let wing = Wing::new(
        shoulder(120.0, 60.0),
        full_inertia(),
        springs([20.0, 3.0, 2.0, 15.0, 4.0, 1.5]),
        WingAero::None,
    )
    .unwrap();
    Device::new(DeviceSpec {
        wings: vec![wing],
        constraints: Constraints::none(3).unwrap(),
        transmission: None,
        actuator: None,
        formulation,
    })
    .unwrap()
}

#[test]
fn unforced_wing_conserves_energy_over_100_oscillations() {
    use paritysim_dynamics::integrate::{Integrator, Method, RungeKutta};
    let device = free_wing_device(Formulation::NullSpace);
    let p0 = Vec6::new(0.4, -0.2, 0.6, 0.0, 0.0, 0.0);
    let v0 = Vec6::new(0.1, 0.05, -0.2, 0.0, 0.0, 0.0);
    let mut y = device.state_from(&p0, &v0).unwrap();
    let energy = |y: &paritysim_dynamics::State, t: f64| {
        let (p, v) = device.coordinates(y).unwrap();
        device.energy(&device.evaluate(t, &p, &v).unwrap())
    };
    let e0 = energy(&y, 0.0);
    let rk = RungeKutta::new(Method::Dop853, 1e-13, 1e-15, 1_000_000).unwrap();
    // Slowest mode: φ with I ≈ 29 mg·mm² and k ≈ 20 mN·mm/rad: period ≈ 7.6 ms. Each segment ends
    // on a solver step (dense output between steps is less accurate than the steps themselves).
    let (segment, mut t, mut worst, mut phi_max) = (7.6, 0.0, 0.0f64, 0.0f64);
    for _ in 0..100 {
        y = rk
            .integrate(&device, t, &y, t + segment, &[t + segment])
            .unwrap()[0];
        t += segment;
        worst = worst.max((energy(&y, t) - e0).abs() / e0);
        phi_max = phi_max.max(device.coordinates(&y).unwrap().0[0].abs());
    }
    assert!(worst < 1e-9, "relative energy drift {worst:e}");
    assert!(phi_max > 0.1, "it really oscillates");
}

fn parity_device(omega_left: f64, k2: f64, config: &str, formulation: Formulation) -> Device {
    parity_device_with(
        omega_left,
        k2,
        config,
        formulation,
        Drivetrain::LinkageDifferential(LinkageDifferential::thesis()),
    )
}

/// Long runs use eq. 2.15 (no reach limit): with a soft K2 the start-up transient of the
/// whippletree is slow and large.
fn linear_parity(omega_left: f64, formulation: Formulation) -> Device {
    let linear = Drivetrain::LinearDifferential(
        paritysim_kinematics::drivetrain::LinearDifferential::new(2.5, 2.5, 1.0).unwrap(),
    );
    parity_device_with(omega_left, 20.0, "drag_parity_fixed", formulation, linear)
}

fn parity_device_with(
    omega_left: f64,
    k2: f64,
    config: &str,
    formulation: Formulation,
    drivetrain: Drivetrain,
) -> Device {
    let wing = |omega: f64| fixed_wing(drag(omega));
    // 50 V keeps the unit-coefficient drag device inside the linkage's reach (about ±48°).
    let actuator = Actuator::thesis(Waveform::sine(50.0, 110.0, 0.0, 0.0).unwrap());
    two_wing_device(
        [wing(omega_left), wing(31.3)],
        config,
        drivetrain,
        k2,
        actuator,
        formulation,
    )
}

#[test]
fn actuator_work_equals_dissipation_plus_energy_change() {
    let device = parity_device(18.75, 5.0, "drag_parity_fixed", Formulation::NullSpace);
    let options = SimulationOptions {
        rtol: 1e-12,
        atol: 1e-13,
        max_cycles: 3,
        min_cycles: 3,
        ..Default::default()
    };
    let r = simulate(&device, &options).unwrap();
    let t = &r.trajectory;
    let energy = t.column("mechanical_energy").unwrap();
    let w_act = *t.column("work_actuator").unwrap().last().unwrap();
    let w_aero = *t.column("work_aero").unwrap().last().unwrap();
    let delta_e = energy.last().unwrap() - energy[0];
    let balance = (w_act + w_aero - delta_e).abs() / w_act.abs();
    assert!(
        w_aero < 0.0 && w_act > 0.0,
        "aero dissipates, actuator injects: {w_act} {w_aero}"
    );
    assert!(balance < 1e-6, "energy balance residual {balance:e}");
}

// ------------------------------------------------------------- constraints

#[test]
fn null_space_cannot_drift_over_1000_wingbeats() {
    let device = linear_parity(18.75, Formulation::NullSpace);
    let options = SimulationOptions {
        max_cycles: 1000,
        min_cycles: 1000,
        steady_tol: 1e-30,
        ..Default::default()
    };
    let r = simulate(&device, &options).unwrap();
    assert_eq!(r.cycles_run, 1000);
    let c = Constraints::configuration("drag_parity_fixed").unwrap();
    let t = &r.trajectory;
    for i in 0..t.time.len() {
        let p = Vec6::from_fn(|k, _| {
            t.column(&format!(
                "{}_{}",
                if k < 3 { "left" } else { "right" },
                ["phi", "theta", "psi"][k % 3]
            ))
            .unwrap()[i]
        });
        assert!(c.residual(&p) < 1e-12);
    }
}

#[test]
fn dense_output_conserves_energy_as_well_as_the_steps() {
    // docs/findings.md item 4: with Hairer's CONTD8 the interpolated samples are as good as
    // the steps (the old crate's interpolant was O(h^5): 5e-9 against 6e-14).
    use paritysim_dynamics::integrate::{Integrator, Method, RungeKutta};
    let device = free_wing_device(Formulation::NullSpace);
    let p0 = Vec6::new(0.4, -0.2, 0.6, 0.0, 0.0, 0.0);
    let v0 = Vec6::new(0.1, 0.05, -0.2, 0.0, 0.0, 0.0);
    let y0 = device.state_from(&p0, &v0).unwrap();
    let energy = |y: &paritysim_dynamics::State, t: f64| {
        let (p, v) = device.coordinates(y).unwrap();
        device.energy(&device.evaluate(t, &p, &v).unwrap())
    };
    let e0 = energy(&y0, 0.0);
    let rk = RungeKutta::new(Method::Dop853, 1e-13, 1e-15, 1_000_000).unwrap();
    let times: Vec<f64> = (0..20_000).map(|k| 0.0381 * k as f64 + 0.01).collect();
    let mut worst: f64 = 0.0;
    rk.integrate_with(&device, 0.0, &y0, 762.0, &times, &mut |_, t, y| {
        worst = worst.max((energy(y, t) - e0).abs() / e0);
        Ok(())
    })
    .unwrap();
    assert!(
        worst < 1e-11,
        "relative energy error at dense samples {worst:e}"
    );
}

#[test]
fn projection_agrees_with_null_space() {
    let options = SimulationOptions {
        rtol: 1e-13,
        atol: 1e-14,
        max_cycles: 5,
        min_cycles: 5,
        ..Default::default()
    };
    let a = simulate(&linear_parity(13.15, Formulation::NullSpace), &options).unwrap();
    let b = simulate(&linear_parity(13.15, Formulation::Projection), &options).unwrap();
    for name in ["left_phi", "right_phi", "left_phi_dot", "q2"] {
        let (x, y) = (
            a.trajectory.column(name).unwrap(),
            b.trajectory.column(name).unwrap(),
        );
        let err = x
            .iter()
            .zip(y)
            .map(|(u, v)| (u - v).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-8, "{name}: {err:e}");
    }
}

#[test]
fn symmetric_parity_stays_symmetric_and_hmf_keeps_strokes_equal() {
    let options = SimulationOptions {
        max_cycles: 10,
        ..Default::default()
    };
    let r = simulate(
        &parity_device(31.3, 0.0, "drag_parity_fixed", Formulation::NullSpace),
        &options,
    )
    .unwrap();
    let (l, rr) = (
        r.trajectory.column("left_phi").unwrap(),
        r.trajectory.column("right_phi").unwrap(),
    );
    for (a, b) in l.iter().zip(rr) {
        assert!((a - b).abs() < 1e-9);
    }
    let roll = r.trajectory.column("roll_total").unwrap();
    assert!(
        roll.iter().all(|v| v.abs() < 1e-8),
        "symmetric device has no net roll torque"
    );

    let wing = |omega: f64| fixed_wing(drag(omega));
    let actuator = Actuator::thesis(Waveform::sine(50.0, 110.0, 0.0, 0.0).unwrap());
    let hmf = two_wing_device(
        [wing(18.75), wing(31.3)],
        "hmf_fixed",
        hmf_drivetrain(),
        0.0,
        actuator,
        Formulation::NullSpace,
    );
    let r = simulate(&hmf, &options).unwrap();
    let (l, rr) = (
        r.trajectory.column("left_phi").unwrap(),
        r.trajectory.column("right_phi").unwrap(),
    );
    assert!(
        l.iter().zip(rr).all(|(a, b)| (a - b).abs() < 1e-13),
        "hmf: phi_L == phi_R to round-off"
    );
    assert!(
        r.metrics
            .iter()
            .any(|(n, v)| n == "left_stroke_amplitude" && *v > 0.1)
    );
}

#[test]
fn inconsistent_initial_state_and_bad_devices_are_rejected() {
    let rows = vec![
        vec![1.0, 0.0, 0.0, -1.0, 0.0, 0.0],
        vec![0.0, 1.0, 0.0, 0.0, 0.0, 0.0],
    ];
    let c = Constraints::new(6, &rows, &[0.0, 0.0]).unwrap();
    let sh = shoulder(90.0, 0.0);
    let wing = Wing::stroke_only(sh, 29.0, WingAero::None).unwrap();
    let device = Device::new(DeviceSpec {
        wings: vec![wing.clone(), wing.clone()],
        constraints: c,
        transmission: None,
        actuator: None,
        formulation: Formulation::NullSpace,
    })
    .unwrap();
    let options = SimulationOptions {
        initial: Some((Vec6::new(0.1, 0.0, 0.0, 0.2, 0.0, 0.0), Vec6::zeros())),
        duration_ms: Some(1.0),
        ..Default::default()
    };
    let err = simulate(&device, &options).unwrap_err();
    assert_eq!(err.kind(), "Constraint", "{err}");

    // A 1-DOF drivetrain on two wings not tied by C.
    let err = Device::new(DeviceSpec {
        wings: vec![wing.clone(), wing.clone()],
        constraints: Constraints::configuration("drag_parity_fixed").unwrap(),
        transmission: Some(
            Transmission::new(
                Drivetrain::HmfFourBar(HmfFourBar::new(RodCrank::THESIS)),
                0.0,
            )
            .unwrap(),
        ),
        actuator: None,
        formulation: Formulation::NullSpace,
    })
    .unwrap_err();
    assert_eq!(err.kind(), "Constraint");
    // Non-positive-definite inertia names the field.
    let err = Wing::new(
        sh,
        Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, 1.0)),
        [JointSpring::default(); 6],
        WingAero::None,
    )
    .unwrap_err();
    assert_eq!(err.field(), Some("inertia"));
    assert_eq!(
        Waveform::sine(1.0, 0.0, 0.0, 0.0).unwrap_err().field(),
        Some("frequency_hz")
    );
    assert_eq!(
        Waveform::sampled(vec![], vec![], 1.0).unwrap_err().field(),
        Some("times_ms")
    );
}

#[test]
fn integration_failure_carries_time_and_state() {
    // A huge force drives the linkage beyond its reach: the model error surfaces as an
    // integration error with the time and state where it happened.
    let wing = |omega: f64| fixed_wing(drag(omega));
    let actuator = Actuator::new(
        1.2,
        467.0,
        Waveform::sine(5000.0, 110.0, 0.0, 0.0).unwrap(),
        DcOffset::AsForce,
    )
    .unwrap();
    let linkage = Drivetrain::LinkageDifferential(LinkageDifferential::thesis());
    let device = two_wing_device(
        [wing(31.3), wing(31.3)],
        "drag_parity_fixed",
        linkage,
        0.0,
        actuator,
        Formulation::NullSpace,
    );
    match simulate(&device, &SimulationOptions::default()) {
        Err(paritysim_dynamics::Error::Integration { time, state, .. }) => {
            assert!(time > 0.0 && time < 10.0);
            assert_eq!(state.len(), 14);
        }
        other => panic!("expected an integration error, got {other:?}"),
    }
}

#[test]
fn whippletree_kick_decays_for_parity() {
    let device = linear_parity(18.75, Formulation::NullSpace);
    let kick = Perturbation {
        target: PerturbTarget::WhippletreeRate,
        delta: 0.002,
        phase: 0.0,
    };
    let options = SimulationOptions {
        max_cycles: 200,
        record_cycles: 3,
        perturbation: Some(kick),
        ..Default::default()
    };
    let kicked = simulate(&device, &options).unwrap();
    let base = simulate(
        &device,
        &SimulationOptions {
            perturbation: None,
            ..options.clone()
        },
    )
    .unwrap();
    // The aerodynamic damping of the whippletree mode (eq. 2.19) removes the kicked velocity
    // within a few ms; the displaced q2 then relaxes slowly through K2 (overdamped mode).
    let (a, b) = (
        kicked.trajectory.column("q2_dot").unwrap(),
        base.trajectory.column("q2_dot").unwrap(),
    );
    let n = a.len();
    let early = (0..n / 6).map(|i| (a[i] - b[i]).abs()).fold(0.0, f64::max);
    let late = (5 * n / 6..n)
        .map(|i| (a[i] - b[i]).abs())
        .fold(0.0, f64::max);
    assert!(early > 1e-6, "the kick is visible: {early:e}");
    assert!(
        late < 0.1 * early,
        "and decays: early {early:e}, late {late:e}"
    );
}

/// The blade-element model of crates/aero on a fixed wing (ψ = θ = 0, α = 90°) is the stroke
/// drag of eq. 3.8 with `C = C_N(90°)`: two formulations, one trajectory.
#[test]
fn blade_element_fixed_wing_equals_stroke_drag_with_cn90() {
    use paritysim_aero::{BladeElementModel, CoefficientModel, CoefficientSet, Omegas};
    let coefficients = CoefficientSet::default();
    let cn90 = coefficients
        .coefficients(std::f64::consts::FRAC_PI_2)
        .normal;
    assert!(cn90 > 3.0 && cn90 < 4.0, "Dickinson C_N(90°) = {cn90}");
    let blade =
        BladeElementModel::new(Omegas::new(31.3, 0.6, 17.0, 0.7).unwrap(), coefficients).unwrap();
    // The generalised stroke torque is the same function of the state, to round-off.
    let (wb, wd) = (
        fixed_wing(WingAero::BladeElement(blade)),
        fixed_wing(WingAero::stroke_drag(31.3, cn90).unwrap()),
    );
    for k in 0..50 {
        let (phi, rate) = (-0.8 + 0.032 * k as f64, (k as f64 * 0.37).sin() * 0.7);
        let (p, v) = (Vector3::new(phi, 0.0, 0.0), Vector3::new(rate, 0.0, 0.0));
        let (a, b) = (
            wb.terms(&p, &v).unwrap().aero[0],
            wd.terms(&p, &v).unwrap().aero[0],
        );
        assert!(
            (a - b).abs() <= 1e-12 * (1.0 + b.abs()),
            "phi {phi} rate {rate}: {a} vs {b}"
        );
    }
    let make = |aero: WingAero| {
        let actuator = Actuator::thesis(Waveform::sine(100.0, 110.0, 0.0, 0.0).unwrap());
        two_wing_device(
            [fixed_wing(aero.clone()), fixed_wing(aero)],
            "hmf_fixed",
            hmf_drivetrain(),
            0.0,
            actuator,
            Formulation::NullSpace,
        )
    };
    // M_T and M_r act on the constrained θ, ψ and enter only through round-off of the null-space
    // basis (1e-17), which can change adaptive step decisions: compare at a tight tolerance.
    let options = SimulationOptions {
        rtol: 1e-12,
        atol: 1e-14,
        max_cycles: 8,
        min_cycles: 8,
        steady_tol: 1e-30,
        ..Default::default()
    };
    let a = simulate(&make(WingAero::BladeElement(blade)), &options).unwrap();
    let b = simulate(&make(WingAero::stroke_drag(31.3, cn90).unwrap()), &options).unwrap();
    for name in ["left_phi", "right_roll_aero", "actuator_power"] {
        let (x, y) = (
            a.trajectory.column(name).unwrap(),
            b.trajectory.column(name).unwrap(),
        );
        let scale = y.iter().map(|v| v.abs()).fold(1e-300, f64::max);
        let err = x
            .iter()
            .zip(y)
            .map(|(u, v)| (u - v).abs())
            .fold(0.0, f64::max)
            / scale;
        assert!(err < 1e-7, "{name}: relative {err:e}");
    }
}

/// (configuration, drivetrain, K2) of a cross-check case.
type Case = (&'static str, fn() -> Drivetrain, f64);

/// Drivetrain coordinates (q, forward map only) against the general null-space formulation
/// (wing coordinates, inverse kinematics, full shoulder): the same trajectories.
#[test]
fn drivetrain_coordinates_agree_with_null_space() {
    // 60 V: the cut (lighter) left wing strokes further and must stay inside the linkage's reach.
    let actuator = || Actuator::thesis(Waveform::sine(60.0, 110.0, 0.0, 0.0).unwrap());
    let wing = |omega: f64| fixed_wing(WingAero::stroke_drag(omega, 3.4609).unwrap());
    let linkage = || Drivetrain::LinkageDifferential(LinkageDifferential::thesis());
    let cases: [Case; 3] = [
        (
            "drag_parity_fixed",
            || {
                Drivetrain::LinearDifferential(
                    paritysim_kinematics::drivetrain::LinearDifferential::new(2.5, 2.5, 1.0)
                        .unwrap(),
                )
            },
            20.0,
        ),
        (
            "drag_parity_fixed",
            || Drivetrain::LinkageDifferential(LinkageDifferential::thesis()),
            500.0,
        ),
        ("hmf_fixed", hmf_drivetrain, 0.0),
    ];
    for (config, drivetrain, k2) in cases {
        let make = |f: Formulation| {
            two_wing_device(
                [wing(18.75), wing(31.3)],
                config,
                drivetrain(),
                k2,
                actuator(),
                f,
            )
        };
        let fast = make(Formulation::Auto);
        assert_eq!(
            fast.formulation(),
            Formulation::DrivetrainCoordinates,
            "{config}"
        );
        // Compare step-aligned end states (dense output between steps is only ~1e-8 accurate).
        use paritysim_dynamics::integrate::{Integrator, Method, RungeKutta};
        let rk = RungeKutta::new(Method::Dop853, 1e-12, 1e-14, 1_000_000).unwrap();
        let general = make(Formulation::NullSpace);
        let period = 1.0 / 0.110;
        for cycles in [1.0, 3.0, 6.0] {
            let end = |d: &Device| {
                let y0 = d.state_from(&Vec6::zeros(), &Vec6::zeros()).unwrap();
                let y = rk
                    .integrate(d, 0.0, &y0, cycles * period, &[cycles * period])
                    .unwrap()[0];
                (d.coordinates(&y).unwrap(), y.work_actuator, y.work_aero)
            };
            let (((pa, va), wa, aa), ((pb, vb), wb, ab)) = (end(&fast), end(&general));
            let rel = |a: f64, b: f64| (a - b).abs() / (1e-3 + b.abs());
            for k in [0, 3] {
                assert!(
                    rel(pa[k], pb[k]) < 1e-9,
                    "{config} {cycles} cycles phi[{k}]: {} vs {}",
                    pa[k],
                    pb[k]
                );
                assert!(
                    rel(va[k], vb[k]) < 1e-9,
                    "{config} {cycles} cycles phi_dot[{k}]: {} vs {}",
                    va[k],
                    vb[k]
                );
            }
            assert!(
                rel(wa, wb) < 1e-9 && rel(aa, ab) < 1e-9,
                "{config}: work {wa} vs {wb}, aero {aa} vs {ab}"
            );
        }
    }
    // Rotating wings cannot use it: Auto falls back, an explicit request is a typed error.
    let rotating = |f: Formulation| {
        Device::new(DeviceSpec {
            wings: vec![wing(31.3), wing(31.3)],
            constraints: Constraints::configuration("drag_parity").unwrap(),
            transmission: Some(Transmission::new(linkage(), 0.0).unwrap()),
            actuator: Some(actuator()),
            formulation: f,
        })
    };
    assert_eq!(
        rotating(Formulation::Auto).unwrap().formulation(),
        Formulation::NullSpace
    );
    let err = rotating(Formulation::DrivetrainCoordinates).unwrap_err();
    assert!(err.to_string().contains("theta and psi"), "{err}");
}

// A global allocator needs `unsafe impl`; this test-only module is the one place that allows it.
#[allow(unsafe_code)]
mod allocation {
    //! "No heap allocation inside the RHS", checked with a counting global allocator that only
    //! counts on the current thread while a flag is set (tests run on several threads).
    use std::alloc::{GlobalAlloc, Layout, System};
    use std::cell::Cell;

    thread_local! {
        static COUNTING: Cell<bool> = const { Cell::new(false) };
        static COUNT: Cell<usize> = const { Cell::new(0) };
    }

    struct Counting;

    unsafe impl GlobalAlloc for Counting {
        unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
            if COUNTING.with(|c| c.get()) {
                COUNT.with(|n| n.set(n.get() + 1));
            }
            unsafe { System.alloc(layout) }
        }
        unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
            unsafe { System.dealloc(ptr, layout) }
        }
    }

    #[global_allocator]
    static ALLOCATOR: Counting = Counting;

    /// Number of allocations made by `f` on this thread.
    pub fn count<R>(f: impl FnOnce() -> R) -> (R, usize) {
        COUNT.with(|n| n.set(0));
        COUNTING.with(|c| c.set(true));
        let r = f();
        COUNTING.with(|c| c.set(false));
        (r, COUNT.with(|n| n.get()))
    }
}

#[test]
fn right_hand_side_does_not_allocate() {
    let actuator = || Actuator::thesis(Waveform::sine(100.0, 110.0, 0.0, 0.0).unwrap());
    let wing = || fixed_wing(WingAero::stroke_drag(31.3, 3.4609).unwrap());
    let linkage = || Drivetrain::LinkageDifferential(LinkageDifferential::thesis());
    let blade = paritysim_aero::BladeElementModel::new(
        paritysim_aero::Omegas::new(46.8, 0.59, 17.5, 0.71).unwrap(),
        paritysim_aero::CoefficientSet::default(),
    )
    .unwrap();
    let rotating = Wing::new(
        shoulder(120.0, 60.0),
        full_inertia(),
        springs([0.0, 0.0, 0.0, 0.0, 0.0, 3.0]),
        WingAero::BladeElement(blade),
    )
    .unwrap();
    let devices = [
        two_wing_device(
            [wing(), wing()],
            "drag_parity_fixed",
            linkage(),
            1.0,
            actuator(),
            Formulation::DrivetrainCoordinates,
        ),
        two_wing_device(
            [wing(), wing()],
            "drag_parity_fixed",
            linkage(),
            1.0,
            actuator(),
            Formulation::NullSpace,
        ),
        two_wing_device(
            [wing(), wing()],
            "drag_parity_fixed",
            linkage(),
            1.0,
            actuator(),
            Formulation::Projection,
        ),
        two_wing_device(
            [rotating.clone(), rotating],
            "drag_parity",
            linkage(),
            1.0,
            actuator(),
            Formulation::NullSpace,
        ),
    ];
    for device in &devices {
        let y = device
            .state_from(
                &Vec6::new(0.2, 0.0, 0.0, 0.25, 0.0, 0.0),
                &Vec6::new(0.3, 0.0, 0.0, 0.25, 0.0, 0.0),
            )
            .unwrap();
        let mut dydt = paritysim_dynamics::State::default();
        let (result, allocations) = allocation::count(|| {
            (0..100).try_for_each(|k| device.rhs(0.1 * k as f64, &y, &mut dydt))
        });
        result.unwrap();
        assert_eq!(
            allocations,
            0,
            "{:?}: {allocations} allocations in 100 right-hand sides",
            device.formulation()
        );
    }
    // The counter works: a Vec allocates.
    let (_, n) = allocation::count(|| vec![1.0f64; 8]);
    assert!(n >= 1);
}

/// The tunable hinge (§2.5.1): its generalised forces are the gradient of its energy, checked
/// by finite differences and by energy conservation of an undamped wing.
#[test]
fn tunable_hinge_forces_are_the_gradient_of_its_energy() {
    use paritysim_dynamics::TunableHinge;
    let hinge = TunableHinge::new(2.0, 1.5, 4.0).unwrap();
    let wing = Wing::new(
        shoulder(90.0, 0.0),
        full_inertia(),
        springs([5.0, 0.0, 0.0, 8.0, 0.0, 0.0]),
        WingAero::None,
    )
    .unwrap()
    .with_tunable_hinge(hinge);
    let h = 1e-6;
    for p in [Vector3::new(0.2, 0.3, -0.5), Vector3::new(-0.4, -0.2, 0.8)] {
        let v = Vector3::zeros();
        let t = wing.terms(&p, &v).unwrap();
        for k in 0..3 {
            let e = Vector3::ith(k, h);
            let dv = (wing.terms(&(p + e), &v).unwrap().potential
                - wing.terms(&(p - e), &v).unwrap().potential)
                / (2.0 * h);
            assert_relative_eq!(t.spring[k], dv, epsilon = 1e-7, max_relative = 1e-7);
        }
    }
    assert!(
        TunableHinge::new(1.0, 3.0, 1.0).is_err(),
        "k(theta) would go negative"
    );
    use paritysim_dynamics::integrate::{Integrator, Method, RungeKutta};
    let device = Device::new(DeviceSpec {
        wings: vec![wing],
        constraints: Constraints::none(3).unwrap(),
        transmission: None,
        actuator: None,
        formulation: Formulation::NullSpace,
    })
    .unwrap();
    let mut y = device
        .state_from(&Vec6::new(0.3, 0.2, 0.5, 0.0, 0.0, 0.0), &Vec6::zeros())
        .unwrap();
    let energy = |y: &paritysim_dynamics::State| {
        let (p, v) = device.coordinates(y).unwrap();
        device.energy(&device.evaluate(0.0, &p, &v).unwrap())
    };
    let e0 = energy(&y);
    let rk = RungeKutta::new(Method::Dop853, 1e-12, 1e-14, 1_000_000).unwrap();
    let mut worst = 0.0f64;
    for k in 0..20 {
        y = rk
            .integrate(
                &device,
                k as f64 * 10.0,
                &y,
                (k + 1) as f64 * 10.0,
                &[(k + 1) as f64 * 10.0],
            )
            .unwrap()[0];
        worst = worst.max((energy(&y) - e0).abs() / e0);
    }
    assert!(worst < 1e-8, "relative energy drift {worst:e}");
}

/// The closed-form stroke-only wing terms equal the general shoulder terms at θ = ψ = 0.
#[test]
fn stroke_terms_equal_general_terms_on_the_stroke_plane() {
    for (a2, a3) in [(90.0, 0.0), (90.0, 30.0), (90.0, 60.0)] {
        let blade = paritysim_aero::BladeElementModel::new(
            paritysim_aero::Omegas::new(46.8, 0.59, 17.5, 0.71).unwrap(),
            paritysim_aero::CoefficientSet::default(),
        )
        .unwrap();
        let wing = Wing::new(
            shoulder(a2, a3),
            full_inertia(),
            springs([3.0, 0.0, 0.0, 2.0, 0.0, 1.0]),
            WingAero::BladeElement(blade),
        )
        .unwrap();
        for (phi, rate) in [(0.3, 0.7), (-0.9, -0.2), (1.2, 0.05), (0.0, 0.0)] {
            let fast = wing
                .stroke_plane_terms(&Vector3::new(phi, 0.0, 0.0), &Vector3::new(rate, 0.0, 0.0));
            let general = wing
                .terms(&Vector3::new(phi, 0.0, 0.0), &Vector3::new(rate, 0.0, 0.0))
                .unwrap();
            let tol = 1e-12;
            assert_relative_eq!(fast.mass, general.mass, epsilon = tol);
            assert_relative_eq!(fast.coriolis, general.coriolis, epsilon = tol);
            assert_relative_eq!(fast.spring, general.spring, epsilon = tol);
            assert_relative_eq!(fast.aero, general.aero, epsilon = tol);
            assert_relative_eq!(fast.aero_frame6, general.aero_frame6, epsilon = tol);
            assert_relative_eq!(fast.j6, general.j6, epsilon = tol);
            assert_relative_eq!(fast.omega, general.omega, epsilon = tol);
            assert_relative_eq!(fast.jdot_pdot, general.jdot_pdot, epsilon = tol);
            assert_relative_eq!(fast.rotation, general.rotation, epsilon = tol);
            assert_relative_eq!(fast.potential, general.potential, epsilon = tol);
            assert_relative_eq!(fast.kinetic, general.kinetic, epsilon = tol);
            assert!(general.theta_w.abs() < tol);
        }
    }
}

/// The closed-form stroke-plane terms (θ = θ̇ = 0) equal the general shoulder terms.
#[test]
fn stroke_plane_terms_equal_general_terms() {
    use paritysim_dynamics::TunableHinge;
    for (a2, a3) in [(90.0, 0.0), (90.0, 40.0)] {
        let blade = paritysim_aero::BladeElementModel::new(
            paritysim_aero::Omegas::new(46.8, 0.59, 17.5, 0.71).unwrap(),
            paritysim_aero::CoefficientSet::default(),
        )
        .unwrap();
        let wing = Wing::new(
            shoulder(a2, a3),
            full_inertia(),
            springs([3.0, 0.0, 0.0, 2.0, 0.0, 1.5]),
            WingAero::BladeElement(blade),
        )
        .unwrap()
        .with_tunable_hinge(TunableHinge::new(2.0, 0.5, 3.0).unwrap());
        assert!(wing.has_closed_form_stroke_plane());
        for (phi, psi, rate, spin) in [
            (0.3, 0.7, 0.6, -0.4),
            (-0.9, -1.1, -0.2, 1.3),
            (1.2, 0.1, 0.05, 0.0),
        ] {
            let (p, v) = (Vector3::new(phi, 0.0, psi), Vector3::new(rate, 0.0, spin));
            let fast = wing.stroke_plane_terms(&p, &v);
            let general = wing.terms(&p, &v).unwrap();
            let tol = 1e-12;
            assert_relative_eq!(fast.mass, general.mass, epsilon = tol);
            assert_relative_eq!(fast.coriolis, general.coriolis, epsilon = tol);
            assert_relative_eq!(fast.spring, general.spring, epsilon = tol);
            assert_relative_eq!(fast.aero, general.aero, epsilon = tol);
            assert_relative_eq!(fast.j6, general.j6, epsilon = tol);
            assert_relative_eq!(fast.jdot_pdot, general.jdot_pdot, epsilon = tol);
            assert_relative_eq!(fast.rotation, general.rotation, epsilon = tol);
            assert_relative_eq!(fast.potential, general.potential, epsilon = tol);
            assert_relative_eq!(fast.kinetic, general.kinetic, epsilon = tol);
        }
    }
}

/// The closed-form free-deviation terms (α2 = 90°, α3 = 0, any θ) equal the general shoulder
/// terms (joint-angle solve of eqs. 2.11–2.13, closure partials), every field.
#[test]
fn free_deviation_terms_equal_general_terms() {
    use paritysim_dynamics::TunableHinge;
    let blade = paritysim_aero::BladeElementModel::new(
        paritysim_aero::Omegas::new(46.8, 0.59, 17.5, 0.71).unwrap(),
        paritysim_aero::CoefficientSet::default(),
    )
    .unwrap();
    let wing = Wing::new(
        shoulder(90.0, 0.0),
        full_inertia(),
        springs([3.0, 0.0, 0.0, 2.0, 0.0, 1.5]),
        WingAero::BladeElement(blade),
    )
    .unwrap()
    .with_tunable_hinge(TunableHinge::new(2.0, 0.5, 3.0).unwrap());
    assert!(wing.has_closed_form_free_deviation());
    let drag_wing = Wing::new(
        shoulder(90.0, 0.0),
        full_inertia(),
        springs([3.0, 0.0, 0.0, 2.0, 0.0, 1.5]),
        drag(31.3),
    )
    .unwrap();
    let mut checked = 0;
    for wing in [&wing, &drag_wing] {
        for k in 0..300 {
            let x = k as f64;
            // Strokes to ±80°, deviations to ±60°, rotations to ±70°, rates of both signs.
            let p = Vector3::new(
                1.4 * (0.37 * x).sin(),
                1.05 * (0.61 * x).cos(),
                1.2 * (1.3 * x).sin(),
            );
            let v = Vector3::new(
                0.8 * (0.71 * x).cos(),
                -0.5 * (0.23 * x).sin(),
                1.5 * (2.1 * x).cos(),
            );
            let fast = wing.free_deviation_terms(&p, &v).unwrap();
            let general = wing.terms(&p, &v).unwrap();
            let tol = 1e-12;
            assert_relative_eq!(fast.mass, general.mass, epsilon = tol, max_relative = tol);
            assert_relative_eq!(
                fast.coriolis,
                general.coriolis,
                epsilon = tol,
                max_relative = tol
            );
            assert_relative_eq!(
                fast.spring,
                general.spring,
                epsilon = tol,
                max_relative = tol
            );
            assert_relative_eq!(fast.aero, general.aero, epsilon = tol, max_relative = tol);
            assert_relative_eq!(
                fast.aero_frame6,
                general.aero_frame6,
                epsilon = tol,
                max_relative = tol
            );
            assert_relative_eq!(fast.j6, general.j6, epsilon = tol, max_relative = tol);
            assert_relative_eq!(fast.omega, general.omega, epsilon = tol, max_relative = tol);
            assert_relative_eq!(
                fast.jdot_pdot,
                general.jdot_pdot,
                epsilon = tol,
                max_relative = tol
            );
            assert_relative_eq!(
                fast.rotation,
                general.rotation,
                epsilon = tol,
                max_relative = tol
            );
            assert_relative_eq!(
                fast.theta_w,
                general.theta_w,
                epsilon = tol,
                max_relative = tol
            );
            assert_relative_eq!(
                fast.potential,
                general.potential,
                epsilon = tol,
                max_relative = tol
            );
            assert_relative_eq!(
                fast.kinetic,
                general.kinetic,
                epsilon = tol,
                max_relative = tol
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 600);
    // Other shoulders keep the general terms.
    let other = Wing::new(
        shoulder(90.0, 30.0),
        full_inertia(),
        springs([0.0; 6]),
        drag(31.3),
    )
    .unwrap();
    assert!(!other.has_closed_form_free_deviation());
}
