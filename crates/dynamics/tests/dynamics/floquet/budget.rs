//! The stability analyses under a spent wall budget or a cancel: every parallel part stops,
//! on the caller's threads and on the pool's.

use super::*;

/// The caller's budget reaches the pool threads of a parallel analysis (`budget::carry`): with
/// its cancel flag already set, every point stops at its first check. Without the carry the
/// points run on rayon threads that have no budget and the call would succeed.
#[test]
fn a_cancelled_budget_stops_the_parallel_stability_analyses() {
    use paritysim_dynamics::integrate::budget::{Budget, CancelFlag};
    let flag = CancelFlag::new();
    flag.cancel();
    let _budget = Budget::new(None, Some(flag)).enter();
    let axis: Vec<f64> = (0..200).map(|i| 0.01 * f64::from(i)).collect();
    let chart = stability_chart(&axis, &axis);
    assert_eq!(chart.unwrap_err().kind(), "Cancelled");
    let spec = section_3_3(31.3, 1.0).spec().clone();
    let sweep = balance_spring_sweep(&spec, &[1.0, 100.0, 500.0], &options());
    assert_eq!(sweep.unwrap_err().kind(), "Cancelled");
}

/// `budget::cancellable` from another thread: a K2 sweep of 64 points is stopped partway
/// (the flag is set once the first point has started integrating) and returns `Cancelled`,
/// long before the points could finish.
#[test]
fn cancelling_a_k2_sweep_from_another_thread_returns_cancelled() {
    use paritysim_dynamics::integrate::budget::{CancelFlag, cancellable};
    let spec = section_3_3(31.3, 1.0).spec().clone();
    let k2: Vec<f64> = (0..64).map(|i| 1.0 + f64::from(i)).collect();
    let flag = CancelFlag::new();
    let started = std::time::Instant::now();
    let out = std::thread::scope(|scope| {
        let canceller = flag.clone();
        scope.spawn(move || {
            std::thread::sleep(std::time::Duration::from_millis(50));
            canceller.cancel();
        });
        cancellable(&flag, || balance_spring_sweep(&spec, &k2, &options()))
    });
    assert_eq!(out.unwrap_err().kind(), "Cancelled");
    assert!(started.elapsed().as_secs_f64() < 30.0);
}

#[test]
fn a_spent_wall_budget_or_a_cancel_stops_the_parallel_parts_of_an_analysis() {
    use paritysim_dynamics::integrate::budget::{Budget, CancelFlag};
    let device = section_3_3(31.3, 500.0);
    let f = floquet(&device, &options()).unwrap();
    let rk = RungeKutta::new(Method::Dop853, 1e-12, 1e-14, 1_000_000).unwrap();
    let wall = |e: paritysim_dynamics::Error| match e {
        paritysim_dynamics::Error::Integration { reason, .. } => {
            assert!(reason.contains("max_wall_ms"), "{reason}")
        }
        other => panic!("{other:?}"),
    };
    {
        // A deadline 1 ns from now: spent at the parts' first budget check.
        let _budget = Budget::new(Some(1e-6), None).enter();
        let m = map_jacobian(&device, 2, &rk, 0.0, f.orbit.period, &f.orbit.state, 1e-5);
        wall(m.unwrap_err());
        wall(floquet(&device, &options()).unwrap_err());
        let r = disturbance_response(
            &device,
            &f.orbit,
            300.0,
            0.5,
            &DisturbanceOptions::default(),
        );
        wall(r.unwrap_err());
    }
    let flag = CancelFlag::new();
    flag.cancel();
    let _budget = Budget::new(None, Some(flag)).enter();
    let m = map_jacobian(&device, 2, &rk, 0.0, f.orbit.period, &f.orbit.state, 1e-5);
    assert_eq!(m.unwrap_err().kind(), "Cancelled");
    let r = disturbance_response(
        &device,
        &f.orbit,
        300.0,
        0.5,
        &DisturbanceOptions::default(),
    );
    assert_eq!(r.unwrap_err().kind(), "Cancelled");
}
