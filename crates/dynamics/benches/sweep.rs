//! Criterion benches of the sweep engine: a 64-point §3.3 Drag PARITY grid (K2 × drive voltage,
//! steady state at rtol 1e-8) on 1 and 2 threads. The ratio of the two is the parallel
//! efficiency; `benchmarks/sweeps.py` reports the same from Python with 1,000 points.

#![allow(missing_docs)] // criterion_group! generates undocumented items

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{Matrix3, Vector3};
use paritysim_constraints::Constraints;
use paritysim_dynamics::device::{Device, DeviceSpec, Formulation, Transmission};
use paritysim_dynamics::sweep::{Grid, SweepControl, SweepSettings, sweep};
use paritysim_dynamics::{
    Actuator, JointSpring, Result, SimulationOptions, Waveform, Wing, WingAero,
};
use paritysim_kinematics::drivetrain::LinkageDifferential;
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
            "drivetrain.balance_stiffness",
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

criterion_group!(benches, sweeps);
criterion_main!(benches);
