//! Criterion benches of the Floquet module: the 200×200 (β0, κ) stability chart of eq. 2.25
//! (target: well under 1 s on 2 cores), one monodromy matrix, and the nonlinear Floquet analysis
//! (shooting + finite-difference monodromy) of the §3.3 Drag PARITY device.

#![allow(missing_docs)] // criterion_group! generates undocumented items

use criterion::{Criterion, black_box, criterion_group, criterion_main};
use nalgebra::{Matrix3, Vector3};
use paritysim_constraints::Constraints;
use paritysim_dynamics::device::{Device, DeviceSpec, Formulation, Transmission};
use paritysim_dynamics::floquet::{ShootingOptions, floquet, hill_monodromy, stability_chart};
use paritysim_dynamics::{Actuator, JointSpring, Waveform, Wing, WingAero};
use paritysim_kinematics::drivetrain::LinkageDifferential;
use paritysim_kinematics::{Drivetrain, SphericalShoulder};

fn axis(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| lo + (hi - lo) * i as f64 / (n - 1) as f64)
        .collect()
}

fn section_3_3_device() -> Device {
    let sh = SphericalShoulder::new(std::f64::consts::FRAC_PI_2, 0.0).unwrap();
    let wing = Wing::new(
        sh,
        Matrix3::from_diagonal(&Vector3::new(29.0, 29.0, 1.0)),
        [JointSpring::default(); 6],
        WingAero::stroke_drag(31.3, 3.4609).unwrap(),
    )
    .unwrap();
    Device::new(DeviceSpec {
        wings: vec![wing.clone(), wing],
        constraints: Constraints::configuration("drag_parity_fixed").unwrap(),
        transmission: Some(
            Transmission::new(
                Drivetrain::LinkageDifferential(LinkageDifferential::thesis()),
                500.0,
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

fn chart(c: &mut Criterion) {
    // The Fig. 2.13 map extended to negative damping and stiffness.
    let beta0 = axis(-1.0, 5.0, 200);
    let kappa = axis(-1.0, 4.0, 200);
    c.bench_function("stability_chart_200x200", |b| {
        b.iter(|| stability_chart(black_box(&beta0), black_box(&kappa)).unwrap())
    });
    c.bench_function("hill_monodromy", |b| {
        b.iter(|| hill_monodromy(black_box(2.0), black_box(1.5), black_box(-1.0)).unwrap())
    });
    let device = section_3_3_device();
    let options = ShootingOptions::default();
    let mut group = c.benchmark_group("nonlinear");
    group.sample_size(20);
    group.bench_function("floquet_section_3_3", |b| {
        b.iter(|| floquet(black_box(&device), &options).unwrap())
    });
    group.finish();
}

criterion_group!(benches, chart);
criterion_main!(benches);
