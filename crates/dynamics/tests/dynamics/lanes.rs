//! SIMD-lane sweeps (issue 12 item 5): the lane path against the scalar path (lane width 1).

use paritysim_dynamics::lanes::{
    LANES_ENV, MAX_LANES, has_lane_model, points_completed_in_lanes, resolve_lanes,
};
use paritysim_dynamics::sweep::{PointOutput, SweepControl, run_points_with_lanes};
use paritysim_dynamics::{Error, SteadyState};
use paritysim_kinematics::drivetrain::LinearDifferential;

use super::*;

/// The issue 12 design-sweep device: eq. 2.15 (T = L = 2.5), eq. 2.16 drag, 50 V at 110 Hz.
fn linear_device(omega_left: f64, k2: f64) -> Device {
    parity_device_with(
        omega_left,
        k2,
        "drag_parity_fixed",
        Formulation::Auto,
        Drivetrain::LinearDifferential(LinearDifferential::new(2.5, 2.5, 1.0).unwrap()),
    )
}

fn shooting_options() -> SimulationOptions {
    SimulationOptions {
        steady_state: SteadyState::Shooting,
        samples_per_cycle: 400,
        ..Default::default()
    }
}

/// Two rows of a design grid (Ω^L/Ω^R × K2): 40 points, chains of 16, 16 and 8; along K2 the
/// neighbours' grids are sometimes refused and re-picked (both branches of the lane path).
fn design_points() -> Vec<paritysim_dynamics::Result<(Device, SimulationOptions)>> {
    [0.45, 0.8]
        .iter()
        .flat_map(|&r| (0..20).map(move |k| (r * 31.3, 100.0 * k as f64 / 19.0)))
        .map(|(omega, k2)| Ok((linear_device(omega, k2), shooting_options())))
        .collect()
}

/// A chain along the drive amplitude and phase (every point its own actuator, `F(0) ≠ 0`)
/// and K2: the lanes must read each point's own forcing.
fn voltage_points() -> Vec<paritysim_dynamics::Result<(Device, SimulationOptions)>> {
    // Three chains: with two lanes a chain starts in a lane its predecessor's device left.
    (0..48)
        .map(|k| {
            let volts = 60.0 + 1.25 * k as f64;
            let wing = |omega: f64| fixed_wing(drag(omega));
            let device = two_wing_device(
                [wing(0.6 * 31.3), wing(31.3)],
                "drag_parity_fixed",
                Drivetrain::LinearDifferential(LinearDifferential::new(2.5, 2.5, 1.0).unwrap()),
                2.0 * k as f64,
                Actuator::thesis(Waveform::sine(volts, 110.0, 0.0, 0.02 * k as f64).unwrap()),
                Formulation::Auto,
            );
            Ok((device, shooting_options()))
        })
        .collect()
}

fn metric_list() -> Vec<String> {
    [
        "delta_tau_peak",
        "right_roll_aero_peak",
        "left_roll_aero_peak",
        "imbalance_instantaneous_pct",
        "imbalance_peak_pct",
        "left_stroke_mean",
        "q2_amplitude",
    ]
    .map(String::from)
    .to_vec()
}

fn run(
    points: &[paritysim_dynamics::Result<(Device, SimulationOptions)>],
    threads: usize,
    lanes: usize,
) -> Vec<paritysim_dynamics::Result<PointOutput>> {
    run_with(points, &metric_list(), threads, lanes)
}

fn run_with(
    points: &[paritysim_dynamics::Result<(Device, SimulationOptions)>],
    metrics: &[String],
    threads: usize,
    lanes: usize,
) -> Vec<paritysim_dynamics::Result<PointOutput>> {
    run_points_with_lanes(
        points,
        metrics,
        false,
        Some(threads),
        Some(lanes),
        &SweepControl::new(),
    )
    .unwrap()
    .into_iter()
    .map(|slot| slot.expect("not cancelled"))
    .collect()
}

/// Everything a point reports, bit for bit.
fn fingerprint(o: &PointOutput) -> Vec<u64> {
    let mut v: Vec<u64> = o.metrics.iter().map(|x| x.to_bits()).collect();
    v.push(o.residual.to_bits());
    v.push(o.cycles_run as u64);
    v.push(o.converged as u64);
    v.extend(o.step_grid.iter().map(|x| x.to_bits()));
    if let Some((p, pd)) = o.steady_state {
        v.extend(p.iter().chain(pd.iter()).map(|x| x.to_bits()));
    }
    if let Some(j) = &o.monodromy {
        v.extend(j.iter().map(|x| x.to_bits()));
    }
    v
}

#[test]
fn the_design_device_has_a_lane_model_and_a_linkage_device_has_none() {
    assert!(has_lane_model(&linear_device(0.6 * 31.3, 20.0)));
    // The rod-crank linkage (nonlinear map) runs on the scalar path.
    assert!(!has_lane_model(&parity_device(
        0.6 * 31.3,
        20.0,
        "drag_parity_fixed",
        Formulation::Auto
    )));
}

#[test]
fn lane_widths_and_thread_counts_give_bit_identical_sweeps() {
    let points = design_points();
    let scalar = run(&points, 1, 1);
    for o in &scalar {
        let o = o.as_ref().unwrap();
        assert!(o.converged, "every design point has a stable orbit");
        // The residual the shooting reports is its own: the orbit closes to the tolerance.
        assert!(o.residual < 1e-7, "residual {}", o.residual);
    }
    let voltages = voltage_points();
    let voltage_scalar = run(&voltages, 1, 1);
    for lanes in [2, 4] {
        for (i, (a, b)) in voltage_scalar
            .iter()
            .zip(&run(&voltages, 1, lanes))
            .enumerate()
        {
            let (a, b) = (a.as_ref().unwrap(), b.as_ref().unwrap());
            assert_eq!(
                fingerprint(a),
                fingerprint(b),
                "voltage point {i}, {lanes} lanes"
            );
        }
    }
    for (threads, lanes) in [(1, 2), (1, 3), (1, 4), (2, 4), (2, 1)] {
        let before = points_completed_in_lanes();
        let other = run(&points, threads, lanes);
        if lanes > 1 {
            // Every point, chain starts included, ran in the lanes, but for continued points
            // with a soft direction (small K2), whose multipliers the scalar path checks at
            // the orbit.
            let soft = points
                .iter()
                .filter(|p| p.as_ref().unwrap().0.has_soft_direction())
                .count();
            assert!(soft < points.len() / 2, "{soft} soft points");
            assert!(points_completed_in_lanes() - before >= points.len() - soft);
        }
        for (i, (a, b)) in scalar.iter().zip(&other).enumerate() {
            let (a, b) = (a.as_ref().unwrap(), b.as_ref().unwrap());
            assert_eq!(
                fingerprint(a),
                fingerprint(b),
                "point {i}: {threads} threads, {lanes} lanes"
            );
        }
    }
}

#[test]
fn lane_sweeps_find_the_orbit_a_direct_tight_run_finds() {
    // Independent of the chains: a cold, tight-tolerance shooting of one point alone.
    let points = design_points();
    let swept = run(&points, 2, 4);
    let names = metric_list();
    for i in [3, 17, 25] {
        let (device, _) = points[i].as_ref().unwrap();
        let direct = simulate(
            device,
            &SimulationOptions {
                rtol: 1e-11,
                atol: 1e-13,
                steady_tol: 1e-9,
                ..shooting_options()
            },
        )
        .unwrap();
        let o = swept[i].as_ref().unwrap();
        let scale = direct
            .metrics
            .iter()
            .find(|(n, _)| n == "delta_tau_peak")
            .unwrap()
            .1;
        for (k, name) in names.iter().take(3).enumerate() {
            let reference = direct.metrics.iter().find(|(n, _)| n == name).unwrap().1;
            assert!(
                (o.metrics[k] - reference).abs() <= 1e-6 * scale,
                "point {i} {name}: {} vs {reference}",
                o.metrics[k]
            );
        }
    }
}

/// A coarse 4 × 4 grid in one chain: the chained starts are far from their orbits (first
/// residuals up to 1.4e-2: along each row and across row ends), so the grids their adaptive
/// first periods pick are picked again at the converged states (`REPICK_RESIDUAL`). Measured
/// before: τR peak up to 1.6e-6 off a direct tight run (a direct default run: 1.1e-9).
#[test]
fn a_coarse_sweep_chain_matches_direct_tight_runs_and_the_lanes_match_the_scalar_path() {
    let points: Vec<_> = (0..16)
        .map(|i| {
            let ratio = 0.3 + 0.7 * (i / 4) as f64 / 3.0;
            let k2 = 100.0 * (i % 4) as f64 / 3.0;
            Ok((linear_device(ratio * 31.3, k2), shooting_options()))
        })
        .collect();
    let scalar = run(&points, 1, 1);
    let lanes = run(&points, 1, 4);
    let names = metric_list();
    for (i, (a, b)) in scalar.iter().zip(&lanes).enumerate() {
        let (a, b) = (a.as_ref().unwrap(), b.as_ref().unwrap());
        assert_eq!(fingerprint(a), fingerprint(b), "point {i}");
        let (device, options) = points[i].as_ref().unwrap();
        let direct = simulate(
            device,
            &SimulationOptions {
                rtol: 1e-12,
                atol: 1e-14,
                ..options.clone()
            },
        )
        .unwrap();
        let value = |name: &str| direct.metrics.iter().find(|(n, _)| n == name).unwrap().1;
        let scale = value("right_roll_aero_peak");
        for (k, name) in names.iter().take(3).enumerate() {
            let error = (a.metrics[k] - value(name)).abs() / scale;
            assert!(error <= 1e-7, "point {i} {name}: {error:.1e} of τR's peak");
        }
    }
}

#[test]
fn failing_points_are_rows_with_their_errors_in_the_lane_path() {
    let mut points = design_points();
    // A point whose options are invalid and one whose device could not be built, mid-chain.
    let bad = SimulationOptions {
        samples_per_cycle: 4,
        ..shooting_options()
    };
    points[5] = Ok((linear_device(0.45 * 31.3, 30.0), bad));
    points[9] = Err(Error::invalid("wings[0].aero.omega1", -1.0, ">= 0"));
    let scalar = run(&points, 1, 1);
    let lanes = run(&points, 2, MAX_LANES);
    for (i, (a, b)) in scalar.iter().zip(&lanes).enumerate() {
        match (a, b) {
            (Ok(a), Ok(b)) => assert_eq!(fingerprint(a), fingerprint(b), "point {i}"),
            (Err(a), Err(b)) => {
                assert_eq!(a, b, "point {i}");
                let field = if i == 5 {
                    "samples_per_cycle"
                } else {
                    "wings[0].aero.omega1"
                };
                assert_eq!(a.field(), Some(field));
                assert!(i == 5 || i == 9);
            }
            _ => panic!("point {i}: {a:?} vs {b:?}"),
        }
    }
    assert!(lanes[5].is_err() && lanes[9].is_err() && lanes[10].is_ok());
}

#[test]
fn a_spent_wall_budget_is_the_budget_error_row_in_the_lanes() {
    // A chain's cold start and a continued point with a 1 µs `max_wall_ms`: the lanes stop
    // them inside their first period (before, they ran to the end: the lanes checked no
    // budget) and give the scalar path's budget error; the other rows are unchanged.
    let mut points = design_points();
    let spent = |omega: f64, k2: f64| {
        let options = SimulationOptions {
            max_wall_ms: Some(1e-3),
            ..shooting_options()
        };
        Ok((linear_device(omega, k2), options))
    };
    points[0] = spent(0.45 * 31.3, 0.0);
    points[5] = spent(0.45 * 31.3, 500.0 / 19.0);
    let scalar = run(&points, 1, 1);
    let lanes = run(&points, 2, MAX_LANES);
    for (i, (a, b)) in scalar.iter().zip(&lanes).enumerate() {
        match (a, b) {
            (Ok(a), Ok(b)) => assert_eq!(fingerprint(a), fingerprint(b), "point {i}"),
            (Err(a), Err(b)) => {
                assert!(i == 0 || i == 5, "point {i}: {a}");
                for e in [a, b] {
                    assert!(
                        matches!(e, Error::Integration { reason, .. }
                            if reason.contains("options.max_wall_ms")),
                        "point {i}: {e}"
                    );
                }
            }
            _ => panic!("point {i}: {a:?} vs {b:?}"),
        }
    }
    assert!(lanes[0].is_err() && lanes[5].is_err() && lanes[1].is_ok() && lanes[6].is_ok());
}

#[test]
fn lane_widths_are_validated() {
    assert_eq!(resolve_lanes(Some(1)).unwrap(), 1);
    assert_eq!(resolve_lanes(Some(MAX_LANES)).unwrap(), MAX_LANES);
    for bad in [0, MAX_LANES + 1] {
        let e = resolve_lanes(Some(bad)).unwrap_err();
        assert_eq!(e.field(), Some("lanes"), "{e}");
    }
    assert_eq!(LANES_ENV, "PARITYSIM_LANES");
}

#[test]
fn a_cancel_stops_the_lanes_and_keeps_the_finished_points() {
    // 160 lane points on one thread, cancelled once 6 finished: the finished points are the
    // scalar sweep's rows (bit for bit) and counted; the rest are not run (`None`).
    let points: Vec<_> = (0..4).flat_map(|_| design_points()).collect();
    let scalar = run(&points, 1, 1);
    let control = std::sync::Arc::new(SweepControl::new());
    let observer = {
        let control = std::sync::Arc::clone(&control);
        std::thread::spawn(move || {
            while control.finished() < 6 {
                std::thread::sleep(std::time::Duration::from_micros(50));
            }
            control.cancel();
        })
    };
    let slots =
        run_points_with_lanes(&points, &metric_list(), false, Some(1), Some(4), &control).unwrap();
    observer.join().unwrap();
    let done: Vec<usize> = (0..slots.len()).filter(|&i| slots[i].is_some()).collect();
    assert!(
        done.len() >= 6 && done.len() < points.len(),
        "{}",
        done.len()
    );
    assert_eq!(done.len(), control.finished());
    for i in done {
        let (a, b) = (scalar[i].as_ref().unwrap(), slots[i].as_ref().unwrap());
        assert_eq!(
            fingerprint(a),
            fingerprint(b.as_ref().unwrap()),
            "point {i}"
        );
    }
}

/// A Table 3.3 1-Cut rotating-wing device (blade elements, eq. 2.15 with ±200 µm → ±35°,
/// `offset_v + amplitude_v sin(2π 110 Hz t)`): the §3.4 Drag PARITY with hinge spring
/// `spring` (mN·mm/rad), or (`configuration` `lift_parity`) the §2.5 Lift PARITY with free
/// deviation θ, deviation spring `spring` and the tunable hinge.
fn rotating_device(configuration: &str, spring: f64, amplitude_v: f64, offset_v: f64) -> Device {
    use paritysim_aero::{BladeElementModel, CoefficientSet, Omegas};
    let free = configuration != "drag_parity";
    let wing = |inertia: [f64; 4], omegas: [f64; 4]| {
        let [ixx, iyy, izz, ixz] = inertia;
        let mut springs = [JointSpring::default(); 6];
        springs[if free { 3 } else { 5 }] = JointSpring::linear(spring, 0.0).unwrap();
        let blade = BladeElementModel::new(
            Omegas::new(omegas[0], omegas[1], omegas[2], omegas[3]).unwrap(),
            CoefficientSet::default(),
        )
        .unwrap();
        let wing = Wing::new(
            shoulder(90.0, 0.0),
            Matrix3::new(ixx, 0.0, ixz, 0.0, iyy, 0.0, ixz, 0.0, izz),
            springs,
            WingAero::BladeElement(blade),
        )
        .unwrap();
        if free {
            wing.with_tunable_hinge(
                paritysim_dynamics::TunableHinge::new(2.533928021702924, 0.0, 20.0).unwrap(),
            )
        } else {
            wing
        }
    };
    two_wing_device(
        [
            wing([49.0, 50.5, 1.56, 4.2], [46.8, 0.587, 17.5, 0.712]),
            wing([40.6, 42.0, 1.43, 3.38], [28.7, 0.419, 10.6, 0.787]),
        ],
        configuration,
        Drivetrain::LinearDifferential(
            LinearDifferential::new(35f64.to_radians() / 0.2, 2.5, 1.0).unwrap(),
        ),
        0.0,
        Actuator::new(
            paritysim_dynamics::actuator::THESIS_FORCE_PER_VOLT,
            paritysim_dynamics::actuator::THESIS_STIFFNESS,
            Waveform::sine(amplitude_v, 110.0, offset_v, 0.0).unwrap(),
            paritysim_dynamics::DcOffset::Ignore,
        )
        .unwrap(),
        Formulation::Auto,
    )
}

/// The sweep of `points` with every lane width and thread count equals the scalar sweep bit
/// for bit.
fn assert_lanes_match_the_scalar_sweep(
    points: &[paritysim_dynamics::Result<(Device, SimulationOptions)>],
    metrics: &[String],
) {
    let go = |threads: usize, lanes: usize| {
        run_with(points, metrics, threads, lanes)
            .into_iter()
            .map(|o| o.unwrap())
            .collect::<Vec<_>>()
    };
    let scalar = go(1, 1);
    assert!(scalar.iter().all(|o| o.converged));
    for (threads, lanes) in [(1, 4), (2, 4)] {
        let laned = go(threads, lanes);
        for (i, (a, b)) in scalar.iter().zip(&laned).enumerate() {
            assert_eq!(
                fingerprint(a),
                fingerprint(b),
                "point {i}, {threads} threads, {lanes} lanes"
            );
        }
    }
}

/// The switched devices have no lane model (their lanes did not pay: docs/findings.md §25), and
/// their sweeps beside lane-width and thread settings are the scalar sweep bit for bit: the
/// §3.4 stroke-plane device (blade elements switching, θ held) and the §2.5 Lift PARITY (free
/// deviation θ, whose points run on their own).
#[test]
fn switched_device_sweeps_do_not_depend_on_lanes_or_threads() {
    let points: Vec<_> = [70.0, 100.0]
        .iter()
        .flat_map(|&v| (0..6).map(move |k| (1.2 + 0.5 * k as f64, v)))
        .map(|(hinge, volts)| {
            let device = rotating_device("drag_parity", hinge, volts, 100.0);
            assert!(!has_lane_model(&device));
            Ok((device, shooting_options()))
        })
        .collect();
    let metrics: Vec<String> = [
        "left_stroke_amplitude",
        "right_rotation_amplitude",
        "left_rotation_phase_lag",
        "imbalance_peak_pct",
        "q2_amplitude",
    ]
    .map(String::from)
    .to_vec();
    assert_lanes_match_the_scalar_sweep(&points, &metrics);
    let points: Vec<_> = (0..4)
        .map(|k| {
            let device = rotating_device("lift_parity", 8.0 + k as f64, 85.0, 85.0);
            assert!(!has_lane_model(&device));
            Ok((device, shooting_options()))
        })
        .collect();
    let metrics: Vec<String> = ["tau_r_peak", "right_rotation_amplitude", "left_stroke_mean"]
        .map(String::from)
        .to_vec();
    assert_lanes_match_the_scalar_sweep(&points, &metrics);
}
