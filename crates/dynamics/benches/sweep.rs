//! Criterion benches of the sweep engine: a 64-point §3.3 Drag PARITY grid (K2 × drive voltage,
//! steady state at rtol 1e-8) on 1 and 2 threads. The ratio of the two is the parallel
//! efficiency; `benchmarks/sweeps.py` reports the same from Python with 1,000 points.
//! `sweep_lanes`: the issue 12 linear-map design grid (128 shooting points, Table 3.2 metrics
//! from 4000 samples, one thread) at lane width 1 (the scalar path) and 4 (SIMD lanes): the
//! ratio is what the lanes buy (their results are bit-identical, tests/dynamics/lanes.rs).

#![allow(missing_docs)] // criterion_group! generates undocumented items

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{Matrix3, Vector3};
use paritysim_constraints::Constraints;
use paritysim_dynamics::device::{Device, DeviceSpec, Formulation, Transmission};
use paritysim_dynamics::sweep::{Grid, SweepControl, SweepSettings, run_points_with_lanes, sweep};
use paritysim_dynamics::{
    Actuator, JointSpring, Result, SimulationOptions, Waveform, Wing, WingAero,
};
use paritysim_kinematics::drivetrain::{LinearDifferential, LinkageDifferential};
use paritysim_kinematics::{Drivetrain, SphericalShoulder};

fn device(values: &[f64]) -> Result<Device> {
    let wing = || -> Result<Wing> {
        Wing::new(
            SphericalShoulder::new(std::f64::consts::FRAC_PI_2, 0.0)?,
            Matrix3::from_diagonal(&Vector3::new(29.0, 29.0, 1.0)),
            [JointSpring::default(); 6],
            WingAero::stroke_drag(31.3, 3.4609)?,
        )
    };
    Device::new(DeviceSpec {
        wings: vec![wing()?, wing()?],
        constraints: Constraints::configuration("drag_parity_fixed")?,
        transmission: Some(Transmission::new(
            Drivetrain::LinkageDifferential(LinkageDifferential::thesis()),
            values[0],
        )?),
        actuator: Some(Actuator::thesis(Waveform::sine(
            values[1], 110.0, 0.0, 0.0,
        )?)),
        formulation: Formulation::Auto,
    })
}

fn sweeps(c: &mut Criterion) {
    let table = Grid::new()
        .axis(
            "drivetrain.balance_spring",
            (0..8).map(|i| 1.0 + 2.0 * i as f64),
        )
        .and_then(|g| {
            g.axis(
                "actuator.waveform.amplitude_v",
                (0..8).map(|i| 40.0 + 8.0 * i as f64),
            )
        })
        .unwrap()
        .table();
    let options = SimulationOptions::default();
    let mut group = c.benchmark_group("sweep");
    group.sample_size(10);
    for threads in [1, 2] {
        let settings = SweepSettings {
            threads: Some(threads),
            metrics: Some(vec!["left_stroke_amplitude".into()]),
            keep_cycle: false,
        };
        group.bench_function(format!("drag_parity_64_points_{threads}_threads"), |b| {
            b.iter(|| {
                let r = sweep(&table, device, &options, &settings, &SweepControl::new()).unwrap();
                assert!(r.rows.iter().all(|row| row.outcome.is_ok()));
                r
            })
        });
    }
    group.finish();
}

/// The `benchmarks/vs_jax.py` device: eq. 2.15 (T = L = 2.5), drag C = 1, Ω^R = 31.3, 120 mN.
fn linear_device(omega_ratio: f64, k2: f64) -> Device {
    let wing = |omega: f64| {
        Wing::new(
            SphericalShoulder::new(std::f64::consts::FRAC_PI_2, 0.0).unwrap(),
            Matrix3::from_diagonal(&Vector3::new(29.0, 29.0, 1.0)),
            [JointSpring::default(); 6],
            WingAero::stroke_drag(omega, 1.0).unwrap(),
        )
        .unwrap()
    };
    Device::new(DeviceSpec {
        wings: vec![wing(omega_ratio * 31.3), wing(31.3)],
        constraints: Constraints::configuration("drag_parity_fixed").unwrap(),
        transmission: Some(
            Transmission::new(
                Drivetrain::LinearDifferential(LinearDifferential::new(2.5, 2.5, 1.0).unwrap()),
                k2,
            )
            .unwrap(),
        ),
        actuator: Some(Actuator::thesis(
            Waveform::sine(100.0, 110.0, 0.0, 0.0).unwrap(),
        )),
        formulation: Formulation::Auto,
    })
    .unwrap()
}

fn lanes(c: &mut Criterion) {
    let options = SimulationOptions {
        steady_state: paritysim_dynamics::SteadyState::Shooting,
        samples_per_cycle: 4000,
        ..Default::default()
    };
    // Rows 8..12 of the 32 × 32 grid: 8 chains of 16 points.
    let points: Vec<_> = (8..12)
        .flat_map(|r| (0..32).map(move |k| (0.3 + 0.7 * r as f64 / 31.0, 100.0 * k as f64 / 31.0)))
        .map(|(ratio, k2)| Ok((linear_device(ratio, k2), options.clone())))
        .collect();
    let metrics: Vec<String> = [
        "delta_tau_peak",
        "tau_r_peak",
        "tau_l_peak",
        "imbalance_peak_pct",
    ]
    .map(String::from)
    .to_vec();
    let mut group = c.benchmark_group("sweep_lanes");
    group.sample_size(10);
    for width in [1, 4] {
        group.bench_function(format!("linear_map_128_points_{width}_lanes"), |b| {
            b.iter(|| {
                let slots = run_points_with_lanes(
                    &points,
                    &metrics,
                    false,
                    Some(1),
                    Some(width),
                    &SweepControl::new(),
                )
                .unwrap();
                assert!(slots.iter().all(|s| matches!(s, Some(Ok(_)))));
                slots
            })
        });
    }
    group.finish();
}

criterion_group!(benches, sweeps, lanes);
criterion_main!(benches);
