//! §2.7: eq. 2.59 against the nonlinear disturbance response; the linearisation's stiffness.

use super::*;

// ------------------------------------------------------------------ §2.7

#[test]
fn eq_2_59_closed_forms() {
    let lti = LtiModel::new(2.0, 0.3).unwrap();
    assert_eq!(lti.transfer(0.0).unwrap(), Complex::new(1.0, 0.0));
    // At ω = √κ0 the response is κ0/(iβ*ω): magnitude √κ0/β*, phase −π/2.
    let f = 0.3f64.sqrt() / (2.0 * PI * 1e-3);
    let h = lti.transfer(f).unwrap();
    assert!((h.norm() - 0.3f64.sqrt() / 2.0).abs() < 1e-14);
    assert!((h.arg() + FRAC_PI_2).abs() < 1e-12);
    // High frequency: κ0/ω² roll-off.
    let w = 2.0 * PI * 10.0;
    assert!((lti.transfer(1e4).unwrap().norm() * w * w / 0.3 - 1.0).abs() < 1e-3);
    assert!(LtiModel::new(0.0, 0.0).unwrap().transfer(0.0).is_err());
    assert_eq!(
        lti.transfer(-1.0).unwrap_err().field(),
        Some("frequency_hz")
    );
}

#[test]
fn roll_disturbance_obeys_momentum_balance() {
    // The body roll torque (wing momentum balance) equals the drivetrain's reaction
    // τ_drive,L − τ_drive,R with τ_drive = J⁻ᵀ (F − K1 q1, −K2 q2), at arbitrary states.
    let device = section_3_3_at(0.599 * 31.3, 500.0, 70.0);
    let tr = device.spec().transmission.clone().unwrap();
    let actuator = device.spec().actuator.clone().unwrap();
    let system = RollDisturbance::new(&device, 2.0, 300.0).unwrap();
    for (q, qd, t) in [
        ([0.05, 0.02], [0.3, -0.1], 0.4),
        ([-0.12, -0.05], [0.1, 0.2], 2.9),
    ] {
        let mut y = State::default();
        (y.coords[0], y.coords[1], y.rates[0], y.rates[1]) = (q[0], q[1], qd[0], qd[1]);
        let roll = system.body_roll(t, &y).unwrap();
        let j = tr.kinematics().evaluate(q[0], q[1]).unwrap().jacobian;
        let generalised = nalgebra::Vector2::new(actuator.force(t) - 467.0 * q[0], -500.0 * q[1]);
        let tau = j.transpose().lu().solve(&generalised).unwrap();
        assert!(
            (roll - (tau.x - tau.y)).abs() < 1e-9 * (1.0 + roll.abs()),
            "{roll} vs {}",
            tau.x - tau.y
        );
    }
    // Without a disturbance it is `simulate`'s roll_total.
    let quiet = RollDisturbance::new(&device, 0.0, 300.0).unwrap();
    let r = simulate(
        &device,
        &SimulationOptions {
            max_cycles: 5,
            samples_per_cycle: 16,
            ..Default::default()
        },
    )
    .unwrap();
    let tr = &r.trajectory;
    for k in 0..tr.time.len() {
        let mut y = State::default();
        for (name, s) in [("q1", 0), ("q2", 1), ("q1_dot", 6), ("q2_dot", 7)] {
            *slot(&mut y, s) = tr.column(name).unwrap()[k];
        }
        let roll = quiet.body_roll(tr.time[k], &y).unwrap();
        let want = tr.column("roll_total").unwrap()[k];
        assert!(
            (roll - want).abs() < 1e-9 * (1.0 + want.abs()),
            "{roll} vs {want}"
        );
    }
}

#[test]
fn lti_and_nonlinear_disturbance_responses_agree_at_low_amplitude() {
    // Eq. 2.15 drivetrain with eq. 2.16 drag (β0 ≈ 2, the setting of §2.6–2.7). Eq. 2.59
    // replaces the damping 2Ω|φ̇(t)|/I, which swings between 0 and π/2 times its mean, by the
    // mean; the neglected modulation at twice the flapping frequency mixes the response into
    // sidebands and back. Stated tolerance: 10 % in |H| and 0.1 rad in phase from 30 to 300 Hz.
    let device = eq_2_16_device(linear_map(), 200.0);
    let f = floquet(&device, &options()).unwrap();
    let lin = linearise(&device, &f.orbit, 2000).unwrap();
    // For the linear map the three LTI constructions coincide.
    assert!((lin.lti.beta_star / lin.lti_sinusoidal.beta_star - 1.0).abs() < 1e-5);
    assert!((lin.lti.kappa0 / lin.lti_sinusoidal.kappa0 - 1.0).abs() < 1e-12);
    assert!((lin.lti_averaged.beta_star / lin.lti.beta_star - 1.0).abs() < 1e-5);
    assert!((lin.lti_averaged.kappa0 / lin.lti.kappa0 - 1.0).abs() < 1e-6);
    assert!(lin.geometric_stiffness.abs() < 1e-3);
    for freq in [30.0, 60.0, 150.0, 300.0] {
        let small =
            disturbance_response(&device, &f.orbit, freq, 0.1, &Default::default()).unwrap();
        let larger =
            disturbance_response(&device, &f.orbit, freq, 0.4, &Default::default()).unwrap();
        assert!(small.drift < 1e-4, "{freq}: settled {}", small.drift);
        assert!(small.commensurability_error < 1e-9);
        assert!(
            (small.transfer - larger.transfer).norm() < 1e-3 * small.transfer.norm(),
            "linear response"
        );
        let h = lin.lti.transfer(freq).unwrap();
        let ratio = small.transfer / h;
        assert!(
            (ratio.norm() - 1.0).abs() < 0.1,
            "{freq} Hz: {} vs {}",
            small.transfer,
            h
        );
        assert!(
            ratio.arg().abs() < 0.1,
            "{freq} Hz: {} vs {}",
            small.transfer,
            h
        );
    }
}

#[test]
fn linkage_geometric_stiffness_is_negative() {
    // docs/findings.md item 3: the rod-crank's gain rises towards the stroke ends, so the
    // averaged whippletree stiffness loses a few hundred mN·mm/rad to geometry.
    let device = section_3_3(31.3, 500.0);
    let f = floquet(&device, &options()).unwrap();
    let lin = linearise(&device, &f.orbit, 1000).unwrap();
    assert!(
        lin.geometric_stiffness < -100.0,
        "{}",
        lin.geometric_stiffness
    );
    assert!(lin.lti_averaged.kappa0 < lin.lti.kappa0);
}
