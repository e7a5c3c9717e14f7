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
