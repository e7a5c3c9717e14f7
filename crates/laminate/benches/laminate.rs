//! Criterion benches: ABD and cure curvature of the Mobee stack, bimorph design.
#![allow(missing_docs)] // criterion_group! generates undocumented items

use criterion::{Criterion, black_box, criterion_group, criterion_main};
use paritysim_laminate::pcmems::{CURE_DELTA_T, mobee_stack};
use paritysim_laminate::{ActuatorConstants, Bimorph};

fn laminate(c: &mut Criterion) {
    let stack = mobee_stack().unwrap();
    c.bench_function("mobee_abd", |b| b.iter(|| black_box(&stack).abd()));
    c.bench_function("mobee_cure_curvature", |b| {
        b.iter(|| black_box(&stack).thermal_curvature(CURE_DELTA_T).unwrap())
    });
    let layup = Bimorph::mobee_layup().unwrap();
    c.bench_function("bimorph_design_for_thesis", |b| {
        b.iter(|| {
            Bimorph::design_for(
                black_box(layup.clone()),
                ActuatorConstants::THESIS,
                0.5,
                0.5,
            )
            .unwrap()
        })
    });
}

criterion_group!(benches, laminate);
criterion_main!(benches);
