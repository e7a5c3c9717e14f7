//! The one drive load (`device/drive.rs`): a preload on the whippletree enters every form.

use paritysim_dynamics::State;
use paritysim_kinematics::drivetrain::LinearDifferential;

use super::*;

/// The §3.3 Drag PARITY of the lanes' tests (eq. 2.15, T = L = 2.5; drag; 50 V at 110 Hz) with
/// balance spring `k2` and a preload torque `preload` on `q2`.
fn preloaded(k2: f64, preload: f64, formulation: Formulation) -> Device {
    let wing = |omega: f64| fixed_wing(drag(omega));
    let drivetrain =
        Drivetrain::LinearDifferential(LinearDifferential::new(2.5, 2.5, 1.0).unwrap());
    Device::new(DeviceSpec {
        wings: vec![wing(18.75), wing(31.3)],
        constraints: Constraints::configuration("drag_parity_fixed").unwrap(),
        transmission: Some(
            Transmission::new(drivetrain, k2)
                .unwrap()
                .with_preload(preload)
                .unwrap(),
        ),
        actuator: Some(Actuator::thesis(
            Waveform::sine(50.0, 110.0, 0.0, 0.0).unwrap(),
        )),
        formulation,
    })
    .unwrap()
}

/// At rest at t = 0 (no drive force, springs relaxed) the only load is the preload, so the
/// accelerations are `M_q⁻¹ (0, P)` with `M_q = Σ_k I_k J_kᵀ J_k` of the linear map, in the
/// drivetrain coordinates and (mapped by `J`) in the null-space form.
#[test]
fn a_preload_accelerates_a_device_at_rest_by_the_inverse_mass_matrix() {
    let preload = 3.0;
    let (t, l) = (2.5, 2.5);
    // eq. 2.15: φL = −T q1 + T L q2, φR = −T q1 − T L q2 (rows J_k), Ixx = 29 for both wings.
    let rows = [[-t, t * l], [-t, -t * l]];
    let inertia = 29.0;
    let (mut m00, mut m01, mut m11) = (0.0, 0.0, 0.0);
    for [a, b] in rows {
        m00 += inertia * a * a;
        m01 += inertia * a * b;
        m11 += inertia * b * b;
    }
    let det = m00 * m11 - m01 * m01;
    let q_ddot = [-m01 * preload / det, m00 * preload / det];
    for formulation in [Formulation::DrivetrainCoordinates, Formulation::NullSpace] {
        let device = preloaded(10.0, preload, formulation);
        let y = device.state_from(&Vec6::zeros(), &Vec6::zeros()).unwrap();
        let mut dydt = State::default();
        device.rhs(0.0, &y, &mut dydt).unwrap();
        let (_, p_ddot) = device
            .coordinates(&State {
                coords: y.coords,
                rates: dydt.rates,
                ..State::default()
            })
            .unwrap();
        let phi_ddot = [p_ddot[0], p_ddot[3]];
        for (k, [a, b]) in rows.iter().enumerate() {
            let want = a * q_ddot[0] + b * q_ddot[1];
            assert!(
                (phi_ddot[k] - want).abs() <= 1e-12 * want.abs(),
                "{formulation:?} wing {k}: {} vs {want}",
                phi_ddot[k]
            );
        }
    }
}

/// With a preload the actuator's work still equals the aerodynamic dissipation plus the change
/// of stored energy (the preload's potential `−P q2` included) over three driven cycles.
#[test]
fn a_preloaded_device_balances_its_energy() {
    let device = preloaded(5.0, 2.0, Formulation::NullSpace);
    let options = SimulationOptions {
        rtol: 1e-12,
        atol: 1e-13,
        max_cycles: 3,
        min_cycles: 3,
        steady_state: paritysim_dynamics::SteadyState::Transient,
        ..Default::default()
    };
    let r = simulate(&device, &options).unwrap();
    let trajectory = &r.trajectory;
    let energy = trajectory.column("mechanical_energy").unwrap();
    let w_act = *trajectory.column("work_actuator").unwrap().last().unwrap();
    let w_aero = *trajectory.column("work_aero").unwrap().last().unwrap();
    let delta_e = energy.last().unwrap() - energy[0];
    let balance = (w_act + w_aero - delta_e).abs() / w_act.abs();
    assert!(balance < 1e-8, "energy balance off by {balance:e}");
    // The preload moved the whippletree: its mean is off zero, towards the preload.
    let q2 = trajectory.column("q2").unwrap();
    let mean = q2.iter().sum::<f64>() / q2.len() as f64;
    assert!(mean > 0.0, "mean q2 {mean}");
}

/// A preload on a drivetrain without a whippletree (1 DOF) is refused, naming the field.
#[test]
fn a_preload_needs_a_whippletree() {
    let err = Transmission::new(hmf_drivetrain(), 0.0)
        .unwrap()
        .with_preload(1.0)
        .unwrap_err();
    assert!(err.to_string().contains("balance_preload"), "{err}");
}
