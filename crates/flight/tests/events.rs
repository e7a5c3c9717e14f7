//! Event location in flight (issue 17 performance): stopping each step at the stroke reversals
//! (and the other roots of the blade-element model's switching functions) changes the
//! solution only within the tolerances, makes it more accurate at the default tolerances and
//! needs far fewer right-hand-side calls than stepping across the model's jumps.

mod common;

use common::*;
use nalgebra::UnitQuaternion;
use paritysim_dynamics::integrate::{IntegrationStats, Method};
use paritysim_dynamics::{SimulationOptions, simulate};
use paritysim_flight::model::{Inputs, STATE_LEN};
use paritysim_flight::run::released;
use paritysim_flight::{BodyMode, FlightModel, FlightSystem};

type Samples = Vec<(UnitQuaternion<f64>, paritysim_constraints::Vec6)>;

#[test]
fn event_location_agrees_with_straddling_steps_and_is_cheaper() {
    let device = common::device_3_4(
        wing_3_4(false, 1.0, 2.533928021702924),
        wing_3_4(true, 1.0, 2.533928021702924),
        0.0,
    );
    let options = SimulationOptions::default();
    let steady = simulate(&device, &options).unwrap();
    let model = FlightModel::new(&device, hmf_body(BodyMode::Free), Vec::new()).unwrap();
    let y0 = released(&model, &model.convert_state(&steady.steady_state).unwrap());
    let period = device.period().unwrap();
    let t0 = steady.cycles_run as f64 * period;
    let cycles = 3.0;
    let t1 = t0 + cycles * period;
    let times: Vec<f64> = (0..=48).map(|k| t0 + (t1 - t0) * k as f64 / 48.0).collect();
    let run = |events: bool, rtol: f64| -> (Samples, IntegrationStats) {
        let system = FlightSystem::new(&model, Inputs::default());
        let system = if events {
            system
        } else {
            system.without_events()
        };
        let mut out = Vec::new();
        let (_, stats) = system
            .integrate(
                (Method::Dop853, rtol, rtol * 1e-2, 10_000_000),
                t0,
                &y0,
                t1,
                &times,
                &mut |_, t, y: &[f64; STATE_LEN]| {
                    let e = model.evaluate(t, y, &Inputs::default()).unwrap();
                    out.push((e.attitude, e.p));
                    Ok(())
                },
            )
            .unwrap();
        (out, stats)
    };
    let error = |a: &Samples, b: &Samples| {
        a.iter().zip(b).fold(0.0f64, |m, (x, y)| {
            m.max(x.0.angle_to(&y.0)).max((x.1 - y.1).amax())
        })
    };
    // Two tight references, one with each treatment of the jumps: the same solution.
    let (reference, ref_stats) = run(true, 1e-11);
    let (brute, brute_stats) = run(false, 1e-11);
    let between = error(&reference, &brute);
    // The default tolerances with and without event location.
    let (on, on_stats) = run(true, options.rtol);
    let (off, off_stats) = run(false, options.rtol);
    let (e_on, e_off) = (error(&reference, &on), error(&reference, &off));
    println!(
        "references differ by {between:.1e} rad ({} vs {} rhs); rtol {:e}: error {e_on:.1e} \
         with events ({} rhs, {} rejected, {} events), {e_off:.1e} without ({} rhs, {} \
         rejected)",
        ref_stats.rhs_calls,
        brute_stats.rhs_calls,
        options.rtol,
        on_stats.rhs_calls,
        on_stats.rejected,
        on_stats.events,
        off_stats.rhs_calls,
        off_stats.rejected
    );
    assert!(between < 1e-8, "{between}");
    // Two stroke reversals per wing and wingbeat at least.
    assert!(on_stats.events as f64 >= 4.0 * cycles, "{on_stats:?}");
    assert!(e_on < 1e-6 && e_on < e_off, "{e_on} vs {e_off}");
    assert!(
        2 * on_stats.rhs_calls < off_stats.rhs_calls,
        "{on_stats:?} vs {off_stats:?}"
    );
}

#[test]
fn mirror_symmetric_wings_switch_together() {
    // The symmetric §3.4 device released in free flight: by mirror symmetry the body only
    // pitches, and event location (both wings cross their switching surfaces at the same
    // instants up to round-off) must not change that. (The free body amplifies asymmetries:
    // round-off grows to ~1e-9 rad/ms over 60 wingbeats. With the HMF drivetrain, switching
    // the wings at their separately bracketed roots, up to 1e-10 h apart, gave a 2e-8 rad/ms
    // mean roll rate over 10 wingbeats: tests/test_flight_studies.py; hence the 1e-8 h
    // clustering of roots in the integrator.)
    let device = symmetric_3_4();
    let options = SimulationOptions::default();
    let steady = simulate(&device, &options).unwrap();
    let model = FlightModel::new(&device, hmf_body(BodyMode::Free), Vec::new()).unwrap();
    let y0 = released(&model, &model.convert_state(&steady.steady_state).unwrap());
    let period = device.period().unwrap();
    let t0 = steady.cycles_run as f64 * period;
    let t1 = t0 + 10.0 * period;
    let times: Vec<f64> = (0..=160)
        .map(|k| t0 + (t1 - t0) * k as f64 / 160.0)
        .collect();
    let (mut asymmetric, mut pitch) = (0.0f64, 0.0f64);
    let (_, stats) = FlightSystem::new(&model, Inputs::default())
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
            &times,
            &mut |_, t, y: &[f64; STATE_LEN]| {
                let e = model.evaluate(t, y, &Inputs::default()).unwrap();
                asymmetric = asymmetric.max(e.omega.x.abs()).max(e.omega.y.abs());
                pitch = pitch.max(e.omega.z.abs());
                Ok(())
            },
        )
        .unwrap();
    println!("{stats:?}: |roll|, |yaw| rates <= {asymmetric:.1e}, pitch up to {pitch:.1e} rad/ms");
    assert!(stats.events >= 40, "{stats:?}");
    assert!(pitch > 1e-4, "the body pitches ({pitch})");
    assert!(asymmetric < 1e-12, "{asymmetric}");
}
