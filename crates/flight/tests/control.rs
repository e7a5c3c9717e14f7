//! Slow control in flight (issue 17): eq. 5.1 as a torque-ratio input (constant and
//! stroke-synchronous), set points timed from the release, and the per-side (dual) drive.

mod common;

use common::*;
use nalgebra::Vector3;
use paritysim_constraints::Constraints;
use paritysim_dynamics::device::{DeviceSpec, Formulation, Transmission};
use paritysim_dynamics::{
    Actuator, DcOffset, Device, SimulationOptions, SimulationResult, Waveform,
};
use paritysim_flight::control::{Control, ControlInput, Interpolation, SetPoint};
use paritysim_flight::model::Inputs;
use paritysim_flight::{BodyMode, FlightModel, Release, Schedule, fly};
use paritysim_kinematics::drivetrain::{DualFourBar, LinearDifferential};
use paritysim_kinematics::{Drivetrain, RodCrank};

fn column<'a>(r: &'a SimulationResult, name: &str) -> &'a [f64] {
    r.trajectory
        .column(name)
        .unwrap_or_else(|| panic!("no column {name}"))
}

fn metric(r: &SimulationResult, name: &str) -> f64 {
    r.metrics.iter().find(|(n, _)| n == name).unwrap().1
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

fn with_set_points(set_points: Vec<SetPoint>) -> Schedule {
    Schedule {
        set_points,
        control: None,
    }
}

fn constant(input: ControlInput, value: f64) -> SetPoint {
    SetPoint::new(input, vec![0.0], vec![value]).unwrap()
}

/// The symmetric §3.4 device with an actuator of stiffness `k1` and whippletree arm ratio
/// `hL/hR = arm_ratio`.
fn symmetric(arm_ratio: f64, k1: f64) -> Device {
    symmetric_k2(arm_ratio, k1, 0.0)
}

fn symmetric_k2(arm_ratio: f64, k1: f64, k2: f64) -> Device {
    let hinge = 2.533928021702924;
    let wing = wing_3_4(false, 1.0, hinge);
    Device::new(DeviceSpec {
        wings: vec![wing.clone(), wing],
        constraints: Constraints::configuration("drag_parity").unwrap(),
        transmission: Some(
            Transmission::new(
                Drivetrain::LinearDifferential(
                    LinearDifferential::new(3.0543261909900763, 2.5, arm_ratio).unwrap(),
                ),
                k2,
            )
            .unwrap(),
        ),
        actuator: Some(
            Actuator::new(
                1.2,
                k1,
                Waveform::sine(50.0, 110.0, 0.0, 0.0).unwrap(),
                DcOffset::Ignore,
            )
            .unwrap(),
        ),
        formulation: Formulation::Auto,
    })
    .unwrap()
}

#[test]
fn log_q3_is_the_load_of_the_moved_pivot() {
    // Eq. 5.1 by a load on the centred whippletree against the physical moving pivot
    // (hL/hR = 1/q3, §2.4.2): without the actuator spring both give the same stroke torques
    // at every state, and τL/τR = q3.
    let q3: f64 = 2.0;
    let moved = symmetric(1.0 / q3, 0.0);
    let centred = FlightModel::new(
        &symmetric(1.0, 0.0),
        hmf_body(BodyMode::Clamped),
        Vec::new(),
    )
    .unwrap();
    let inputs = Inputs {
        log_q3: q3.ln(),
        ..Inputs::default()
    };
    let mut worst: f64 = 0.0;
    for (k, &(pl, pr, vl, vr)) in [
        (0.3, 0.2, 1.0, -0.4),
        (-0.5, 0.1, 0.2, 0.3),
        (0.05, -0.6, -2.0, 1.5),
    ]
    .iter()
    .enumerate()
    {
        let t = 0.7 * k as f64 + 0.3;
        let p = paritysim_constraints::Vec6::new(pl, 0.0, 0.1, pr, 0.0, -0.2);
        let p_dot = paritysim_constraints::Vec6::new(vl, 0.0, 0.3, vr, 0.0, 0.1);
        let reference = moved.drive(t, &p, &p_dot).unwrap().stroke_torque;
        let wings = centred.device().state_from(&p, &p_dot).unwrap();
        let y = centred.state(
            &nalgebra::UnitQuaternion::identity(),
            &Vector3::zeros(),
            &Vector3::zeros(),
            &Vector3::zeros(),
            &wings,
        );
        let ours = centred
            .evaluate(t, &y, &inputs)
            .unwrap()
            .drive
            .stroke_torque;
        eprintln!("moved pivot {reference:?}, eq. 5.1 load {ours:?}");
        assert!(reference.amax() > 1e-2, "a loaded drive: {reference:?}");
        worst = worst.max((ours - reference).amax() / reference.amax());
        assert!(
            (ours.x / ours.y - q3).abs() < 1e-12,
            "ratio {}",
            ours.x / ours.y
        );
    }
    assert!(worst < 1e-12, "moved pivot vs eq. 5.1 load: {worst}");
}

fn options(record_cycles: usize) -> SimulationOptions {
    SimulationOptions {
        record_cycles,
        samples_per_cycle: 40,
        min_cycles: 10,
        ..SimulationOptions::default()
    }
}

/// `(t_up, t_down)`: phases (ms into the drive period) where the right stroke rate turns
/// positive and negative, on the clamped periodic orbit (linear interpolation of samples).
fn reversals(model: &FlightModel, opts: &SimulationOptions) -> (f64, f64) {
    let r = fly(
        &model.with_mode(BodyMode::Clamped),
        opts,
        &Release::default(),
        &Schedule::default(),
    )
    .unwrap();
    let (t, w) = (&r.trajectory.time, column(&r, "right_phi_dot"));
    let period = r.period_ms;
    let (mut up, mut down) = (f64::NAN, f64::NAN);
    for i in 1..w.len() {
        if (w[i - 1] < 0.0) != (w[i] < 0.0) {
            let s = w[i - 1] / (w[i - 1] - w[i]);
            let tc = (t[i - 1] + s * (t[i] - t[i - 1]) - t[0]).rem_euclid(period);
            if w[i] > 0.0 { up = tc } else { down = tc }
        }
    }
    (up, down)
}

/// `ln q3 = +u` while the right stroke rate is positive, `−u` otherwise (periodic steps).
fn stroke_synchronous(u: f64, (up, down): (f64, f64), period: f64) -> SetPoint {
    let (times, values) = if up < down {
        (vec![up, down], vec![u, -u])
    } else {
        (vec![down, up], vec![-u, u])
    };
    SetPoint::new(ControlInput::LogQ3, times, values)
        .unwrap()
        .with_interpolation(Interpolation::Previous)
        .with_period(period)
        .unwrap()
}

#[test]
fn constant_q3_averages_out_a_stroke_synchronous_q3_does_not() {
    // §2.4.2: τL = q3 τR with a reciprocating τR gives a zero-mean roll torque; q3 on one
    // half-stroke and 1/q3 on the other gives (q3 − 1/q3)·|τR| on average, mirrored by u → −u.
    let device = symmetric(1.0, 467.0);
    let model = FlightModel::new(&device, hmf_body(BodyMode::Clamped), Vec::new()).unwrap();
    let opts = options(4);
    let period = device.period().unwrap();
    let phases = reversals(&model, &opts);
    let u = 2f64.ln();
    let run = |s: Vec<SetPoint>| fly(&model, &opts, &Release::default(), &with_set_points(s));
    let (fixed, synced, mirrored) = (
        run(vec![constant(ControlInput::LogQ3, u)]).unwrap(),
        run(vec![stroke_synchronous(u, phases, period)]).unwrap(),
        run(vec![stroke_synchronous(-u, phases, period)]).unwrap(),
    );
    let peak = max_abs(column(&fixed, "body_torque_roll"));
    let (m_fixed, m_synced, m_mirror) = (
        metric(&fixed, "body_torque_roll_mean"),
        metric(&synced, "body_torque_roll_mean"),
        metric(&mirrored, "body_torque_roll_mean"),
    );
    eprintln!(
        "reversals {phases:?} of {period:.3} ms; roll torque peak {peak:.3}, means: constant \
         {m_fixed:+.3e}, synchronous {m_synced:+.4}, mirrored {m_mirror:+.4}"
    );
    assert!(peak > 1.0, "q3 = 2 makes a roll oscillation: {peak}");
    assert!(m_fixed.abs() < 1e-3 * peak, "constant q3: mean {m_fixed}");
    assert!(
        m_synced.abs() > 0.05 * peak,
        "synchronous q3: mean {m_synced}"
    );
    assert!(
        (m_synced + m_mirror).abs() < 1e-6 * m_synced.abs(),
        "u -> -u mirrors the mean: {m_synced} vs {m_mirror}"
    );
}

/// Mean roll rate (rad/ms) over each quarter of a run's whole wingbeats, and max |q2|.
fn quarters(r: &SimulationResult) -> ([f64; 4], f64) {
    let w = column(r, "body_omega_roll");
    let n = w.len() - 1;
    let q = |a: usize| mean(&w[a * n / 4..(a + 1) * n / 4]);
    ([q(0), q(1), q(2), q(3)], max_abs(column(r, "q2")))
}

#[test]
fn a_rate_controller_on_the_synchronous_q3_holds_a_roll_rate_by_sliding_under_the_wings() {
    // Eq. 5.1 as a rate command on the free whippletree (K2 = 0, the §3.4 device): a PD at
    // 1 kHz on the roll rate sets the amplitude u of the stroke-synchronous ln q3 = ±u. It
    // holds 2 rad/s and 5 rad/s (and −2 rad/s mirrored), and the body turns under wings that
    // stay put: roll ≈ T h Δq2 (the strokes' differential shift on the linear map).
    let device = symmetric(1.0, 467.0);
    let model = FlightModel::new(&device, hmf_body(BodyMode::Roll), Vec::new()).unwrap();
    let phases = reversals(&model, &options(2));
    let shape = stroke_synchronous(1.0, phases, device.period().unwrap());
    let hold = |target: f64| {
        let schedule = Schedule {
            set_points: Vec::new(),
            control: Some(Control {
                input: ControlInput::LogQ3,
                axis: 0,
                target: 0.0,
                kp: 0.0,
                kd: 10.0,
                target_rate: target,
                rate_hz: 1000.0,
                limit: 0.5,
                shape: Some(shape.clone()),
            }),
        };
        fly(&model, &options(40), &Release::default(), &schedule).unwrap()
    };
    let th = 3.0543261909900763 * 2.5;
    for target in [2e-3, 5e-3] {
        let r = hold(target);
        let (w, _) = quarters(&r);
        let (roll, q2) = (column(&r, "body_roll"), column(&r, "q2"));
        let (turn, slide) = (
            roll[roll.len() - 1] - roll[0],
            th * (q2[q2.len() - 1] - q2[0]),
        );
        eprintln!(
            "target {target:+.1e} rad/ms: quarters {w:.5?}; turn {turn:+.3} rad, T h Δq2 {slide:+.3} rad"
        );
        for q in &w[1..] {
            assert!((q - target).abs() < 0.2 * target, "holds {target}: {w:?}");
        }
        if target == 2e-3 {
            assert!(
                (turn - slide).abs() < 0.25 * turn.abs(),
                "the body slides under the wings: {turn} vs {slide}"
            );
        }
    }
    let (plus, minus) = (quarters(&hold(2e-3)).0, quarters(&hold(-2e-3)).0);
    assert!(
        (plus[3] + minus[3]).abs() < 1e-6 * plus[3].abs(),
        "mirrored"
    );
}

#[test]
fn with_a_balance_spring_the_synchronous_turn_settles() {
    // With a balance spring (K2 = 100 mN·mm/rad) the whippletree cannot slide: the
    // stroke-synchronous q3 = 1.2 turns the body, then the rate decays and q2 keeps a static
    // deflection (the mean internal torque goes into the spring).
    let device = symmetric_k2(1.0, 467.0, 100.0);
    let model = FlightModel::new(&device, hmf_body(BodyMode::Roll), Vec::new()).unwrap();
    let phases = reversals(&model, &options(2));
    let s = stroke_synchronous(1.2f64.ln(), phases, device.period().unwrap());
    let r = fly(
        &model,
        &options(40),
        &Release::default(),
        &with_set_points(vec![s]),
    )
    .unwrap();
    let (w, _) = quarters(&r);
    let q2 = column(&r, "q2");
    let late_q2 = mean(&q2[3 * q2.len() / 4..]);
    eprintln!("quarters {w:.5?}, late q2 {late_q2:+.4}");
    assert!(w[3].abs() < 0.1 * w[0].abs(), "decays: {w:?}");
    assert!(late_q2.abs() > 0.01, "static deflection: {late_q2}");
}

#[test]
fn periodic_steps_and_their_nodes() {
    let s = SetPoint::new(ControlInput::LogQ3, vec![1.0, 3.0], vec![0.5, -0.5])
        .unwrap()
        .with_interpolation(Interpolation::Previous)
        .with_period(4.0)
        .unwrap();
    // Before the first node of a period: the last node's value of the previous period.
    for (t, v) in [
        (0.5, -0.5),
        (1.0, 0.5),
        (2.9, 0.5),
        (3.0, -0.5),
        (5.5, 0.5),
        (-1.5, 0.5),
    ] {
        assert_eq!(s.value(t), v, "t = {t}");
    }
    assert_eq!(s.next_node(0.0, 1e-12), 1.0);
    assert_eq!(s.next_node(1.0, 1e-12), 3.0);
    assert_eq!(s.next_node(3.5, 1e-12), 5.0);
    let linear = SetPoint::new(ControlInput::Q2Bias, vec![1.0, 3.0], vec![0.0, 2.0])
        .unwrap()
        .with_period(4.0)
        .unwrap();
    // Wraps from (3, 2) to (5, 0).
    assert!((linear.value(4.0) - 1.0).abs() < 1e-15);
    assert!(
        SetPoint::new(ControlInput::LogQ3, vec![1.0, 5.0], vec![0.0, 1.0])
            .unwrap()
            .with_period(4.0)
            .is_err()
    );
    assert!(
        SetPoint::new(ControlInput::LogQ3, vec![1.0], vec![0.0])
            .unwrap()
            .with_period(0.0)
            .is_err()
    );
}

#[test]
fn set_points_are_timed_from_the_release_and_vary_within_a_run() {
    // A whippletree bias stepping on 10 ms after the release: the flight equals the open
    // loop before, and departs from it after (it used to be held at its release value).
    let device = symmetric(1.0, 467.0);
    let model = FlightModel::new(&device, hmf_body(BodyMode::Roll), Vec::new()).unwrap();
    let opts = options(3);
    let open = fly(&model, &opts, &Release::default(), &Schedule::default()).unwrap();
    let step = SetPoint::new(ControlInput::Q2Bias, vec![0.0, 10.0], vec![0.0, 0.5])
        .unwrap()
        .with_interpolation(Interpolation::Previous);
    let stepped = fly(
        &model,
        &opts,
        &Release::default(),
        &with_set_points(vec![step]),
    )
    .unwrap();
    let t = &open.trajectory.time;
    let (a, b) = (column(&open, "q2"), column(&stepped, "q2"));
    let (mut before, mut after) = (0.0f64, 0.0f64);
    for i in 0..t.len() {
        let d = (a[i] - b[i]).abs();
        if t[i] - t[0] <= 10.0 {
            before = before.max(d);
        } else {
            after = after.max(d);
        }
    }
    eprintln!("q2 difference before the step {before:.2e}, after {after:.2e}");
    assert!(before < 1e-12, "before the step: {before}");
    assert!(after > 1e-3, "after the step: {after}");
}

// ---------------------------------------------------------------- dual drive

/// The Table 3.3 left wing (blade elements, rotating; aerodynamic scale per side) on each
/// drive of a dual four-bar.
fn dual_device(left_scale: f64, right_scale: f64) -> Device {
    let hinge = 2.533928021702924;
    Device::new(DeviceSpec {
        wings: vec![
            wing_3_4(false, left_scale, hinge),
            wing_3_4(false, right_scale, hinge),
        ],
        constraints: Constraints::configuration("drag_parity").unwrap(),
        transmission: Some(
            Transmission::new(
                Drivetrain::DualFourBar(DualFourBar::new(RodCrank::THESIS)),
                0.0,
            )
            .unwrap(),
        ),
        actuator: Some(
            Actuator::new(
                1.2,
                467.0,
                Waveform::sine(50.0, 110.0, 0.0, 0.0).unwrap(),
                DcOffset::Ignore,
            )
            .unwrap(),
        ),
        formulation: Formulation::Auto,
    })
    .unwrap()
}

#[test]
fn dual_drive_sides_scale_each_wing_alone() {
    // On the stand each wing answers only its own drive: doubling the right drive's force
    // doubles the right stroke amplitude's linear part and leaves the left stroke unchanged.
    let device = dual_device(1.0, 1.0);
    let opts = options(2);
    let run = |gain: [f64; 2]| {
        let a = device
            .spec()
            .actuator
            .clone()
            .unwrap()
            .with_sides(gain, [0.0; 2])
            .unwrap();
        let d = Device::new(DeviceSpec {
            actuator: Some(a),
            ..device.spec().clone()
        })
        .unwrap();
        paritysim_dynamics::simulate(&d, &opts).unwrap()
    };
    let (base, boosted) = (run([1.0, 1.0]), run([1.0, 1.3]));
    let amp = |r: &SimulationResult, c: &str| max_abs(column(r, c));
    let (l0, r0, l1, r1) = (
        amp(&base, "left_phi"),
        amp(&base, "right_phi"),
        amp(&boosted, "left_phi"),
        amp(&boosted, "right_phi"),
    );
    eprintln!("stroke amplitudes: base {l0:.4}/{r0:.4}, right × 1.3: {l1:.4}/{r1:.4}");
    assert!((l0 - r0).abs() < 1e-9 * l0, "symmetric drive: {l0} vs {r0}");
    assert!((l1 - l0).abs() < 1e-6 * l0, "left untouched: {l0} -> {l1}");
    assert!(r1 > 1.1 * r0, "right grows: {r0} -> {r1}");
    assert!(
        Actuator::thesis(Waveform::sine(1.0, 110.0, 0.0, 0.0).unwrap())
            .with_sides([1.0, -1.0], [0.0; 2])
            .is_err()
    );
}

fn yaw_hold(device: &Device, kp: f64) -> (f64, SimulationResult) {
    let model = FlightModel::new(device, hmf_body(BodyMode::Yaw), Vec::new()).unwrap();
    let schedule = Schedule {
        set_points: Vec::new(),
        control: (kp != 0.0).then_some(Control {
            input: ControlInput::SideGainDifference,
            axis: 1,
            target: 0.0,
            kp,
            kd: 0.0,
            target_rate: 0.0,
            rate_hz: 1000.0,
            limit: 0.2,
            shape: None,
        }),
    };
    // Released from the transient's steady state: mirrored devices give exactly mirrored
    // transients, where two Newton solutions are mirrors only to their residual (1e-9), which
    // the open-loop yaw amplifies to 2.6e-6 rad in 20 wingbeats.
    let opts = SimulationOptions {
        steady_state: paritysim_dynamics::SteadyState::Transient,
        ..options(20)
    };
    let r = fly(&model, &opts, &Release::default(), &schedule).unwrap();
    (metric(&r, "body_yaw_final"), r)
}

#[test]
fn per_side_drive_holds_yaw_against_a_cut_wing_and_mirrors() {
    // The dual drive with a cut right wing (aerodynamics × 0.7) yaws open loop on a yaw
    // gimbal (lift asymmetry, the thesis' yaw). The stand gives the sign of the yaw torque per
    // unit side-gain difference; a PD on yaw with that sign holds the yaw; the mirrored
    // asymmetry gives the mirrored open-loop yaw.
    let right_cut = dual_device(1.0, 0.7);
    let stand = FlightModel::new(&right_cut, hmf_body(BodyMode::Clamped), Vec::new()).unwrap();
    let torque = |u: f64| {
        let r = fly(
            &stand,
            &options(2),
            &Release::default(),
            &with_set_points(vec![constant(ControlInput::SideGainDifference, u)]),
        )
        .unwrap();
        metric(&r, "body_torque_yaw_mean")
    };
    let slope = (torque(0.05) - torque(-0.05)) / 0.1;
    let (open, open_run) = yaw_hold(&right_cut, 0.0);
    let (held, held_run) = yaw_hold(&right_cut, 0.5 * slope.signum());
    let late = |r: &SimulationResult| {
        let w = column(r, "body_yaw");
        max_abs(&w[w.len() / 2..])
    };
    eprintln!(
        "stand d(yaw torque)/d(gain difference) {slope:+.3} mN·mm; final yaw: open \
         {open:+.4e}, held {held:+.4e} (late max {:.3e} vs {:.3e})",
        late(&held_run),
        late(&open_run)
    );
    assert!(open.abs() > 1e-2, "open loop yaws: {open}");
    assert!(
        late(&held_run) < 0.2 * late(&open_run),
        "the PD with the stand's sign holds yaw"
    );
    let (mirror, mirror_run) = yaw_hold(&dual_device(0.7, 1.0), 0.0);
    let (a, b) = (
        column(&open_run, "body_yaw"),
        column(&mirror_run, "body_yaw"),
    );
    let d = a
        .iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x + y).abs()));
    assert!(d < 1e-6 * max_abs(a), "mirrored: {open} vs {mirror}, {d}");
}
