//! Criterion benches: shoulder pose + partials, and each drivetrain evaluation.
#![allow(missing_docs)] // criterion_group! generates undocumented items

use criterion::{Criterion, black_box, criterion_group, criterion_main};
use paritysim_kinematics::drivetrain::{HmfFourBar, LinearDifferential, LinkageDifferential};
use paritysim_kinematics::{Drivetrain, RodCrank, SphericalShoulder};

fn shoulder(c: &mut Criterion) {
    let sh = SphericalShoulder::new(120f64.to_radians(), 60f64.to_radians()).unwrap();
    c.bench_function("shoulder_pose", |b| {
        b.iter(|| {
            sh.pose(black_box(0.4), black_box(0.2), black_box(0.1))
                .unwrap()
        })
    });
    c.bench_function("shoulder_pose_partials_j6", |b| {
        b.iter(|| {
            let pose = sh
                .pose(black_box(0.4), black_box(0.2), black_box(0.1))
                .unwrap();
            let [_, g2, _, _, g5, _] = pose.joint_angles;
            let p = sh.partials_at(0.4, 0.2, g2, g5).unwrap();
            sh.jacobian(&pose, &p)
        })
    });
}

fn drivetrains(c: &mut Criterion) {
    let cases = [
        (
            "drivetrain_hmf_four_bar",
            Drivetrain::HmfFourBar(HmfFourBar::new(RodCrank::THESIS)),
        ),
        (
            "drivetrain_linear_differential",
            Drivetrain::LinearDifferential(LinearDifferential::new(2.5, 2.5, 1.0).unwrap()),
        ),
        (
            "drivetrain_linkage_differential",
            Drivetrain::LinkageDifferential(LinkageDifferential::thesis()),
        ),
    ];
    for (name, d) in cases {
        c.bench_function(name, |b| {
            b.iter(|| d.evaluate(black_box(0.1), black_box(0.02)).unwrap())
        });
    }
}

criterion_group!(benches, shoulder, drivetrains);
criterion_main!(benches);
