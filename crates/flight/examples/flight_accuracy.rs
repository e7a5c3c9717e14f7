//! One second of free flight (the bench's §3.4 device, 110 wingbeats): wall time, step
//! statistics and the error against an rtol 1e-11 DOP853 reference (body attitude as the
//! rotation angle between the two attitudes, wing angles `p`) for integrator settings given
//! as `method:rtol:atol[:off]` (method 8 = DOP853, 5 = DOPRI5; `off`: without event
//! location), comma-separated. The reference uses event location; a second argument `check`
//! also prints how far an rtol 1e-11 reference without event location is from it.
//!
//! `cargo run --release -p paritysim-flight --example flight_accuracy -- 8:1e-8:1e-10,8:1e-8:1e-10:off`
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
    let model = FlightModel::new(&device, common::hmf_body(BodyMode::Free), Vec::new()).unwrap();
    let y0 = released(&model, &model.convert_state(&steady.steady_state).unwrap());
    let period = device.period().unwrap();
    let t0 = steady.cycles_run as f64 * period;
    let t1 = t0 + 110.0 * period;
    let cases: Vec<(Method, f64, f64, bool)> = std::env::args()
        .nth(1)
        .map(|s| {
            s.split(',')
                .map(|c| {
                    let p: Vec<&str> = c.split(':').collect();
                    let m = if p[0] == "5" {
                        Method::Dopri5
                    } else {
                        Method::Dop853
                    };
                    let events = p.get(3) != Some(&"off");
                    (m, p[1].parse().unwrap(), p[2].parse().unwrap(), events)
                })
                .collect()
        })
        .unwrap_or(vec![(Method::Dop853, 1e-8, 1e-10, true)]);
    let n_samples = 110 * 16;
    let times: Vec<f64> = (0..=n_samples)
        .map(|k| t0 + (t1 - t0) * k as f64 / n_samples as f64)
        .collect();
    let system = |events: bool| {
        let s = FlightSystem::new(&model, Inputs::default());
        if events { s } else { s.without_events() }
    };
    let run = |method, rtol, atol, events: bool, times: &[f64]| {
        let inputs = Inputs::default();
        let mut out = Vec::new();
        system(events)
            .integrate(
                (method, rtol, atol, 10_000_000),
                t0,
                &y0,
                t1,
                times,
                &mut |_, t, y| {
                    let e = model.evaluate(t, y, &inputs).unwrap();
                    out.push((e.attitude, e.p));
                    Ok(())
                },
            )
            .unwrap();
        out
    };
    let errors =
        |reference: &[(nalgebra::UnitQuaternion<f64>, paritysim_constraints::Vec6)],
         got: &[(nalgebra::UnitQuaternion<f64>, paritysim_constraints::Vec6)]| {
            let (mut eb, mut ew) = (0.0f64, 0.0f64);
            for (r, g) in reference.iter().zip(got) {
                eb = eb.max(r.0.angle_to(&g.0));
                ew = ew.max((r.1 - g.1).amax());
            }
            let last = reference.len() - 1;
            let eb_end = reference[last].0.angle_to(&got[last].0);
            let ew_end = (reference[last].1 - got[last].1).amax();
            (eb, eb_end, ew, ew_end)
        };
    let reference = run(Method::Dop853, 1e-11, 1e-13, true, &times);
    let last = reference.len() - 1;
    if std::env::args().nth(2).as_deref() == Some("check") {
        let other = run(Method::Dop853, 1e-11, 1e-13, false, &times);
        let (eb, eb_end, ew, ew_end) = errors(&reference, &other);
        println!(
            "references (rtol 1e-11) with and without event location differ by: attitude \
             {eb:.1e}, {eb_end:.1e} rad; wing angles {ew:.1e}, {ew_end:.1e} rad"
        );
    }
    for (method, rtol, atol, events) in cases {
        let got = run(method, rtol, atol, events, &times);
        let (eb, eb_end, ew, ew_end) = errors(&reference, &got);
        let turned = reference[last].0.angle();
        let report = format!(
            "error (max over the second, at its end): attitude {eb:.1e}, {eb_end:.1e} rad \
             (the body turned {turned:.2} rad); wing angles {ew:.1e}, {ew_end:.1e} rad"
        );
        let start = std::time::Instant::now();
        let (_, stats) = system(events)
            .integrate(
                (method, rtol, atol, 10_000_000),
                t0,
                &y0,
                t1,
                &[],
                &mut |_, _, _| Ok(()),
            )
            .unwrap();
        let ms = start.elapsed().as_secs_f64() * 1e3;
        println!(
            "{method:?} rtol {rtol:e} atol {atol:e} events {}: {ms:.1} ms, accepted {} \
             rejected {} ({:.1} %), events {}, rhs {}",
            if events { "on" } else { "off" },
            stats.accepted,
            stats.rejected,
            100.0 * stats.rejected as f64 / (stats.accepted + stats.rejected) as f64,
            stats.events,
            stats.rhs_calls
        );
        println!("  {report}");
    }
}
