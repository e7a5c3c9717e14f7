//! The lean paths of stroke-only devices (drivetrain coordinates) against the general ones:
//! the linear map's scalar right-hand side against the null-space formulation at the same
//! `(p, ṗ)`, and the streamed stroke samples (closed-form body torques) against full samples
//! (mass matrices, wing rotations) for every metric.

use super::*;

/// A stroke-only device whose wings have products of inertia with the stroke axis (the yaw
/// and pitch reaction torques are not zero, so the closed form's rotation is exercised).
fn full_inertia_parity(drivetrain: Drivetrain, k2: f64, formulation: Formulation) -> Device {
    full_inertia_parity_with(drivetrain, k2, formulation, drag)
}

/// [`full_inertia_parity`] with the aerodynamics `aero(Ω1)`.
fn full_inertia_parity_with(
    drivetrain: Drivetrain,
    k2: f64,
    formulation: Formulation,
    aero: fn(f64) -> WingAero,
) -> Device {
    let wing = |omega: f64| {
        Wing::new(
            shoulder(90.0, 0.0),
            full_inertia(),
            [JointSpring::default(); 6],
            aero(omega),
        )
        .unwrap()
    };
    let actuator = Actuator::thesis(Waveform::sine(50.0, 110.0, 0.0, 0.0).unwrap());
    two_wing_device(
        [wing(0.6 * 31.3), wing(31.3)],
        "drag_parity_fixed",
        drivetrain,
        k2,
        actuator,
        formulation,
    )
}

fn linear_map() -> Drivetrain {
    Drivetrain::LinearDifferential(
        paritysim_kinematics::drivetrain::LinearDifferential::new(2.5, 2.5, 1.0).unwrap(),
    )
}

#[test]
fn linear_map_right_hand_side_equals_the_null_space_formulation() {
    // Two formulations of one model at the same (t, p, ṗ): the lean scalar right-hand side in
    // drivetrain coordinates (q̈, then φ̈ = J q̈) and the null-space solve of the full 6 × 6
    // mass matrix (eq. 3.20) with the drivetrain torques J⁻ᵀ Q.
    for device in [
        linear_parity(0.6 * 31.3, Formulation::Auto),
        full_inertia_parity(linear_map(), 10.0, Formulation::Auto),
    ] {
        assert_eq!(device.formulation(), Formulation::DrivetrainCoordinates);
        let general = Device::new(DeviceSpec {
            formulation: Formulation::NullSpace,
            ..device.spec().clone()
        })
        .unwrap();
        let jacobian = match device.spec().transmission.as_ref().unwrap().kinematics() {
            Drivetrain::LinearDifferential(map) => map.evaluate(0.0, 0.0).jacobian,
            _ => unreachable!(),
        };
        let mut worst: f64 = 0.0;
        for k in 0..200 {
            let x = k as f64;
            let mut y = paritysim_dynamics::integrate::State::default();
            // q1 (mm), q2 (rad) and their rates over a stroke's range, both signs.
            y.coords[0] = 0.05 * (0.37 * x).sin();
            y.coords[1] = 0.02 * (1.3 * x).cos();
            y.rates[0] = 0.2 * (0.71 * x).cos();
            y.rates[1] = 0.05 * (2.1 * x).sin();
            let t = 0.05 * x;
            let mut dydt = paritysim_dynamics::integrate::State::default();
            device.rhs(t, &y, &mut dydt).unwrap();
            let q_ddot = nalgebra::Vector2::new(dydt.rates[0], dydt.rates[1]);
            let phi_ddot = jacobian * q_ddot;
            let (p, p_dot) = device.coordinates(&y).unwrap();
            let e = general.evaluate(t, &p, &p_dot).unwrap();
            for (lean, full) in [(phi_ddot.x, e.p_ddot[0]), (phi_ddot.y, e.p_ddot[3])] {
                worst = worst.max((lean - full).abs() / full.abs().max(1e-3));
            }
            // The actuator and aerodynamic powers of the work integrals.
            let power = e.drive.actuator_force * e.drive.q_dot.x;
            worst = worst.max((dydt.work_actuator - power).abs() / power.abs().max(1e-3));
        }
        assert!(
            worst <= 1e-12,
            "lean vs null-space accelerations: {worst:e}"
        );
    }
}

fn all_metrics(device: &Device, columns: Option<Vec<String>>) -> Vec<(String, f64)> {
    let options = SimulationOptions {
        max_cycles: 6,
        samples_per_cycle: 256,
        columns,
        ..Default::default()
    };
    simulate(device, &options).unwrap().metrics
}

#[test]
fn streamed_stroke_samples_give_every_metric_of_full_samples() {
    // Full samples (any column asked) evaluate the model and rotate the wing torques; the
    // streamed samples (no column) use the closed-form stroke-only torques. Same steps, so
    // the same numbers to round-off: every metric, including the yaw/pitch/inertial ones, the
    // work integrals and Table 3.2.
    let cases = [
        linear_parity(0.6 * 31.3, Formulation::Auto),
        // K2 = 500: the linkage's whippletree mode is stable there (docs/findings.md#3).
        parity_device(0.6 * 31.3, 500.0, "drag_parity_fixed", Formulation::Auto),
        full_inertia_parity(linear_map(), 10.0, Formulation::Auto),
        full_inertia_parity(
            Drivetrain::LinkageDifferential(LinkageDifferential::thesis()),
            500.0,
            Formulation::Auto,
        ),
        // Blade-element aerodynamics on the fixed wings: the frame-6 torque is rotated too.
        full_inertia_parity_with(linear_map(), 10.0, Formulation::Auto, |omega| {
            WingAero::BladeElement(
                paritysim_aero::BladeElementModel::new(
                    paritysim_aero::Omegas::new(omega, 0.59, 17.5, 0.71).unwrap(),
                    paritysim_aero::CoefficientSet::default(),
                )
                .unwrap(),
            )
        }),
        // Polynomial transmissions and a drive per wing (issue 35; diagonal inertias).
        super::polynomial::polynomial_differential(),
        super::polynomial::polynomial_dual(),
    ];
    for (case, device) in cases.iter().enumerate() {
        assert_eq!(device.formulation(), Formulation::DrivetrainCoordinates);
        let full = all_metrics(device, Some(vec!["left_phi".into()]));
        let lean = all_metrics(device, Some(vec![]));
        assert_eq!(full.len(), lean.len());
        let mut nonzero_yaw = false;
        for ((name, b), (lean_name, a)) in full.iter().zip(&lean) {
            assert_eq!(name, lean_name);
            if b.is_nan() {
                assert!(
                    a.is_nan(),
                    "case {case} {name}: streamed {a} where full is NaN"
                );
                continue;
            }
            assert!(
                (a - b).abs() <= 1e-12 * (1.0 + b.abs()),
                "case {case} {name}: streamed {a} vs full {b}"
            );
            nonzero_yaw |= name == "right_yaw_rms" && b.abs() > 1e-3;
        }
        // The full-inertia wings have a yaw reaction: the rotation was exercised.
        assert_eq!(nonzero_yaw, (2..=4).contains(&case), "case {case}");
    }
}

#[test]
fn streamed_samples_compute_only_what_the_asked_metrics_need() {
    let device = full_inertia_parity(linear_map(), 10.0, Formulation::Auto);
    let full = all_metrics(&device, Some(vec![]));
    let get = |m: &[(String, f64)], name: &str| m.iter().find(|(n, _)| n == name).unwrap().1;
    let asked = |names: &[&str]| {
        let options = SimulationOptions {
            max_cycles: 6,
            samples_per_cycle: 256,
            columns: Some(vec![]),
            metrics: Some(names.iter().map(|s| s.to_string()).collect()),
            ..Default::default()
        };
        simulate(&device, &options).unwrap().metrics
    };
    // Torque metrics alone: no work integral (NaN), the torques as with everything asked.
    let torques = asked(&["right_yaw_rms", "pitch_total_mean"]);
    for name in ["right_yaw_rms", "pitch_total_mean", "tau_r_peak"] {
        assert_eq!(get(&torques, name), get(&full, name), "{name}");
    }
    assert!(get(&torques, "work_actuator_per_cycle").is_nan());
    // Work alone: no torques.
    let work = asked(&["mean_actuator_power"]);
    assert_eq!(
        get(&work, "mean_actuator_power"),
        get(&full, "mean_actuator_power")
    );
    assert!(get(&work, "right_yaw_rms").is_nan());
    assert!(get(&work, "actuator_force_peak").is_nan());
    // Stroke metrics alone: neither.
    let stroke = asked(&["left_stroke_amplitude"]);
    assert_eq!(
        get(&stroke, "left_stroke_amplitude"),
        get(&full, "left_stroke_amplitude")
    );
    assert!(
        get(&stroke, "roll_total_peak").is_nan() && get(&stroke, "work_aero_per_cycle").is_nan()
    );
}
