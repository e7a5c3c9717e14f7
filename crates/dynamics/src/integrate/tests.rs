//! Closed-form checks of the Dormand–Prince core and a cross-check against
//! `differential-equations` 0.7.0.

use super::*;

/// `ẍ = −ω² x` in slot 0; the actuator-work slot integrates `ẋ²` (so its value is known too).
struct Oscillator(f64);

impl OdeSystem for Oscillator {
    fn rhs(&self, _t: f64, y: &State, dydt: &mut State) -> Result<()> {
        dydt.coords[0] = y.rates[0];
        dydt.rates[0] = -self.0 * self.0 * y.coords[0];
        dydt.work_actuator = y.rates[0] * y.rates[0];
        Ok(())
    }
    fn n_active(&self) -> usize {
        1
    }
}

/// `ẋ = λ x`, `v̇ = μ v` (two decoupled exponentials).
struct Exponential(f64, f64);

impl OdeSystem for Exponential {
    fn rhs(&self, _t: f64, y: &State, dydt: &mut State) -> Result<()> {
        dydt.coords[0] = self.0 * y.coords[0];
        dydt.rates[0] = self.1 * y.rates[0];
        Ok(())
    }
    fn n_active(&self) -> usize {
        1
    }
}

fn start(x: f64, v: f64) -> State {
    let mut y = State::default();
    y.coords[0] = x;
    y.rates[0] = v;
    y
}

/// Largest error at the step ends and at `samples` uniform dense-output times.
fn step_and_dense_errors(
    rk: &RungeKutta,
    system: &dyn OdeSystem,
    y0: &State,
    t_end: f64,
    exact: &dyn Fn(f64) -> [f64; 2],
    samples: usize,
) -> (f64, f64, IntegrationStats) {
    let times: Vec<f64> = (0..samples)
        .map(|k| t_end * (k as f64 + 0.37) / samples as f64)
        .collect();
    let err = |t: f64, y: &State| {
        let e = exact(t);
        (y.coords[0] - e[0]).abs().max((y.rates[0] - e[1]).abs())
    };
    let mut dense: f64 = 0.0;
    let mut step: f64 = 0.0;
    let (_, stats) = rk
        .solve::<4>(
            system,
            2,
            0.0,
            y0,
            t_end,
            None,
            &times,
            &mut |_, t, y| {
                dense = dense.max(err(t, y));
                Ok(())
            },
            &mut |t, y| step = step.max(err(t, y)),
        )
        .unwrap();
    (step, dense, stats)
}

#[test]
fn dense_error_is_the_step_error_on_a_harmonic_oscillator() {
    let w = 2.0;
    let exact = |t: f64| [(w * t).cos(), -w * (w * t).sin()];
    for method in [Method::Dop853, Method::Dopri5] {
        for rtol in [1e-6, 1e-8, 1e-10, 1e-12] {
            let rk = RungeKutta::new(method, rtol, rtol * 1e-2, 100_000).unwrap();
            let (step, dense, _) =
                step_and_dense_errors(&rk, &Oscillator(w), &start(1.0, 0.0), 20.0, &exact, 997);
            assert!(
                step < 1e3 * rtol,
                "{method:?} rtol {rtol}: step error {step:e}"
            );
            // The global error grows along the run; the interpolant adds no error of its own.
            assert!(
                dense <= 3.0 * step + 1e-15,
                "{method:?} rtol {rtol}: dense {dense:e} vs step {step:e}"
            );
        }
    }
}

#[test]
fn dense_error_is_the_step_error_on_exponentials() {
    let (lam, mu) = (-1.3, 0.7);
    let exact = |t: f64| [(lam * t).exp(), 2.0 * (mu * t).exp()];
    for method in [Method::Dop853, Method::Dopri5] {
        for rtol in [1e-6, 1e-7, 1e-8, 1e-9, 1e-12] {
            let rk = RungeKutta::new(method, rtol, 1e-14, 100_000).unwrap();
            let (step, dense, _) = step_and_dense_errors(
                &rk,
                &Exponential(lam, mu),
                &start(1.0, 2.0),
                5.0,
                &exact,
                501,
            );
            assert!(step < 1e3 * rtol * 2.0 * (mu * 5.0f64).exp());
            // Few, long steps: the 8th-order steps are far inside the tolerance, the 7th-order
            // interpolant (CONTD8) a little less so, but both scale alike with rtol.
            assert!(dense <= rtol * 2.0 * (mu * 5.0f64).exp());
            assert!(
                dense <= 30.0 * step + 1e-15,
                "{method:?} rtol {rtol}: dense {dense:e} vs step {step:e}"
            );
        }
    }
}

#[test]
fn dense_stages_only_on_steps_with_samples_and_counts_match_the_scheme() {
    let rk = RungeKutta::new(Method::Dop853, 1e-9, 1e-12, 100_000).unwrap();
    let system = Oscillator(3.0);
    let y0 = start(1.0, 0.0);
    let (_, none) = rk
        .integrate_counted(&system, 0.0, &y0, 10.0, &[], &mut |_, _, _| Ok(()))
        .unwrap();
    assert_eq!(none.dense_steps, 0);
    // f(t0), HINIT, 11 per trial, 1 (FSAL) per accepted step.
    assert_eq!(
        none.rhs_calls,
        2 + 11 * (none.accepted + none.rejected) + none.accepted
    );
    // Samples in the second half only: dense output there only, 3 extra calls each.
    let times: Vec<f64> = (0..50).map(|k| 9.0 + k as f64 * 0.02).collect();
    let (_, some) = rk
        .integrate_counted(&system, 0.0, &y0, 10.0, &times, &mut |_, _, _| Ok(()))
        .unwrap();
    assert_eq!(some.accepted, none.accepted);
    assert!(some.dense_steps > 0 && some.dense_steps < some.accepted / 5);
    assert_eq!(some.rhs_calls, none.rhs_calls + 3 * some.dense_steps);
    // DOPRI5's interpolant costs nothing.
    let rk5 = RungeKutta::new(Method::Dopri5, 1e-9, 1e-12, 100_000).unwrap();
    let (_, five) = rk5
        .integrate_counted(&system, 0.0, &y0, 10.0, &times, &mut |_, _, _| Ok(()))
        .unwrap();
    assert_eq!(five.rhs_calls, 2 + 6 * (five.accepted + five.rejected));
}

#[test]
fn work_integrals_do_not_change_the_steps_and_are_exact() {
    let w = 2.0;
    let system = Oscillator(w);
    let y0 = start(1.0, 0.0);
    let t_end = 7.3;
    let with = RungeKutta::new(Method::Dop853, 1e-10, 1e-12, 100_000).unwrap();
    let without = with.with_work(false);
    let run = |rk: &RungeKutta| {
        rk.integrate_counted(&system, 0.0, &y0, t_end, &[], &mut |_, _, _| Ok(()))
            .unwrap()
    };
    let ((a, sa), (b, sb)) = (run(&with), run(&without));
    assert_eq!(sa.accepted, sb.accepted);
    assert_eq!(sa.rejected, sb.rejected);
    assert_eq!(a.coords, b.coords);
    assert_eq!(a.rates, b.rates);
    assert_eq!(b.work_actuator, 0.0);
    // ∫ ẋ² dt = w²(t/2 − sin(2wt)/(4w)).
    let exact = w * w * (t_end / 2.0 - (2.0 * w * t_end).sin() / (4.0 * w));
    assert!((a.work_actuator - exact).abs() < 1e-8 * exact);
}

#[test]
fn agrees_with_differential_equations_steps_and_values() {
    use differential_equations::prelude::{ExplicitRungeKutta, IVP, ODE};
    struct Plain(f64);
    impl ODE<f64, [f64; 2]> for Plain {
        fn diff(&self, _t: f64, y: &[f64; 2], d: &mut [f64; 2]) {
            d[0] = y[1];
            d[1] = -self.0 * self.0 * y[0];
        }
    }
    let w = 2.0;
    for rtol in [1e-7, 1e-10] {
        let atol = rtol * 1e-2;
        let t_end = 30.0;
        let theirs = IVP::ode(&Plain(w), 0.0, t_end, [1.0, 0.0])
            .method(ExplicitRungeKutta::dop853().rtol(rtol).atol(atol))
            .solve()
            .unwrap();
        let ours_rk = RungeKutta::new(Method::Dop853, rtol, atol, 100_000)
            .unwrap()
            .with_work(false);
        let (ours, stats) = ours_rk
            .integrate_counted(
                &Oscillator(w),
                0.0,
                &start(1.0, 0.0),
                t_end,
                &[],
                &mut |_, _, _| Ok(()),
            )
            .unwrap();
        let (_, y) = theirs.last().unwrap();
        // Same pair, same error norm and tolerances: same accuracy and (up to the
        // controller's clamps, Hairer's 1/3..6 against the crate's 0.2..10) the same steps.
        let exact = [(w * t_end).cos(), -w * (w * t_end).sin()];
        let e_ours = (ours.coords[0] - exact[0]).abs();
        let e_theirs = (y[0] - exact[0]).abs();
        assert!(
            e_ours < 5.0 * e_theirs.max(rtol * 1e-2),
            "{e_ours:e} vs {e_theirs:e}"
        );
        assert!((ours.coords[0] - y[0]).abs() < 100.0 * rtol);
        let (a, b) = (stats.accepted as f64, theirs.steps.accepted as f64);
        assert!((a - b).abs() <= 0.1 * b + 2.0, "accepted {a} vs {b}");
    }
}

#[test]
fn differential_equations_dense_output_is_worse_than_ours() {
    // The finding behind owning the core (docs/findings.md): its DOP853 interpolant is O(h⁵).
    use differential_equations::prelude::{ExplicitRungeKutta, IVP, ODE};
    struct Plain(f64);
    impl ODE<f64, [f64; 2]> for Plain {
        fn diff(&self, _t: f64, y: &[f64; 2], d: &mut [f64; 2]) {
            d[0] = y[1];
            d[1] = -self.0 * self.0 * y[0];
        }
    }
    let w = 2.0;
    let rtol = 1e-8;
    let times: Vec<f64> = (0..997).map(|k| 20.0 * (k as f64 + 0.37) / 997.0).collect();
    let theirs = IVP::ode(&Plain(w), 0.0, 20.0, [1.0, 0.0])
        .t_eval(times.clone())
        .method(ExplicitRungeKutta::dop853().rtol(rtol).atol(rtol * 1e-2))
        .solve()
        .unwrap();
    let their_err = theirs
        .t
        .iter()
        .zip(&theirs.y)
        .map(|(t, y)| (y[0] - (w * t).cos()).abs())
        .fold(0.0, f64::max);
    let rk = RungeKutta::new(Method::Dop853, rtol, rtol * 1e-2, 100_000).unwrap();
    let exact = |t: f64| [(w * t).cos(), -w * (w * t).sin()];
    let (_, ours, _) =
        step_and_dense_errors(&rk, &Oscillator(w), &start(1.0, 0.0), 20.0, &exact, 997);
    assert!(
        their_err > 10.0 * ours,
        "theirs {their_err:e}, ours {ours:e}"
    );
}

#[test]
fn bad_times_and_failures_are_typed_errors() {
    let rk = RungeKutta::new(Method::Dop853, 1e-8, 1e-10, 100).unwrap();
    let y0 = start(1.0, 0.0);
    let none = &mut |_: usize, _: f64, _: &State| Ok(());
    assert!(matches!(
        rk.integrate_with(&Oscillator(1.0), 0.0, &y0, 1.0, &[0.5, 0.2], none),
        Err(Error::InvalidParameter { .. })
    ));
    assert!(matches!(
        rk.integrate_with(&Oscillator(1.0), 0.0, &y0, 1.0, &[1.5], none),
        Err(Error::InvalidParameter { .. })
    ));
    // The step limit.
    assert!(matches!(
        rk.integrate_with(&Oscillator(1.0), 0.0, &y0, 1e4, &[], none),
        Err(Error::Integration { .. })
    ));
    // A model error carries its time.
    struct Fails;
    impl OdeSystem for Fails {
        fn rhs(&self, t: f64, y: &State, d: &mut State) -> Result<()> {
            if t > 0.5 {
                return Err(Error::Singular("boom".into()));
            }
            d.coords[0] = y.rates[0];
            Ok(())
        }
    }
    match rk.integrate_with(&Fails, 0.0, &y0, 1.0, &[], none) {
        Err(Error::Integration { time, reason, .. }) => {
            assert!(time > 0.5 && reason.contains("boom"), "{time} {reason}");
        }
        other => panic!("{other:?}"),
    }
}

/// The oscillator over a very long span needs millions of steps: the budget must stop it.
fn long_run(rk: &RungeKutta) -> (Result<State>, std::time::Duration) {
    let start_time = std::time::Instant::now();
    let out = rk.advance(&Oscillator(1.0), 0.0, &start(1.0, 0.0), 1e9);
    (out, start_time.elapsed())
}

#[test]
fn a_set_cancel_flag_stops_the_integration_at_its_first_check() {
    let rk = RungeKutta::new(Method::Dop853, 1e-10, 1e-12, usize::MAX).unwrap();
    let flag = budget::CancelFlag::new();
    flag.cancel();
    let _guard = budget::Budget::new(None, Some(flag)).enter();
    let (out, _) = long_run(&rk);
    assert_eq!(out.unwrap_err(), Error::Cancelled);
}

#[test]
fn a_cancel_from_another_thread_stops_a_running_integration() {
    let rk = RungeKutta::new(Method::Dop853, 1e-10, 1e-12, usize::MAX).unwrap();
    let flag = budget::CancelFlag::new();
    let remote = flag.clone();
    let canceller = std::thread::spawn(move || {
        std::thread::sleep(std::time::Duration::from_millis(50));
        remote.cancel();
    });
    let _guard = budget::Budget::new(None, Some(flag)).enter();
    let (out, _) = long_run(&rk);
    canceller.join().unwrap();
    assert_eq!(out.unwrap_err(), Error::Cancelled);
}

#[test]
fn the_wall_budget_becomes_an_error_naming_the_option() {
    let rk = RungeKutta::new(Method::Dop853, 1e-10, 1e-12, usize::MAX).unwrap();
    let _guard = budget::Budget::new(Some(20.0), None).enter();
    let (out, _) = long_run(&rk);
    match out.unwrap_err() {
        Error::Integration { reason, time, .. } => {
            assert!(
                reason.contains("options.max_wall_ms") && reason.contains("20 ms"),
                "{reason}"
            );
            // It stopped partway, not at the end.
            assert!(time > 0.0 && time < 1e9, "{time}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_budget_ends_with_its_guard_and_an_inner_one_keeps_the_outer_flag() {
    let rk = RungeKutta::new(Method::Dop853, 1e-8, 1e-10, 100_000).unwrap();
    let flag = budget::CancelFlag::new();
    {
        let _outer = budget::Budget::new(None, Some(flag.clone())).enter();
        let _inner = budget::Budget::new(Some(60_000.0), None).enter();
        flag.cancel();
        assert_eq!(
            rk.advance(&Oscillator(1.0), 0.0, &start(1.0, 0.0), 10.0)
                .unwrap_err(),
            Error::Cancelled
        );
    }
    // Guards dropped: no budget on this thread any more.
    let y = rk
        .advance(&Oscillator(1.0), 0.0, &start(1.0, 0.0), 10.0)
        .unwrap();
    assert!((y.coords[0] - 10f64.cos()).abs() < 1e-6);
}

#[test]
fn the_step_budget_names_the_option() {
    let rk = RungeKutta::new(Method::Dop853, 1e-10, 1e-12, 50).unwrap();
    match long_run(&rk).0.unwrap_err() {
        Error::Integration { reason, .. } => {
            assert!(
                reason.contains("options.max_steps") && reason.contains("50"),
                "{reason}"
            )
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_fixed_grid_retraces_the_adaptive_steps_and_its_dense_output() {
    // On the grid an adaptive run chose, the fixed-step integration takes the same steps (up
    // to the rounding of `h = t_{k+1} − t_k`): same end state and dense samples to round-off;
    // and it is a smooth map of y0 (here linear: no step-sequence jump).
    let w = 1.7;
    let system = Oscillator(w);
    let rk = RungeKutta::new(Method::Dop853, 1e-8, 1e-10, 100_000)
        .unwrap()
        .with_work(false);
    let y0 = start(0.3, -0.8);
    let t_end = 7.3;
    let (adaptive, grid) = rk.advance_with_steps(&system, 0.0, &y0, t_end).unwrap();
    assert_eq!(grid[0], 0.0);
    assert_eq!(*grid.last().unwrap(), t_end);
    assert!(grid.len() > 5);
    let times: Vec<f64> = (0..=50).map(|k| t_end * k as f64 / 50.0).collect();
    let (mut a, mut b) = (Vec::new(), Vec::new());
    let y_adaptive = rk
        .integrate_with(&system, 0.0, &y0, t_end, &times, &mut |_, _, y| {
            a.push(*y);
            Ok(())
        })
        .unwrap();
    let y_grid = rk
        .integrate_on_grid(&system, &grid, &y0, &times, &mut |_, _, y| {
            b.push(*y);
            Ok(())
        })
        .unwrap();
    let close = |p: &State, q: &State| {
        (p.coords[0] - q.coords[0]).abs() < 1e-14 && (p.rates[0] - q.rates[0]).abs() < 1e-14
    };
    assert!(close(&y_grid, &adaptive) && close(&y_grid, &y_adaptive));
    assert_eq!(a.len(), b.len());
    assert!(a.iter().zip(&b).all(|(p, q)| close(p, q)));
    // Linear system: the fixed-grid map is exactly linear up to round-off.
    let scale = 1e-3;
    let y1 = rk
        .integrate_on_grid(
            &system,
            &grid,
            &start(0.3 * scale, -0.8 * scale),
            &[],
            &mut |_, _, _| Ok(()),
        )
        .unwrap();
    assert!((y1.coords[0] - scale * y_grid.coords[0]).abs() < 1e-15);
    assert!((y1.rates[0] - scale * y_grid.rates[0]).abs() < 1e-15);
    // And it integrates the oscillator to the adaptive run's accuracy.
    let exact = 0.3 * (w * t_end).cos() - 0.8 / w * (w * t_end).sin();
    assert!((y_grid.coords[0] - exact).abs() < 1e-7);
}

#[test]
fn a_bad_grid_is_rejected_with_its_index() {
    let rk = RungeKutta::new(Method::Dopri5, 1e-8, 1e-10, 1000).unwrap();
    let y0 = start(1.0, 0.0);
    for (grid, field) in [
        (vec![0.0], "grid"),
        (vec![0.0, 1.0, 1.0], "grid[2]"),
        (vec![0.0, f64::NAN], "grid[1]"),
    ] {
        let e = rk
            .integrate_on_grid(&Oscillator(1.0), &grid, &y0, &[], &mut |_, _, _| Ok(()))
            .unwrap_err();
        assert!(format!("{e}").contains(field), "{e}");
    }
}

/// Dry friction on a harmonic oscillator, `ẍ = −x − μ sgn(ẋ)`: the acceleration jumps by
/// `2μ` at every turning point (`ẋ = 0`). From rest at `x0 > 0` each half swing is a cosine
/// about `±μ` with period 2π: the k-th turning point is at `t = kπ`, `x_k = (−1)^k (x0 − 2kμ)`
/// (until `|x_k| <= μ`, where it sticks).
struct DryFriction {
    mu: f64,
    events: bool,
}

impl DryFriction {
    fn exact(&self, x0: f64, t: f64) -> [f64; 2] {
        let k = (t / std::f64::consts::PI).floor();
        let sign = if k as i64 % 2 == 0 { 1.0 } else { -1.0 };
        let amplitude = x0 - 2.0 * k * self.mu - self.mu;
        let tau = t - k * std::f64::consts::PI;
        // Centre +μ while moving left (k even), −μ while moving right.
        let c = sign * self.mu;
        [
            c + sign * amplitude * tau.cos(),
            -sign * amplitude * tau.sin(),
        ]
    }
}

impl ArraySystem<2> for DryFriction {
    fn rhs(&mut self, _t: f64, y: &[f64; 2], sides: Sides, dydt: &mut [f64; 2]) -> Result<()> {
        let s = if self.events {
            sides.sign(0)
        } else {
            y[1].signum()
        };
        dydt[0] = y[1];
        dydt[1] = -y[0] - self.mu * s;
        Ok(())
    }
    fn n_switches(&self) -> usize {
        usize::from(self.events)
    }
    fn switches(&mut self, _t: f64, y: &[f64; 2], g: &mut [f64; MAX_SWITCHES]) -> Result<()> {
        g[0] = y[1];
        Ok(())
    }
}

#[test]
fn events_locate_the_turning_points_of_dry_friction() {
    let (x0, mu) = (1.0, 0.05);
    let pi = std::f64::consts::PI;
    // Eight half swings, ending mid-swing; samples at the turning points and between them.
    let t_end = 8.5 * pi;
    let times: Vec<f64> = (1..=16).map(|k| k as f64 * 0.5 * pi + 0.1).collect();
    let run = |events: bool, method: Method, rtol: f64| {
        let mut sys = DryFriction { mu, events };
        // Start just after release, on the moving-left branch (ẋ < 0 from rest is a zero g).
        let t0 = 1e-3;
        let y0 = sys.exact(x0, t0);
        let mut err: f64 = 0.0;
        let (y, stats) = integrate_system(
            method,
            rtol,
            rtol * 1e-2,
            1_000_000,
            &mut sys,
            t0,
            &y0,
            t_end,
            &times,
            &mut |_, t, y| {
                let e = DryFriction { mu, events }.exact(x0, t);
                err = err.max((y[0] - e[0]).abs()).max((y[1] - e[1]).abs());
                Ok(())
            },
        )
        .unwrap();
        let e = sys.exact(x0, t_end);
        let end = (y[0] - e[0]).abs().max((y[1] - e[1]).abs());
        (end, err, stats)
    };
    for method in [Method::Dop853, Method::Dopri5] {
        let rtol = 1e-9;
        let (end_on, dense_on, on) = run(true, method, rtol);
        let (end_off, dense_off, off) = run(false, method, rtol);
        println!(
            "{method:?} rtol {rtol:e}: with events error {end_on:.1e} (samples {dense_on:.1e}), \
             {} rhs, {} accepted, {} rejected, {} events; without {end_off:.1e} \
             ({dense_off:.1e}), {} rhs, {} accepted, {} rejected",
            on.rhs_calls,
            on.accepted,
            on.rejected,
            on.events,
            off.rhs_calls,
            off.accepted,
            off.rejected
        );
        // One event per turning point (t = π, 2π, ..., 8π).
        assert_eq!(on.events, 8, "{on:?}");
        // Branch-true steps: the closed form to the tolerance's order, far fewer rejections.
        assert!(end_on < 2e-8 && dense_on < 2e-8, "{end_on} {dense_on}");
        assert!(on.rejected * 4 <= off.rejected, "{on:?} vs {off:?}");
        // DOP853 loses most (a run of rejections at every jump): at least 3x fewer calls.
        let gain = if method == Method::Dop853 { 3 } else { 1 };
        assert!(on.rhs_calls * gain < off.rhs_calls, "{on:?} vs {off:?}");
    }
}

#[test]
fn sides_name_the_branches() {
    let s = Sides::of(&[1.0, -2.0, 0.0]);
    assert!(s.positive(0) && !s.positive(1) && s.positive(2));
    assert_eq!(s.sign(1), -1.0);
    let t = s.with(1, true).with(0, false);
    assert!(!t.positive(0) && t.positive(1));
}
