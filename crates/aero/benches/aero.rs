//! Criterion benches: one blade-element moment evaluation (the ODE right-hand-side cost), and
//! the planform integrals of a 257-vertex outline.

#![allow(missing_docs)] // criterion_group! generates an undocumented pub fn

use criterion::{Criterion, black_box, criterion_group, criterion_main};
use nalgebra::Vector3;
use paritysim_aero::{
    BladeElementModel, CoefficientSet, DEFAULT_AIR_DENSITY, Dickinson1999, Omegas, Planform,
    WingState,
};

fn moments(c: &mut Criterion) {
    let omegas = Omegas::new(46.8, 0.587, 17.5, 0.712).unwrap();
    let model = BladeElementModel::new(omegas, CoefficientSet::default()).unwrap();
    let fixed = BladeElementModel::new(omegas, Dickinson1999).unwrap();
    let state = WingState::new(0.4, 0.05, -0.9, 0.6, 0.02, 1.1).unwrap();
    c.bench_function("blade_element_moments_state", |b| {
        b.iter(|| model.moments(black_box(&state)))
    });
    let omega = state.angular_velocity();
    c.bench_function("blade_element_moments_omega", |b| {
        b.iter(|| model.moments_omega(black_box(&omega)))
    });
    c.bench_function("blade_element_moments_omega_dickinson_static", |b| {
        b.iter(|| fixed.moments_omega(black_box(&Vector3::new(omega.x, omega.y, omega.z))))
    });
    let p = Planform::hmf_like(16.6, 64).unwrap();
    let full = BladeElementModel::new(
        p.omegas(DEFAULT_AIR_DENSITY).unwrap(),
        CoefficientSet::default(),
    )
    .unwrap();
    c.bench_function("blade_element_loads", |b| {
        b.iter(|| full.loads(black_box(&state)).unwrap())
    });
}

fn planform(c: &mut Criterion) {
    c.bench_function("planform_hmf_like_128", |b| {
        b.iter(|| Planform::hmf_like(black_box(16.6), 128).unwrap())
    });
}

criterion_group!(benches, moments, planform);
criterion_main!(benches);
