//! One second of free flight (issue 17's target: <= 100 ms): the §3.4 Drag PARITY device
//! (both wings rotating, blade-element aerodynamics) released from its clamped steady state,
//! 110 wingbeats at 110 Hz, metrics only, at the default options (DOP853 rtol 1e-8, event
//! location at the stroke reversals); `..._without_events` the same integration with steps
//! straddling the blade-element model's jumps (the state before event location). The clamped
//! steady state is computed once outside the timed loop; `fixed_body_110_cycles` times the
//! engine (fixed body, same device, same window, default DOP853 rtol 1e-8) for the ratio.

#![allow(missing_docs)]

#[path = "../tests/common.rs"]
mod common;

use criterion::{Criterion, criterion_group, criterion_main};
use paritysim_dynamics::integrate::{Integrator, RungeKutta};
use paritysim_dynamics::{SimulationOptions, simulate};
use paritysim_flight::model::Inputs;
use paritysim_flight::run::released;
use paritysim_flight::{BodyMode, FlightModel, FlightSystem, integrate_flight};

fn bench(c: &mut Criterion) {
    let device = common::device_3_4(
        common::wing_3_4(false, 1.0, 2.533928021702924),
        common::wing_3_4(true, 1.0, 2.533928021702924),
        0.0,
    );
    let options = SimulationOptions::default();
    let steady = simulate(&device, &options).unwrap();
    let model = FlightModel::new(&device, common::hmf_body(BodyMode::Free), Vec::new()).unwrap();
    let y0 = released(&model, &model.convert_state(&steady.steady_state).unwrap());
    let period = device.period().unwrap();
    let t0 = steady.cycles_run as f64 * period;
    let t1 = t0 + 110.0 * period;
    let mut group = c.benchmark_group("flight");
    group.sample_size(10);
    group.bench_function("free_flight_1s_110_cycles", |b| {
        b.iter(|| {
            integrate_flight(
                &model,
                &options,
                &Inputs::default(),
                t0,
                &y0,
                t1,
                &[],
                &mut |_, _, _| Ok(()),
            )
            .unwrap()
        })
    });
    group.bench_function("free_flight_1s_110_cycles_without_events", |b| {
        b.iter(|| {
            FlightSystem::new(&model, Inputs::default())
                .without_events()
                .integrate(
                    (
                        options.method,
                        options.rtol,
                        options.atol,
                        options.max_steps,
                    ),
                    t0,
                    &y0,
                    t1,
                    &[],
                    &mut |_, _, _| Ok(()),
                )
                .unwrap()
        })
    });
    // The same second at DOPRI5, rtol 1e-6.
    let loose = SimulationOptions {
        method: paritysim_dynamics::integrate::Method::Dopri5,
        rtol: 1e-6,
        atol: 1e-8,
        ..options.clone()
    };
    group.bench_function("free_flight_1s_dopri5_rtol1e-6", |b| {
        b.iter(|| {
            integrate_flight(
                &model,
                &loose,
                &Inputs::default(),
                t0,
                &y0,
                t1,
                &[],
                &mut |_, _, _| Ok(()),
            )
            .unwrap()
        })
    });
    let rk = RungeKutta::new(
        options.method,
        options.rtol,
        options.atol,
        options.max_steps,
    )
    .unwrap()
    .with_work(false);
    group.bench_function("fixed_body_110_cycles", |b| {
        b.iter(|| rk.advance(&device, t0, &steady.steady_state, t1).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
