//! The default steady state (Newton shooting) on the shipped §3.4 devices: mirror symmetry of
//! identical rotating wings, where the differential stroke offset is a neutral direction.

use paritysim_dynamics::{SteadyState, simulate};
use paritysim_spec::from_toml;

fn shipped_device(name: &str) -> String {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    std::fs::read_to_string(root.join("python/paritysim/devices").join(name)).unwrap()
}

fn largest_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn largest(a: &[f64]) -> f64 {
    a.iter().map(|x| x.abs()).fold(0.0, f64::max)
}

#[test]
fn shooting_keeps_identical_rotating_wings_mirror_images() {
    // The §3.4 PARITY with both wings the right one: linear differential with K2 = 0, so any
    // constant differential stroke offset is an orbit too (a Floquet multiplier 1). The
    // mirror-symmetric start must give the mirror-symmetric orbit: with the former SVD cutoff
    // (1e-10 of the largest singular value, which the variational Jacobian's 2e-10 for the
    // neutral direction may or may not clear) Newton moved 8.4e-4 rad along it here at a hinge
    // stiffness of 2.0 mN·mm/rad (7e-4 at 2.5 with the Python trial's options).
    let (mut spec, _) = from_toml(&shipped_device("sreetharan2012_3_4_parity.toml")).unwrap();
    spec.wings[0] = spec.wings[1].clone();
    for hinge in [2.5, 2.0, 3.0] {
        for wing in &mut spec.wings {
            wing.springs.hinge.stiffness = hinge;
        }
        let (device, options) = spec.model().unwrap();
        assert_eq!(options.steady_state, SteadyState::Shooting, "the default");
        let r = simulate(&device, &options).unwrap();
        assert!(r.converged);
        // Shooting found the orbit itself (no transient fallback), and it has the neutral mode.
        assert!(
            r.monodromy.is_some(),
            "the shooting's orbit, not the fallback's"
        );
        let neutral = r.multipliers.iter().any(|m| (m - 1.0).norm() < 1e-6);
        assert!(neutral, "a multiplier 1: {:?}", r.multipliers);
        let col = |name: &str| r.trajectory.column(name).unwrap();
        for angle in ["phi", "psi", "phi_dot", "psi_dot"] {
            let (left, right) = (
                col(&format!("left_{angle}")),
                col(&format!("right_{angle}")),
            );
            let d = largest_difference(left, right);
            assert!(
                d < 1e-9 * largest(right).max(1.0),
                "hinge {hinge}, {angle}: {d:e}"
            );
        }
        let scale = largest(col("right_roll_aero"));
        for net in ["roll_total", "yaw_total"] {
            let v = largest(col(net));
            assert!(
                v < 1e-7 * scale,
                "hinge {hinge}, {net}: {v:e} vs scale {scale}"
            );
        }
    }
}

#[test]
fn lift_parity_settles_on_a_period_doubled_orbit_that_shooting_finds() {
    use paritysim_dynamics::{Integrator, Method, integrate::RungeKutta};
    // The §2.5 Lift PARITY on the 1-Cut wings: its period-1 orbit has lost stability through a
    // flip (a multiplier below −1), and the run settles on an orbit that repeats every second
    // wingbeat. The transient's one-cycle change never falls below steady_tol (it used to run
    // all 200 cycles and report converged = false); its two-cycle change does. (Newton on the
    // two-cycle frozen-grid map stalls near 2e-7 here: the blade element's switch at stroke
    // reversal inside a fixed step makes that map non-smooth, so the transient finishes.)
    let (spec, _) = from_toml(&shipped_device("sreetharan2012_2_5_lift_parity_1cut.toml")).unwrap();
    let (device, options) = spec.model().unwrap();
    let shot = simulate(&device, &options).unwrap();
    assert!(shot.converged && shot.orbit_cycles == 2, "{shot:?}");
    assert!(shot.residual <= options.steady_tol, "{}", shot.residual);
    assert!(shot.cycles_run < 100, "{}", shot.cycles_run);
    if let Some(largest) = shot.multipliers.first() {
        assert!(
            largest.norm() < 1.0,
            "the two-cycle map's multipliers {largest}"
        );
    }
    // Independently, at a 1000× tighter tolerance: two wingbeats return to the state, one does not.
    let n = device.n_dof();
    let rk = RungeKutta::new(Method::Dop853, 1e-11, 1e-13, 1_000_000).unwrap();
    let (t, y0) = (shot.period_ms, shot.steady_state.without_work());
    let y1 = rk.advance(&device, 0.0, &y0, t).unwrap();
    let y2 = rk.advance(&device, t, &y1, 2.0 * t).unwrap();
    let size = largest(y0.compact(n).as_slice());
    let one = largest_difference(y1.compact(n).as_slice(), y0.compact(n).as_slice()) / size;
    let two = largest_difference(y2.compact(n).as_slice(), y0.compact(n).as_slice()) / size;
    assert!(one > 1e-2, "one wingbeat changes the state: {one:e}");
    assert!(two < 1e-6, "two wingbeats return to it: {two:e}");
    // The window spans the whole orbit: two cycles of samples.
    let samples = r_len(&shot);
    assert_eq!(samples, 2 * options.samples_per_cycle + 1);
    // The plain transient at a 100× tighter tolerance settles on the same orbit, and the
    // metrics over the whole orbit agree.
    let transient = simulate(
        &device,
        &paritysim_dynamics::SimulationOptions {
            steady_state: SteadyState::Transient,
            rtol: 1e-10,
            atol: 1e-12,
            ..options.clone()
        },
    )
    .unwrap();
    assert!(transient.converged && transient.orbit_cycles == 2);
    for ((name, a), (_, b)) in shot.metrics.iter().zip(&transient.metrics) {
        if a.is_finite() {
            assert!(
                (a - b).abs() <= 1e-4 * (1.0 + a.abs()),
                "{name}: {a} vs {b}"
            );
        }
    }
}

fn r_len(r: &paritysim_dynamics::SimulationResult) -> usize {
    r.trajectory.time.len()
}
