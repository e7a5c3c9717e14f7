//! One second of free flight (the bench's §3.4 device, 110 wingbeats), integrated once at
//! `method:rtol:atol[:off]` (as `flight_accuracy`; default the options' defaults with event
//! location), or with `fixed` the fixed-body engine on the same window and options, or with
//! `clamped` the flight model on a clamped body (the torque stand's physics through the
//! flight equations: what event location does for a fixed-body trial): for instruction
//! counts, e.g.
//!
//! `valgrind --tool=callgrind target/release/examples/flight_once 8:1e-8:1e-10`
#![allow(missing_docs)]

#[path = "../tests/common.rs"]
mod common;

use paritysim_dynamics::integrate::Method;
use paritysim_dynamics::{SimulationOptions, simulate};
use paritysim_flight::model::Inputs;
use paritysim_flight::run::released;
use paritysim_flight::{BodyMode, FlightModel, FlightSystem};

fn main() {
    let device = common::device_3_4(
        common::wing_3_4(false, 1.0, 2.533928021702924),
        common::wing_3_4(true, 1.0, 2.533928021702924),
        0.0,
    );
    let options = SimulationOptions::default();
    let steady = simulate(&device, &options).unwrap();
    let mode = if std::env::args().nth(2).as_deref() == Some("clamped") {
        BodyMode::Clamped
    } else {
        BodyMode::Free
    };
    let model = FlightModel::new(&device, common::hmf_body(mode), Vec::new()).unwrap();
    let y0 = released(&model, &model.convert_state(&steady.steady_state).unwrap());
    let period = device.period().unwrap();
    let t0 = steady.cycles_run as f64 * period;
    let t1 = t0 + 110.0 * period;
    let arg = std::env::args().nth(1).unwrap_or_default();
    let p: Vec<&str> = arg.split(':').collect();
    let method = match p.first() {
        Some(&"5") => Method::Dopri5,
        _ => options.method,
    };
    let rtol = p.get(1).map_or(options.rtol, |v| v.parse().unwrap());
    let atol = p.get(2).map_or(options.atol, |v| v.parse().unwrap());
    let system = FlightSystem::new(&model, Inputs::default());
    let system = if p.get(3) == Some(&"off") {
        system.without_events()
    } else {
        system
    };
    if std::env::args().nth(2).as_deref() == Some("fixed") {
        use paritysim_dynamics::integrate::{RungeKutta, Sink};
        let rk = RungeKutta::new(method, rtol, atol, options.max_steps)
            .unwrap()
            .with_work(false);
        let start = std::time::Instant::now();
        let sink: &mut Sink<'_> = &mut |_, _, _| Ok(());
        let (_, stats) = rk
            .integrate_counted(&device, t0, &steady.steady_state, t1, &[], sink)
            .unwrap();
        println!(
            "fixed body, {method:?} rtol {rtol:e}: {:.1} ms, {stats:?}",
            start.elapsed().as_secs_f64() * 1e3
        );
        return;
    }
    let start = std::time::Instant::now();
    let (_, stats) = system
        .integrate(
            (method, rtol, atol, options.max_steps),
            t0,
            &y0,
            t1,
            &[],
            &mut |_, _, _| Ok(()),
        )
        .unwrap();
    println!(
        "{method:?} rtol {rtol:e}: {:.1} ms, {stats:?}",
        start.elapsed().as_secs_f64() * 1e3
    );
}
