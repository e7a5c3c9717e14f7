//! The generic `sin_cos` against libm: scalar calls, and four values per `f64x4` call.
//! `cargo bench -p paritysim-simd`

#![allow(missing_docs)] // criterion_group! generates an undocumented pub fn

use criterion::{Criterion, black_box, criterion_group, criterion_main};
use wide::f64x4;

/// 1024 angles over the models' range (hinge and fit arguments, |x| <= 2π).
fn angles() -> Vec<f64> {
    (0..1024).map(|i| -6.0 + 12.0 * i as f64 / 1023.0).collect()
}

fn bench(c: &mut Criterion) {
    let xs = angles();
    let mut group = c.benchmark_group("sin_cos_1024");
    group.bench_function("libm", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &x in black_box(&xs) {
                let (s, c) = x.sin_cos();
                acc += s + c;
            }
            acc
        })
    });
    group.bench_function("generic_f64", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &x in black_box(&xs) {
                let (s, c) = paritysim_simd::sin_cos(x);
                acc += s + c;
            }
            acc
        })
    });
    group.bench_function("generic_f64x4", |b| {
        b.iter(|| {
            let mut acc = f64x4::splat(0.0);
            for x in black_box(&xs).chunks_exact(4) {
                let (s, c) = paritysim_simd::sin_cos(f64x4::new([x[0], x[1], x[2], x[3]]));
                acc += s + c;
            }
            acc
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
