//! Newton shooting for the periodic steady state against long transients, and continuation
//! in sweeps.

use super::*;
use paritysim_dynamics::SteadyState;
use paritysim_dynamics::floquet::{ShootingOptions, floquet};
use paritysim_dynamics::sweep::{ParameterTable, SweepControl, SweepSettings, sweep};

fn metric(r: &paritysim_dynamics::SimulationResult, name: &str) -> f64 {
    r.metrics.iter().find(|(n, _)| n == name).unwrap().1
}

fn shooting() -> SimulationOptions {
    SimulationOptions {
        steady_state: SteadyState::Shooting,
        samples_per_cycle: 400,
        columns: Some(vec![]),
        ..Default::default()
    }
}

#[test]
fn shooting_reaches_the_orbit_of_a_long_transient() {
    let device = linear_parity(0.6 * 31.3, Formulation::Auto);
    let fast = simulate(&device, &shooting()).unwrap();
    let long = simulate(
        &device,
        &SimulationOptions {
            steady_state: SteadyState::Transient,
            steady_tol: 1e-10,
            max_cycles: 5000,
            rtol: 1e-12,
            atol: 1e-14,
            ..shooting()
        },
    )
    .unwrap();
    assert!(long.converged && fast.converged);
    assert!(fast.residual <= 1e-9, "{:e}", fast.residual);
    assert!(
        fast.cycles_run * 4 < long.cycles_run,
        "{} vs {}",
        fast.cycles_run,
        long.cycles_run
    );
    for name in ["delta_tau_peak", "tau_r_peak", "tau_l_peak", "q2_amplitude"] {
        let (a, b) = (metric(&fast, name), metric(&long, name));
        assert!((a - b).abs() <= 1e-7 * b.abs(), "{name}: {a} vs {b}");
    }
    for name in ["imbalance_instantaneous_pct", "imbalance_peak_pct"] {
        let (a, b) = (metric(&fast, name), metric(&long, name));
        assert!((a - b).abs() <= 1e-5, "{name}: {a} vs {b}");
    }
    // The multipliers come with the result (from the chord Jacobian, evaluated within the
    // 1e-3 warm-up tolerance of the orbit) and agree with the stability analysis at the orbit.
    let f = floquet(
        &device,
        &ShootingOptions {
            rtol: 1e-8,
            atol: 1e-10,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(fast.multipliers.len(), 4);
    for (a, b) in fast.multipliers.iter().zip(&f.multipliers) {
        assert!((a - b).norm() < 2e-3, "{a} vs {b}");
    }
}

#[test]
fn continuation_sweeps_agree_with_cold_starts_and_any_thread_count() {
    let build = |v: &[f64]| {
        let linear = Drivetrain::LinearDifferential(
            paritysim_kinematics::drivetrain::LinearDifferential::new(2.5, 2.5, 1.0).unwrap(),
        );
        Ok(parity_device_with(
            v[0],
            v[1],
            "drag_parity_fixed",
            Formulation::Auto,
            linear,
        ))
    };
    let rows: Vec<Vec<f64>> = [0.6, 0.8]
        .iter()
        .flat_map(|&r| (0..10).map(move |k| vec![r * 31.3, 5.0 + 10.0 * k as f64]))
        .collect();
    let table = ParameterTable::new(vec!["omega_l".into(), "k2".into()], rows).unwrap();
    let names = vec![
        "delta_tau_peak".to_string(),
        "imbalance_peak_pct".to_string(),
    ];
    let run = |threads: usize, options: &SimulationOptions| {
        sweep(
            &table,
            build,
            options,
            &SweepSettings {
                threads: Some(threads),
                metrics: Some(names.clone()),
                keep_cycle: false,
            },
            &SweepControl::new(),
        )
        .unwrap()
    };
    // Tolerances where the integration error is below the 1e-7 compared.
    let options = SimulationOptions {
        rtol: 1e-10,
        atol: 1e-12,
        ..shooting()
    };
    let one = run(1, &options);
    let two = run(2, &options);
    let cycles = |r: &paritysim_dynamics::sweep::SweepResult| {
        r.rows
            .iter()
            .map(|row| row.outcome.as_ref().unwrap().cycles_run)
            .sum::<usize>()
    };
    for (a, b) in one.rows.iter().zip(&two.rows) {
        let (a, b) = (a.outcome.as_ref().unwrap(), b.outcome.as_ref().unwrap());
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a.metrics), bits(&b.metrics));
    }
    // Cold starts (every point from rest, transient to 1e-9 per cycle, same tolerances) find
    // the same orbits.
    let cold = run(
        2,
        &SimulationOptions {
            steady_state: SteadyState::Transient,
            steady_tol: 1e-9,
            max_cycles: 5000,
            ..options.clone()
        },
    );
    for (a, b) in one.rows.iter().zip(&cold.rows) {
        let (a, b) = (a.outcome.as_ref().unwrap(), b.outcome.as_ref().unwrap());
        assert!(a.converged && a.residual <= 1e-9);
        assert!(
            (a.metrics[0] - b.metrics[0]).abs() <= 1e-7 * b.metrics[0],
            "{:?} vs {:?}",
            a.metrics,
            b.metrics
        );
        assert!((a.metrics[1] - b.metrics[1]).abs() <= 1e-5);
    }
    assert!(
        cycles(&one) * 4 < cycles(&cold),
        "{} vs {}",
        cycles(&one),
        cycles(&cold)
    );
}

#[test]
fn stroke_samples_give_the_metrics_of_full_samples() {
    // Two formulations of the same samples: the full model evaluation (mass matrix, body
    // torques through the wing rotations) and the stroke-only sample (forward map and drag
    // torque about the stroke axis). Linear map and rod-crank linkage, both Table 3.2 and the
    // stroke metrics.
    // K2 = 500: the linkage's whippletree mode is stable there (docs/findings.md#3).
    let linkage = parity_device(0.6 * 31.3, 500.0, "drag_parity_fixed", Formulation::Auto);
    for device in [linear_parity(0.6 * 31.3, Formulation::Auto), linkage] {
        let names: Vec<String> = [
            "delta_tau_peak",
            "tau_l_peak",
            "tau_r_peak",
            "imbalance_instantaneous_pct",
            "imbalance_peak_pct",
            "left_stroke_amplitude",
            "right_stroke_mean",
            "left_roll_aero_mean",
            "right_rotation_amplitude",
            "q2_amplitude",
            "actuator_force_peak",
        ]
        .map(String::from)
        .to_vec();
        // Any column makes every sample a full one.
        let full = simulate(
            &device,
            &SimulationOptions {
                columns: Some(vec!["q2".into()]),
                ..shooting()
            },
        )
        .unwrap();
        let lean = simulate(
            &device,
            &SimulationOptions {
                metrics: Some(names.clone()),
                ..shooting()
            },
        )
        .unwrap();
        for name in &names {
            let (a, b) = (metric(&lean, name), metric(&full, name));
            assert!(
                (a - b).abs() <= 1e-12 * (1.0 + b.abs()),
                "{name}: stroke {a} vs full {b}"
            );
        }
        // Metrics the stroke samples cannot give are NaN, not a wrong number.
        assert!(metric(&lean, "roll_total_peak").is_nan());
        assert!(metric(&full, "roll_total_peak").is_finite());
    }
}

#[test]
fn shooting_at_default_tolerances_finds_a_slow_mode_orbit_to_1e_7() {
    // K2 = 3.2 on the linear map: whippletree multiplier 0.98. With the adaptive map Newton
    // stalled near rtol and the transient fallback stopped 5e-6 off the orbit; on the frozen
    // grid the default-option result is within 1e-7 of an rtol-1e-12 long transient.
    let device = parity_device_with(
        0.684 * 31.3,
        3.2,
        "drag_parity_fixed",
        Formulation::Auto,
        Drivetrain::LinearDifferential(
            paritysim_kinematics::drivetrain::LinearDifferential::new(2.5, 2.5, 1.0).unwrap(),
        ),
    );
    let fast = simulate(&device, &shooting()).unwrap();
    let reference = simulate(
        &device,
        &SimulationOptions {
            steady_state: SteadyState::Transient,
            steady_tol: 1e-12,
            max_cycles: 20_000,
            rtol: 1e-12,
            atol: 1e-14,
            ..shooting()
        },
    )
    .unwrap();
    assert!(fast.converged && reference.converged);
    assert!(fast.multipliers[0].norm() > 0.95, "{:?}", fast.multipliers);
    let tau_r = metric(&reference, "tau_r_peak");
    for name in ["delta_tau_peak", "tau_r_peak", "tau_l_peak"] {
        let (a, b) = (metric(&fast, name), metric(&reference, name));
        assert!((a - b).abs() <= 1e-7 * tau_r, "{name}: {a} vs {b}");
    }
    for name in ["imbalance_instantaneous_pct", "imbalance_peak_pct"] {
        let (a, b) = (metric(&fast, name), metric(&reference, name));
        assert!((a - b).abs() <= 1e-5, "{name}: {a} vs {b}");
    }
}

#[test]
fn default_options_meet_the_accuracy_goals_on_a_slow_mode() {
    // Issue 12's goals at *default* options (torques 1e-7 relative, imbalance percentages 1e-5
    // points of an rtol-1e-12 reference) on a slow whippletree mode (K2 = 1 on the linear
    // map). The former default, the transient, stops on `steady_tol` off this orbit: this test
    // failed with it (measured: transient torques 6.3e-6 relative and percentages 5.3e-4
    // points off, shooting 8.8e-10 and 6.9e-8).
    let device = parity_device_with(
        0.684 * 31.3,
        1.0,
        "drag_parity_fixed",
        Formulation::Auto,
        Drivetrain::LinearDifferential(
            paritysim_kinematics::drivetrain::LinearDifferential::new(2.5, 2.5, 1.0).unwrap(),
        ),
    );
    let defaults = SimulationOptions {
        samples_per_cycle: 400,
        columns: Some(vec![]),
        ..Default::default()
    };
    let reference = simulate(
        &device,
        &SimulationOptions {
            steady_state: SteadyState::Transient,
            steady_tol: 1e-12,
            max_cycles: 20_000,
            rtol: 1e-12,
            atol: 1e-14,
            ..defaults.clone()
        },
    )
    .unwrap();
    let tau_r = metric(&reference, "tau_r_peak");
    let torque_error = |r: &paritysim_dynamics::SimulationResult| {
        ["delta_tau_peak", "tau_r_peak", "tau_l_peak"]
            .iter()
            .map(|name| (metric(r, name) - metric(&reference, name)).abs() / tau_r)
            .fold(0.0, f64::max)
    };
    let percent_error = |r: &paritysim_dynamics::SimulationResult| {
        ["imbalance_instantaneous_pct", "imbalance_peak_pct"]
            .iter()
            .map(|name| (metric(r, name) - metric(&reference, name)).abs())
            .fold(0.0, f64::max)
    };
    let default = simulate(&device, &defaults).unwrap();
    assert!(default.converged && reference.converged);
    assert!(
        torque_error(&default) <= 1e-7,
        "{:e}",
        torque_error(&default)
    );
    assert!(
        percent_error(&default) <= 1e-5,
        "{:e}",
        percent_error(&default)
    );
    // The bound discriminates: the transient at the same options misses it.
    let transient = SimulationOptions {
        steady_state: SteadyState::Transient,
        ..defaults
    };
    let transient = simulate(&device, &transient).unwrap();
    let (t, p) = (torque_error(&transient), percent_error(&transient));
    assert!(t > 1e-7 || p > 1e-5, "{t:e} {p:e}");
}
