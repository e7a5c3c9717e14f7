//! Body-referenced mechanisms and slow control: energy balance and authority.

mod common;

use common::*;
use nalgebra::{UnitQuaternion, Vector3};
use paritysim_dynamics::{SimulationOptions, State};
use paritysim_flight::control::{Control, ControlInput, SetPoint};
use paritysim_flight::model::{Inputs, STATE_LEN, WORK_ACTUATOR};
use paritysim_flight::{
    BodyMode, DriveCoordinate, FlightModel, Mechanism, Release, Schedule, fly, fly_controlled,
    integrate_flight,
};

#[test]
fn mechanism_work_balances_the_energy_change() {
    // Vacuum, no actuator: the only non-conservative forces are the mechanisms and the
    // set point, and their power is integrated into work_actuator: E(t) − E(0) = W(t).
    let device = vacuum_device();
    let mechanisms = vec![
        Mechanism::rate(DriveCoordinate::Q2, 40.0, v(1.0, 0.2, 0.0)).unwrap(),
        Mechanism::pendulum(
            DriveCoordinate::Q2,
            30.0,
            v(-1.0, 0.0, 0.0),
            v(0.0, 1.0, 0.0),
        )
        .unwrap(),
        Mechanism::rate(DriveCoordinate::Q1, -5.0, v(1.0, 0.0, 0.0)).unwrap(),
    ];
    let model = FlightModel::new(&device, hmf_body(BodyMode::RollPitchYaw), mechanisms).unwrap();
    let mut wings = State::default();
    for i in 0..model.n_dof() {
        wings.coords[i] = 0.1 * (i as f64 + 1.0);
        wings.rates[i] = 0.03;
    }
    let y0 = model.state(
        &UnitQuaternion::from_euler_angles(0.4, 0.1, -0.2),
        &Vector3::zeros(),
        &Vector3::zeros(),
        &v(0.02, -0.01, 0.015),
        &wings,
    );
    let inputs = Inputs {
        q2_bias: 0.3,
        ..Inputs::default()
    };
    let t_end = 200.0;
    let times: Vec<f64> = (0..=200).map(|k| t_end * k as f64 / 200.0).collect();
    let mut rows = Vec::new();
    integrate_flight(
        &model,
        &tight(),
        &inputs,
        0.0,
        &y0,
        t_end,
        &times,
        &mut |_, t, y: &[f64; STATE_LEN]| {
            let e = model.evaluate(t, y, &inputs)?;
            rows.push((
                e.kinetic + e.potential + e.gravity_potential,
                y[WORK_ACTUATOR],
                e.kinetic,
            ));
            Ok(())
        },
    )
    .unwrap();
    let e0 = rows[0].0;
    let work = rows.iter().fold(0.0f64, |m, r| m.max(r.1.abs()));
    let scale = rows.iter().fold(0.0f64, |m, r| m.max(r.2));
    assert!(
        work > 1e-3 * scale,
        "the mechanisms do work: {work} vs kinetic {scale}"
    );
    let worst = rows
        .iter()
        .fold(0.0f64, |m, r| m.max((r.0 - e0 - r.1).abs()));
    eprintln!(
        "energy balance residual {:.2e} of kinetic {scale:.3e}, work {work:.3e}",
        worst / scale
    );
    assert!(worst < 1e-9 * scale, "E − E0 − W = {worst}");
}

#[test]
fn pendulum_torque_is_the_gravity_moment_of_the_tilt() {
    // τ = m l (d × R_bᵀ g) · a for a tilt β about a: m l g sin β (sign by the right-hand rule).
    let p = Mechanism::pendulum(
        DriveCoordinate::Q1,
        7.0,
        v(-1.0, 0.0, 0.0),
        v(0.0, 1.0, 0.0),
    )
    .unwrap();
    let g = v(-9.81e-3, 0.0, 0.0);
    for beta in [-0.7f64, 0.0, 0.3, 1.2] {
        let r = *nalgebra::Rotation3::from_axis_angle(&Vector3::y_axis(), beta).matrix();
        let tau = p.force(&r, &Vector3::zeros(), &g, 0.0);
        let expected = -7.0 * 9.81e-3 * beta.sin();
        assert!(
            (tau - expected).abs() < 1e-15,
            "β = {beta}: {tau} vs {expected}"
        );
    }
}

#[test]
fn roll_controller_on_the_whippletree_has_authority_over_roll() {
    // A 1-Cut stroke-only PARITY device on a roll gimbal rolls; a PD on roll driving the
    // whippletree bias changes the final roll with the sign of its gain: one sign regulates.
    let device = drag_only_1cut();
    // The transient release (300 cycles, 1e-5 off the orbit: whippletree multiplier 0.9985):
    // the open-loop roll this test regulates is that slow mode settling. Released on the
    // orbit the default shooting finds, PARITY balances the cut wing and the body rolls only
    // 2.9e-5 rad in 40 cycles.
    let opts = SimulationOptions {
        record_cycles: 40,
        samples_per_cycle: 20,
        steady_state: paritysim_dynamics::SteadyState::Transient,
        ..SimulationOptions::default()
    };
    let model = FlightModel::new(&device, hmf_body(BodyMode::Roll), Vec::new()).unwrap();
    let final_roll = |kp: f64| {
        let schedule = Schedule {
            set_points: Vec::new(),
            control: (kp != 0.0).then_some(Control {
                input: ControlInput::Q2Bias,
                axis: 0,
                target: 0.0,
                kp,
                kd: 0.0,
                target_rate: 0.0,
                rate_hz: 1000.0,
                limit: 5.0,
                shape: None,
            }),
        };
        let r = fly(&model, &opts, &Release::default(), &schedule).unwrap();
        r.metrics
            .iter()
            .find(|(n, _)| n == "body_roll_final")
            .unwrap()
            .1
    };
    let (open, plus, minus) = (final_roll(0.0), final_roll(50.0), final_roll(-50.0));
    eprintln!("final roll: open {open:.4e}, kp +50 {plus:.4e}, kp -50 {minus:.4e}");
    assert!(open.abs() > 1e-3, "open loop rolls: {open}");
    let (better, worse) = if plus.abs() < minus.abs() {
        (plus, minus)
    } else {
        (minus, plus)
    };
    assert!(
        better.abs() < 0.5 * open.abs(),
        "regulating sign: {better} vs open {open}"
    );
    assert!(
        worse.abs() > open.abs(),
        "destabilising sign: {worse} vs open {open}"
    );
}

#[test]
fn set_point_schedule_interpolates_and_holds() {
    let s = SetPoint::new(ControlInput::Q2Bias, vec![1.0, 3.0], vec![0.0, 2.0]).unwrap();
    assert_eq!(s.value(0.0), 0.0);
    assert_eq!(s.value(2.0), 1.0);
    assert_eq!(s.value(9.0), 2.0);
    assert!(SetPoint::new(ControlInput::Q2Bias, vec![1.0, 1.0], vec![0.0, 2.0]).is_err());
}

#[test]
fn an_external_controller_flies_like_the_pd_with_the_same_law() {
    // `fly_controlled` with a closure computing the PD law at the PD's rate must reproduce
    // `[body.control]` (same ticks, same held inputs); together they add, each on its own grid.
    let device = drag_only_1cut();
    // The transient release (300 cycles, 1e-5 off the orbit: whippletree multiplier 0.9985):
    // the open-loop roll this test regulates is that slow mode settling. Released on the
    // orbit the default shooting finds, PARITY balances the cut wing and the body rolls only
    // 2.9e-5 rad in 40 cycles.
    let opts = SimulationOptions {
        record_cycles: 6,
        samples_per_cycle: 20,
        steady_state: paritysim_dynamics::SteadyState::Transient,
        ..SimulationOptions::default()
    };
    let model = FlightModel::new(&device, hmf_body(BodyMode::Roll), Vec::new()).unwrap();
    let pd = Control {
        input: ControlInput::Q2Bias,
        axis: 0,
        target: 0.0,
        kp: 50.0,
        kd: 100.0,
        target_rate: 0.0,
        rate_hz: 1000.0,
        limit: 5.0,
        shape: None,
    };
    let with_pd = Schedule {
        set_points: Vec::new(),
        control: Some(pd.clone()),
    };
    let release = Release::default();
    let rust = fly(&model, &opts, &release, &with_pd).unwrap();
    let mut ticks = Vec::new();
    let mut law = |t: f64, s: &paritysim_flight::FlightSample| {
        ticks.push(t);
        Ok(Inputs {
            q2_bias: pd.output(s.angles.x, s.flight.omega.x),
            ..Inputs::default()
        })
    };
    let external = fly_controlled(
        &model,
        &opts,
        &release,
        &Schedule::default(),
        Some((pd.period_ms(), &mut law)),
    )
    .unwrap();
    let column = |r: &paritysim_dynamics::simulate::SimulationResult, name: &str| {
        r.trajectory
            .columns
            .iter()
            .find(|(n, _)| n == name)
            .unwrap()
            .1
            .clone()
    };
    let (a, b) = (column(&rust, "body_roll"), column(&external, "body_roll"));
    let open = column(
        &fly(&model, &opts, &release, &Schedule::default()).unwrap(),
        "body_roll",
    );
    let moved = a
        .iter()
        .zip(&open)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(moved > 1e-4, "the PD acts: {moved}");
    let diff = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(diff < 1e-13, "external vs PD: {diff}");
    let period = device.period().unwrap();
    assert_eq!(ticks.len(), (6.0 * period / pd.period_ms()).ceil() as usize);
    // Both at once: twice the law, on the same grid.
    let mut half = |_: f64, s: &paritysim_flight::FlightSample| {
        Ok(Inputs {
            q2_bias: pd.output(s.angles.x, s.flight.omega.x),
            ..Inputs::default()
        })
    };
    let doubled = Control {
        kp: 100.0,
        kd: 200.0,
        target_rate: 0.0,
        limit: 10.0,
        ..pd.clone()
    };
    let both = fly_controlled(
        &model,
        &opts,
        &release,
        &with_pd,
        Some((pd.period_ms(), &mut half)),
    );
    let twice = fly(
        &model,
        &opts,
        &release,
        &Schedule {
            set_points: Vec::new(),
            control: Some(doubled),
        },
    );
    let (c, d) = (
        column(&both.unwrap(), "body_roll"),
        column(&twice.unwrap(), "body_roll"),
    );
    let diff = c
        .iter()
        .zip(&d)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(diff < 1e-9, "PD + external vs doubled PD: {diff}");
}
