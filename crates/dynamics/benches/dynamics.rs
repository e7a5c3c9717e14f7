//! Criterion benches: right-hand side of one wing and of the constrained two-wing system, a
//! 20-wingbeat §3.3 `drag_parity_fixed` run at rtol 1e-8, and issue 12's single trials
//! (`cargo bench -p paritysim-dynamics --bench dynamics -- trial`).

#![allow(missing_docs)] // criterion_group! generates undocumented items

use criterion::{Criterion, black_box, criterion_group, criterion_main};
use nalgebra::{Matrix3, Vector3};
use paritysim_constraints::{Constraints, Vec6};
use paritysim_dynamics::device::{Device, DeviceSpec, Formulation, Transmission};
use paritysim_dynamics::{
    Actuator, JointSpring, SimulationOptions, Waveform, Wing, WingAero, simulate,
};
use paritysim_kinematics::drivetrain::LinkageDifferential;
use paritysim_kinematics::{Drivetrain, SphericalShoulder};

fn wing(omega: f64) -> Wing {
    let sh = SphericalShoulder::new(std::f64::consts::FRAC_PI_2, 0.0).unwrap();
    Wing::new(
        sh,
        Matrix3::from_diagonal(&Vector3::new(29.0, 29.0, 1.0)),
        [JointSpring::default(); 6],
        WingAero::stroke_drag(omega, 3.4609).unwrap(),
    )
    .unwrap()
}

fn section_3_3_device(formulation: Formulation) -> Device {
    Device::new(DeviceSpec {
        wings: vec![wing(31.3), wing(31.3)],
        constraints: Constraints::configuration("drag_parity_fixed").unwrap(),
        transmission: Some(
            Transmission::new(
                Drivetrain::LinkageDifferential(LinkageDifferential::thesis()),
                1.0,
            )
            .unwrap(),
        ),
        actuator: Some(Actuator::thesis(
            Waveform::sine(100.0, 110.0, 0.0, 0.0).unwrap(),
        )),
        formulation,
    })
    .unwrap()
}

fn rhs(c: &mut Criterion) {
    let sh = SphericalShoulder::new(120f64.to_radians(), 60f64.to_radians()).unwrap();
    let full = Matrix3::new(29.0, 0.4, -3.1, 0.4, 30.5, 0.7, -3.1, 0.7, 2.2);
    let springs = [JointSpring::linear(10.0, 0.0).unwrap(); 6];
    let one = Wing::new(sh, full, springs, WingAero::stroke_drag(31.3, 1.0).unwrap()).unwrap();
    let p = Vector3::new(0.3, 0.1, 0.4);
    let v = Vector3::new(0.5, -0.2, 1.0);
    c.bench_function("rhs_one_wing_terms", |b| {
        b.iter(|| one.terms(black_box(&p), black_box(&v)).unwrap())
    });

    let device = section_3_3_device(Formulation::NullSpace);
    let y = device
        .state_from(
            &Vec6::new(0.2, 0.0, 0.0, 0.25, 0.0, 0.0),
            &Vec6::new(0.3, 0.0, 0.0, 0.25, 0.0, 0.0),
        )
        .unwrap();
    let mut dydt = paritysim_dynamics::State::default();
    c.bench_function("rhs_two_wing_drag_parity_fixed_null_space", |b| {
        b.iter(|| {
            device
                .rhs(black_box(1.0), black_box(&y), &mut dydt)
                .unwrap()
        })
    });
    let fast = section_3_3_device(Formulation::DrivetrainCoordinates);
    let y = fast
        .state_from(
            &Vec6::new(0.2, 0.0, 0.0, 0.25, 0.0, 0.0),
            &Vec6::new(0.3, 0.0, 0.0, 0.25, 0.0, 0.0),
        )
        .unwrap();
    c.bench_function(
        "rhs_two_wing_drag_parity_fixed_drivetrain_coordinates",
        |b| b.iter(|| fast.rhs(black_box(1.0), black_box(&y), &mut dydt).unwrap()),
    );
}

fn run(c: &mut Criterion) {
    let device = section_3_3_device(Formulation::Auto);
    let options = SimulationOptions {
        rtol: 1e-8,
        atol: 1e-10,
        min_cycles: 19,
        max_cycles: 19,
        steady_tol: 1e-30,
        samples_per_cycle: 100,
        ..Default::default()
    };
    let mut group = c.benchmark_group("simulate");
    group.sample_size(20);
    group.bench_function("drag_parity_fixed_20_wingbeats_rtol_1e-8", |b| {
        b.iter(|| simulate(&device, &options).unwrap())
    });
    let general = section_3_3_device(Formulation::NullSpace);
    group.bench_function("drag_parity_fixed_20_wingbeats_rtol_1e-8_null_space", |b| {
        b.iter(|| simulate(&general, &options).unwrap())
    });
    group.finish();
}

/// A Table 3.3 wing (blade element, Ω1..Ω4): with `free_deviation` the §2.5 deviation spring
/// (10 mN·mm/rad) and tunable hinge, else the §3.4 hinge spring 2.53 mN·mm/rad.
fn table_3_3_wing(inertia: [f64; 4], omegas: [f64; 4], free_deviation: bool) -> Wing {
    use paritysim_aero::{BladeElementModel, CoefficientSet, Omegas};
    let [ixx, iyy, izz, ixz] = inertia;
    let sh = SphericalShoulder::new(std::f64::consts::FRAC_PI_2, 0.0).unwrap();
    let matrix = Matrix3::new(ixx, 0.0, ixz, 0.0, iyy, 0.0, ixz, 0.0, izz);
    let blade = BladeElementModel::new(
        Omegas::new(omegas[0], omegas[1], omegas[2], omegas[3]).unwrap(),
        CoefficientSet::default(),
    )
    .unwrap();
    let mut springs = [JointSpring::default(); 6];
    if !free_deviation {
        springs[5] = JointSpring::linear(2.53, 0.0).unwrap();
        return Wing::new(sh, matrix, springs, WingAero::BladeElement(blade)).unwrap();
    }
    springs[3] = JointSpring::linear(10.0, 0.0).unwrap();
    Wing::new(sh, matrix, springs, WingAero::BladeElement(blade))
        .unwrap()
        .with_tunable_hinge(
            paritysim_dynamics::TunableHinge::new(2.533928021702924, 0.0, 20.0).unwrap(),
        )
}

/// §3.4 (`drag_parity`: rotating wings) or §2.5 (`lift_parity` / `dual_parity`: free
/// deviation θ) on the Table 3.3 1-Cut wings, eq. 2.15 with ±200 µm → ±35°,
/// V = 100 + 100 sin(2π 110 Hz t) with the DC part ignored.
fn table_3_3_device(configuration: &str) -> Device {
    let free = configuration != "drag_parity";
    Device::new(DeviceSpec {
        wings: vec![
            table_3_3_wing([49.0, 50.5, 1.56, 4.2], [46.8, 0.587, 17.5, 0.712], free),
            table_3_3_wing([40.6, 42.0, 1.43, 3.38], [28.7, 0.419, 10.6, 0.787], free),
        ],
        constraints: Constraints::configuration(configuration).unwrap(),
        transmission: Some(
            Transmission::new(
                Drivetrain::LinearDifferential(
                    paritysim_kinematics::drivetrain::LinearDifferential::new(
                        35f64.to_radians() / 0.2,
                        2.5,
                        1.0,
                    )
                    .unwrap(),
                ),
                0.0,
            )
            .unwrap(),
        ),
        actuator: Some(
            Actuator::new(
                paritysim_dynamics::actuator::THESIS_FORCE_PER_VOLT,
                paritysim_dynamics::actuator::THESIS_STIFFNESS,
                Waveform::sine(100.0, 110.0, 100.0, 0.0).unwrap(),
                paritysim_dynamics::DcOffset::Ignore,
            )
            .unwrap(),
        ),
        formulation: Formulation::Auto,
    })
    .unwrap()
}

/// §3.4: two rotating Table 3.3 wings (blade element, hinge spring), Drag PARITY (#3).
fn rotating(c: &mut Criterion) {
    let device = table_3_3_device("drag_parity");
    let options = SimulationOptions {
        rtol: 1e-8,
        atol: 1e-10,
        min_cycles: 14,
        max_cycles: 14,
        steady_tol: 1e-30,
        samples_per_cycle: 100,
        ..Default::default()
    };
    let mut group = c.benchmark_group("simulate");
    group.sample_size(20);
    group.bench_function("section_3_4_rotating_15_wingbeats_rtol_1e-8", |b| {
        b.iter(|| simulate(&device, &options).unwrap())
    });
    group.finish();
}

/// Issue 12's single trials (`examples/trial.rs`'s workload): 20 wingbeats from rest at rtol
/// 1e-8, every metric of the last cycle from 4000 samples, no trajectory column. The §3.3
/// Drag PARITY device on the linear map (T = L = 2.5, K2 = 10, 1-Cut, 120 mN: goal ≤ 0.7 ms),
/// the §3.4 rotating device (goal ≤ 3 ms) and the §2.5 Lift / Dual PARITY devices (free θ).
fn trial(c: &mut Criterion) {
    let drag = Device::new(DeviceSpec {
        wings: vec![wing(0.6 * 31.3), wing(31.3)],
        constraints: Constraints::configuration("drag_parity_fixed").unwrap(),
        transmission: Some(
            Transmission::new(
                Drivetrain::LinearDifferential(
                    paritysim_kinematics::drivetrain::LinearDifferential::new(2.5, 2.5, 1.0)
                        .unwrap(),
                ),
                10.0,
            )
            .unwrap(),
        ),
        actuator: Some(Actuator::thesis(
            Waveform::sine(100.0, 110.0, 0.0, 0.0).unwrap(),
        )),
        formulation: Formulation::Auto,
    })
    .unwrap();
    let options = SimulationOptions {
        rtol: 1e-8,
        atol: 1e-10,
        min_cycles: 19,
        max_cycles: 19,
        steady_tol: 1e-30,
        samples_per_cycle: 4000,
        columns: Some(Vec::new()),
        ..Default::default()
    };
    let mut group = c.benchmark_group("trial");
    group.sample_size(10);
    let cases = [
        ("section_3_3_drag_parity_linear_map", drag),
        ("section_3_4_rotating", table_3_3_device("drag_parity")),
        (
            "section_2_5_lift_parity_free_theta",
            table_3_3_device("lift_parity"),
        ),
        (
            "section_2_5_dual_parity_free_theta",
            table_3_3_device("dual_parity"),
        ),
    ];
    for (name, device) in &cases {
        group.bench_function(*name, |b| b.iter(|| simulate(device, &options).unwrap()));
    }
    group.finish();
}

criterion_group!(benches, rhs, run, rotating, trial);
criterion_main!(benches);
