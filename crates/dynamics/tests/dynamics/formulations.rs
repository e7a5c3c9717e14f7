//! The constraint formulations against each other and against invariants: the null space
//! cannot drift, projection and drivetrain coordinates agree with it, symmetric devices stay
//! symmetric, bad input is rejected, failures carry their time and state.

use super::*;

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
