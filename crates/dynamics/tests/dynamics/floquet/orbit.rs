//! The full nonlinear model's periodic orbit: shooting against long simulation, multipliers
//! against independent differences of the map and kicked simulations, Liouville, budgets.

use super::*;

// ------------------------------------------------------------------ full nonlinear model

#[test]
fn shooting_converges_to_the_orbit_of_long_simulation() {
    // A cut left wing (Table 3.2's Ω ratio 0.599) makes the orbit asymmetric (q2 ≠ 0).
    let device = section_3_3_at(0.599 * 31.3, 500.0, 70.0);
    let f = floquet(&device, &options()).unwrap();
    assert_eq!(f.orbit.method, OrbitMethod::Newton);
    assert!(
        f.orbit.state.coords[1].abs() > 1e-3,
        "asymmetric: q2 = {}",
        f.orbit.state.coords[1]
    );
    let long = simulate(
        &device,
        &SimulationOptions {
            rtol: 1e-12,
            atol: 1e-14,
            min_cycles: 5,
            max_cycles: 2000,
            steady_tol: 1e-11,
            samples_per_cycle: 8,
            // The reference is a long run from rest, independent of the shooting under test.
            steady_state: SteadyState::Transient,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(long.converged, "{}", long.cycles_run);
    // The slowest mode (|ρ| ≈ 0.57) needs tens of cycles to settle from rest.
    assert!(long.cycles_run > 20, "{}", long.cycles_run);
    let tr = &long.trajectory;
    for (name, slot) in [("q1", 0), ("q2", 1), ("q1_dot", 6), ("q2_dot", 7)] {
        let diff = (tr.column(name).unwrap()[0] - f.orbit.state.to_vec()[slot]).abs();
        assert!(diff < 1e-8, "{name}: {diff:e}");
    }
    assert_eq!(f.stability(), OrbitStability::Asymptotic);
    let decay = f.slowest_decay_ms().unwrap();
    let rho = f.spectral_radius();
    assert!((decay - f.orbit.period / -rho.ln()).abs() < 1e-12);
}

#[test]
fn multipliers_match_independent_differences_of_the_stroboscopic_map() {
    // Forward differences with another step, through the public map, give the same spectrum.
    for device in [
        section_3_3_at(0.599 * 31.3, 500.0, 70.0),
        section_3_3(31.3, 1.0),
    ] {
        let opts = options();
        let f = floquet(&device, &opts).unwrap();
        let rk = RungeKutta::new(opts.method, opts.rtol, opts.atol, opts.max_steps).unwrap();
        let y = f.orbit.state;
        let p0 = stroboscopic_map(&device, &rk, 0.0, f.orbit.period, &y).unwrap();
        let slots = [0, 1, 6, 7];
        let mut jac = DMatrix::zeros(4, 4);
        for (j, &sj) in slots.iter().enumerate() {
            let h = 3e-6 * (1.0 + y.to_vec()[sj].abs());
            let mut yp = y;
            *slot(&mut yp, sj) += h;
            let p = stroboscopic_map(&device, &rk, 0.0, f.orbit.period, &yp).unwrap();
            for (i, &si) in slots.iter().enumerate() {
                jac[(i, j)] = (p.to_vec()[si] - p0.to_vec()[si]) / h;
            }
        }
        let independent = eigenvalues(&jac).unwrap();
        // The built-in error estimate (steps h and 4h; dominated by the 4h truncation error)
        // is small.
        assert!(
            f.monodromy_uncertainty < 1e-4,
            "{}",
            f.monodromy_uncertainty
        );
        for (a, b) in f.multipliers.iter().zip(&independent) {
            assert!((a - b).norm() < 1e-4 * (1.0 + a.norm()), "{a} vs {b}");
        }
    }
}

#[test]
fn whippletree_mode_is_unstable_at_small_k2_and_its_growth_matches_a_kicked_simulation() {
    // docs/findings.md item 3: with the rod-crank linkage the whippletree mode of the §3.3
    // device grows for K2 = 1 and decays for K2 = 500. The dominant multiplier must equal the
    // cycle-to-cycle growth of a small q̇2 kick in `simulate` (an independent code path).
    let unstable = floquet(&section_3_3(31.3, 1.0), &options()).unwrap();
    let stable = floquet(&section_3_3(31.3, 500.0), &options()).unwrap();
    assert_eq!(unstable.stability(), OrbitStability::Unstable);
    assert_eq!(stable.stability(), OrbitStability::Asymptotic);
    let w = unstable.whippletree.unwrap();
    assert!(
        (w[0].norm() - unstable.spectral_radius()).abs() < 1e-9,
        "the whippletree mode grows"
    );
    assert!(unstable.growth_time_ms().unwrap() > 0.0);
    let spc = 64;
    let r = simulate(
        &section_3_3(31.3, 1.0),
        &SimulationOptions {
            rtol: 1e-12,
            atol: 1e-14,
            samples_per_cycle: spc,
            record_cycles: 6,
            perturbation: Some(Perturbation {
                target: PerturbTarget::WhippletreeRate,
                delta: 1e-7,
                phase: 0.0,
            }),
            ..Default::default()
        },
    )
    .unwrap();
    let q2 = r.trajectory.column("q2").unwrap();
    let q2d = r.trajectory.column("q2_dot").unwrap();
    let norm = |k: usize| q2[k * spc].hypot(q2d[k * spc]);
    let growth = (norm(6) / norm(4)).sqrt();
    assert!(
        (growth / unstable.spectral_radius() - 1.0).abs() < 1e-3,
        "{growth} vs {}",
        unstable.spectral_radius()
    );
}

#[test]
fn linear_map_with_k2_zero_has_a_unit_multiplier() {
    // §2.6.3, κ = 0: without a balance spring q2 is cyclic for eq. 2.15; the whippletree
    // multipliers are 1 and e^{−4β0} per drive period (eq. 2.50 over two periods). The orbit
    // family makes P − I singular: Newton's least-squares step must cope.
    let device = eq_2_16_device(linear_map(), 0.0);
    let f = floquet(&device, &options()).unwrap();
    let lin = linearise(&device, &f.orbit, 2000).unwrap();
    let [r1, r2] = f.whippletree.unwrap();
    assert!((r1 - 1.0).norm() < 1e-6, "{r1}");
    let want = (-4.0 * lin.hill.beta0).exp();
    assert!(
        (r2.re / want - 1.0).abs() < 1e-3 && r2.im == 0.0,
        "{r2} vs {want}"
    );
    assert_eq!(f.stability(), OrbitStability::Marginal);
    assert!(f.slowest_decay_ms().is_some());
}

#[test]
fn hmf_is_asymptotically_stable_and_transmits_roll_rigidly() {
    let wing = || fixed_wing(WingAero::stroke_drag(31.3, 3.4609).unwrap());
    let hmf = two_wing_device(
        [wing(), wing()],
        "hmf_fixed",
        hmf_drivetrain(),
        0.0,
        Actuator::thesis(Waveform::sine(100.0, 110.0, 0.0, 0.0).unwrap()),
        Formulation::Auto,
    );
    let f = floquet(&hmf, &options()).unwrap();
    assert_eq!(f.multipliers.len(), 2);
    assert!(f.whippletree.is_none());
    assert_eq!(f.coordinates, ["q1", "q1_dot"]);
    assert_eq!(f.stability(), OrbitStability::Asymptotic);
    // One rigid drivetrain: a roll torque on the wings reaches the body unattenuated.
    let r =
        disturbance_response(&hmf, &f.orbit, 300.0, 0.5, &DisturbanceOptions::default()).unwrap();
    assert!((r.transfer - 1.0).norm() < 1e-6, "{}", r.transfer);
    assert_eq!(
        linearise(&hmf, &f.orbit, 100).unwrap_err().kind(),
        "Constraint"
    );
}

#[test]
fn k2_sweep_is_parallel_and_equals_single_runs() {
    let spec = section_3_3(31.3, 1.0).spec().clone();
    let k2 = [1.0, 100.0, 500.0];
    let sweep = balance_spring_sweep(&spec, &k2, &options()).unwrap();
    let sweep: Vec<_> = sweep.into_iter().map(Result::unwrap).collect();
    for (k, f) in k2.iter().zip(&sweep) {
        let single = floquet(&section_3_3(31.3, *k), &options()).unwrap();
        assert_eq!(f.multipliers, single.multipliers);
    }
    let rho: Vec<f64> = sweep.iter().map(|f| f.spectral_radius()).collect();
    assert!(rho[0] > rho[1] && rho[1] > rho[2], "{rho:?}");
}

#[test]
fn a_failing_k2_is_a_row_with_its_error_and_the_others_are_kept() {
    // Formerly the first error stopped the whole sweep.
    let spec = section_3_3(31.3, 1.0).spec().clone();
    let rows = balance_spring_sweep(&spec, &[-1.0, 100.0, f64::NAN], &options()).unwrap();
    assert_eq!(rows.len(), 3);
    for (i, row) in [(0, &rows[0]), (2, &rows[2])] {
        let err = row.as_ref().unwrap_err();
        assert_eq!(err.field(), Some(format!("k2[{i}]").as_str()), "{err}");
    }
    let single = floquet(&section_3_3(31.3, 100.0), &options()).unwrap();
    assert_eq!(rows[1].as_ref().unwrap().multipliers, single.multipliers);
}

#[test]
fn floquet_errors_are_typed() {
    let free = Device::new(DeviceSpec {
        wings: vec![fixed_wing(drag(31.3))],
        constraints: Constraints::none(3).unwrap(),
        transmission: None,
        actuator: None,
        formulation: Formulation::Auto,
    })
    .unwrap();
    assert_eq!(floquet(&free, &options()).unwrap_err().kind(), "Constraint");
    let device = section_3_3(31.3, 500.0);
    let bad = ShootingOptions {
        t0: 1e3,
        ..options()
    };
    assert_eq!(floquet(&device, &bad).unwrap_err().field(), Some("t0"));
    let bad = ShootingOptions {
        fd_step: 0.0,
        ..options()
    };
    assert_eq!(floquet(&device, &bad).unwrap_err().field(), Some("fd_step"));
    // Newton disabled and no simulated cycles: no orbit, reported with the state.
    let none = ShootingOptions {
        max_newton: 0,
        warmup_cycles: 0,
        fallback_cycles: 0,
        ..options()
    };
    match periodic_orbit(&device, &none).unwrap_err() {
        paritysim_dynamics::Error::Integration { state, reason, .. } => {
            assert_eq!(state.len(), 14);
            assert!(reason.contains("no periodic orbit"), "{reason}");
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(
        RollDisturbance::new(&free, 1.0, 300.0)
            .err()
            .unwrap()
            .kind(),
        "Constraint"
    );
    assert_eq!(
        RollDisturbance::new(&device, 1.0, 0.0)
            .err()
            .unwrap()
            .field(),
        Some("frequency_hz")
    );
}

#[test]
fn shooting_finds_an_unstable_asymmetric_orbit_that_simulation_cannot_reach() {
    // A cut wing at K2 = 1: the orbit is asymmetric (q2 ≠ 0) and its whippletree mode grows, so
    // simulating from rest runs out of the linkage's reach, while Newton converges to it.
    let device = section_3_3_at(0.599 * 31.3, 1.0, 70.0);
    let f = floquet(&device, &options()).unwrap();
    assert_eq!(f.orbit.method, OrbitMethod::Newton);
    assert!(f.orbit.residual <= options().tol);
    assert!(
        f.orbit.state.coords[1].abs() > 1e-3,
        "asymmetric: q2 = {}",
        f.orbit.state.coords[1]
    );
    assert_eq!(f.stability(), OrbitStability::Unstable);
    let rk = RungeKutta::new(Method::Dop853, 1e-12, 1e-14, 1_000_000).unwrap();
    let p = stroboscopic_map(&device, &rk, 0.0, f.orbit.period, &f.orbit.state).unwrap();
    for i in [0, 1, 6, 7] {
        assert!(
            (p.to_vec()[i] - f.orbit.state.to_vec()[i]).abs() < 1e-9,
            "periodic in slot {i}"
        );
    }
    let long = simulate(
        &device,
        &SimulationOptions {
            max_cycles: 300,
            ..Default::default()
        },
    );
    assert!(
        matches!(long, Err(paritysim_dynamics::Error::Integration { .. })),
        "{:?}",
        long.map(|r| r.converged)
    );
}

#[test]
fn undamped_and_unsprung_lines_are_marginal_within_the_multiplier_error() {
    // β0 = 0: ẍ + κx = 0, multipliers e^{±iπ√κ} on the unit circle; the computed det M is
    // 1 + O(1e-16), which without a tolerance lands in Region II for about half the points.
    for j in 0..51 {
        let k = 0.05 + 3.95 * j as f64 / 50.0;
        let f = hill_floquet(0.0, k).unwrap();
        assert!(
            f.is_marginal(),
            "beta0 = 0, kappa = {k}: {:?}",
            f.multipliers
        );
        // √(round-off) near the double roots ρ = ±1 at κ = n², round-off elsewhere
        let bound = if (k.sqrt() - k.sqrt().round()).abs() < 0.05 {
            1e-6
        } else {
            1e-12
        };
        assert!(f.multiplier_error < bound, "{k}: {}", f.multiplier_error);
    }
    // κ = 0 (eq. 2.50): a multiplier exactly 1 for any damping.
    for b0 in [0.3, 1.0, 2.5] {
        assert!(hill_floquet(b0, 0.0).unwrap().is_marginal(), "{b0}");
    }
    // Away from |ρ| = 1 the error estimate is far below the distance to the unit circle.
    for (b0, k) in [
        (0.5, 1.0),
        (1.0, 0.05),
        (-0.2, 1.0),
        (0.1, 1.0),
        (2.0, 10.0),
    ] {
        let f = hill_floquet(b0, k).unwrap();
        assert!(!f.is_marginal(), "{b0} {k}: {}", f.spectral_radius());
        assert!(f.multiplier_error < 1e-3 * (f.spectral_radius() - 1.0).abs());
    }
    let chart = stability_chart(&[0.0, 0.5], &[0.5, 2.0]).unwrap();
    assert_eq!(chart.marginal, vec![true, true, false, false]);
}

// ------------------------------------------------------------------ issue 12: stability leftovers

#[test]
fn a_failing_chart_point_is_a_marked_entry_and_the_others_are_kept() {
    // κ = −1e6 passes the axis checks but its solution grows like e^{1000π}: overflow. The
    // chart formerly failed as a whole on it.
    assert_eq!(hill_floquet(0.5, -1e6).unwrap_err().kind(), "OutOfDomain");
    let beta0 = [0.5, 2.0];
    let kappa = [1.0, -1e6, 0.2];
    let chart = stability_chart(&beta0, &kappa).unwrap();
    assert_eq!(chart.a.len(), 6);
    let failed: Vec<usize> = chart.errors.iter().map(|(i, _)| *i).collect();
    assert_eq!(failed, [1, 4]);
    for (idx, err) in &chart.errors {
        assert_eq!(err.kind(), "OutOfDomain", "{err}");
        assert!(
            err.to_string().contains(&format!("at index {idx}:")),
            "{err}"
        );
    }
    let numbers = chart.region_numbers();
    let stable = chart.stable();
    for (i, &b0) in beta0.iter().enumerate() {
        for (j, &k) in kappa.iter().enumerate() {
            let idx = i * kappa.len() + j;
            assert_eq!((chart.beta0[idx], chart.kappa[idx]), (b0, k));
            if j == 1 {
                assert_eq!(chart.region[idx], None);
                assert_eq!(numbers[idx], 0);
                assert!(!stable[idx] && !chart.marginal[idx]);
                assert!(chart.a[idx].is_nan() && chart.spectral_radius[idx].is_nan());
                continue;
            }
            let f = hill_floquet(b0, k).unwrap();
            assert_eq!(chart.a[idx], f.a);
            assert_eq!(chart.b[idx], f.b);
            assert_eq!(chart.region[idx], Some(f.region));
            assert_eq!(numbers[idx], i64::from(f.region.index()));
        }
    }
}

#[test]
fn multipliers_and_orbit_do_not_depend_on_the_section_time() {
    // The monodromies at sections t0 and t1 are similar (M1 = Φ(t1, t0) M0 Φ(t1, t0)⁻¹): same
    // eigenvalues. The orbit found on section t0 is the t = 0 orbit carried to t0 by the flow.
    for device in [
        section_3_3_at(0.599 * 31.3, 500.0, 70.0),
        section_3_3(31.3, 1.0),
    ] {
        let at_zero = floquet(&device, &options()).unwrap();
        let period = at_zero.orbit.period;
        let rk = RungeKutta::new(Method::Dop853, 1e-12, 1e-14, 1_000_000).unwrap();
        for fraction in [0.3, 0.71] {
            let t0 = fraction * period;
            let f = floquet(&device, &ShootingOptions { t0, ..options() }).unwrap();
            assert_eq!(f.orbit.method, OrbitMethod::Newton);
            assert_eq!(f.orbit.t0, t0);
            assert!(f.orbit.residual <= options().tol);
            for (a, b) in f.multipliers.iter().zip(&at_zero.multipliers) {
                assert!(
                    (a - b).norm() < 1e-8 * (1.0 + b.norm()),
                    "t0 {t0}: {a} vs {b}"
                );
            }
            let carried = rk
                .integrate(&device, 0.0, &at_zero.orbit.state, t0, &[t0])
                .unwrap()[0];
            for s in [0, 1, 6, 7] {
                let (x, y) = (carried.to_vec()[s], f.orbit.state.to_vec()[s]);
                assert!(
                    (x - y).abs() < 1e-8 * (1.0 + y.abs()),
                    "t0 {t0} slot {s}: {x} vs {y}"
                );
            }
        }
    }
}

/// `∫₀ᵀ tr ∂f/∂y dt` along the orbit: for `[q, q̇]` the trace is `Σ ∂q̈ᵢ/∂q̇ᵢ` (central
/// differences of the right-hand side), integrated by the trapezoidal rule on `samples`.
fn integrated_trace(device: &Device, orbit: &PeriodicOrbit, samples: usize) -> f64 {
    let rk = RungeKutta::new(Method::Dop853, 1e-12, 1e-14, 1_000_000).unwrap();
    let (t0, period) = (orbit.t0, orbit.period);
    let times: Vec<f64> = (0..=samples)
        .map(|j| t0 + period * j as f64 / samples as f64)
        .collect();
    let states = rk
        .integrate(device, t0, &orbit.state, t0 + period, &times)
        .unwrap();
    let trace = |t: f64, y: &State| -> f64 {
        (0..device.n_dof())
            .map(|i| {
                let h = 1e-6 * (1.0 + y.rates[i].abs());
                let (mut plus, mut minus) = (*y, *y);
                plus.rates[i] += h;
                minus.rates[i] -= h;
                let (mut fp, mut fm) = (State::default(), State::default());
                device.rhs(t, &plus, &mut fp).unwrap();
                device.rhs(t, &minus, &mut fm).unwrap();
                (fp.rates[i] - fm.rates[i]) / (2.0 * h)
            })
            .sum()
    };
    let values: Vec<f64> = times
        .iter()
        .zip(&states)
        .map(|(t, y)| trace(*t, y))
        .collect();
    let h = period / samples as f64;
    h * (values.iter().sum::<f64>() - 0.5 * (values[0] + values[samples]))
}

#[test]
fn monodromy_determinant_obeys_liouville() {
    // Liouville: det Φ(T) = exp(∫ tr J dt) for any ODE. The monodromy comes from the
    // variational equations on the frozen grid; the trace integral from the right-hand side
    // alone (two independent formulations). Linear map and nonlinear linkage (symmetric
    // orbits, measured agreement 2e-10 and 1e-9 relative in ln det), and a cut-wing orbit whose
    // det ≈ e^{−28} is the product of multipliers down to 1e-9, known to the monodromy's
    // absolute accuracy only (measured 8e-7).
    for (device, tol) in [
        (eq_2_16_device(linear_map(), 200.0), 1e-8),
        (
            eq_2_16_device(
                Drivetrain::LinkageDifferential(LinkageDifferential::thesis()),
                200.0,
            ),
            1e-8,
        ),
        (section_3_3_at(0.599 * 31.3, 100.0, 70.0), 1e-5),
    ] {
        let f = floquet(&device, &options()).unwrap();
        let ln_det = f.monodromy.determinant().ln();
        let want = integrated_trace(&device, &f.orbit, 40_000);
        assert!(
            (ln_det - want).abs() < tol * want.abs(),
            "ln det M = {ln_det} vs ∫ tr J = {want}"
        );
    }
}

/// A driven damped oscillator `ẍ + c ẋ + k x = cos(2π t / T)` that records the threads it is
/// evaluated on.
struct Recording {
    c: f64,
    k: f64,
    period: f64,
    threads: std::sync::Mutex<std::collections::BTreeSet<String>>,
}

impl OdeSystem for Recording {
    fn rhs(&self, t: f64, y: &State, dydt: &mut State) -> paritysim_dynamics::Result<()> {
        let name = std::thread::current()
            .name()
            .unwrap_or("<unnamed>")
            .to_string();
        self.threads.lock().unwrap().insert(name);
        *dydt = State::default();
        dydt.coords[0] = y.rates[0];
        dydt.rates[0] =
            (2.0 * PI * t / self.period).cos() - self.c * y.rates[0] - self.k * y.coords[0];
        Ok(())
    }
    fn n_active(&self) -> usize {
        1
    }
}

#[test]
fn map_jacobian_runs_on_the_sweep_engine_pool_and_equals_the_closed_form() {
    // Formerly the columns ran on rayon's global pool (unnamed threads) from a plain call.
    let system = Recording {
        c: 0.3,
        k: 2.0,
        period: 2.0,
        threads: Default::default(),
    };
    let rk = RungeKutta::new(Method::Dop853, 1e-12, 1e-14, 1_000_000).unwrap();
    let mut y = State::default();
    y.coords[0] = 0.2;
    let jac = map_jacobian(&system, 1, &rk, 0.0, system.period, &y, 1e-5).unwrap();
    // Linear: the map's Jacobian is exp(A T), A = [[0, 1], [−k, −c]]:
    // e^{−cT/2} [cos(ωd T) I + sin(ωd T)/ωd (A + c/2 I)], ωd = √(k − c²/4).
    let (c, k, t) = (system.c, system.k, system.period);
    let wd = (k - 0.25 * c * c).sqrt();
    let (cs, sn) = ((wd * t).cos(), (wd * t).sin() / wd);
    let e = (-0.5 * c * t).exp();
    let want = [
        [e * (cs + sn * 0.5 * c), e * sn],
        [-e * sn * k, e * (cs - sn * 0.5 * c)],
    ];
    for (i, row) in want.iter().enumerate() {
        for (j, w) in row.iter().enumerate() {
            assert!(
                (jac[(i, j)] - w).abs() < 1e-8,
                "({i}, {j}): {} vs {w}",
                jac[(i, j)]
            );
        }
    }
    let caller = std::thread::current()
        .name()
        .unwrap_or("<unnamed>")
        .to_string();
    for name in system.threads.lock().unwrap().iter() {
        assert!(
            *name == caller || name.starts_with("paritysim-sweep-"),
            "ran on {name:?}"
        );
    }
}
