//! §2.6: the linearised eq. 2.25 (monodromy, closed forms, regions, the chart, Brockett) and
//! docs/errata.md#7 to #10: the physical mapping of the full model onto it.

use super::*;

// ------------------------------------------------------------------ §2.6: eq. 2.25

#[test]
fn det_m_is_exp_minus_two_beta0_on_a_random_grid() {
    // Eq. 2.45 (Liouville, eqs. 2.42-2.44) for any κ and any t0, including negative values.
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    for _ in 0..300 {
        let beta0 = rng.uniform(-2.0, 6.0);
        let kappa = rng.uniform(-2.0, 12.0);
        let t0 = rng.uniform(-4.0, 4.0);
        let m = hill_monodromy(beta0, kappa, t0).unwrap();
        let expected = (-2.0 * beta0).exp();
        // det is a difference of products: its round-off scales with the products' size.
        let scale = expected.max((m[(0, 0)] * m[(1, 1)]).abs() + (m[(0, 1)] * m[(1, 0)]).abs());
        let err = (m.determinant() - expected).abs() / scale;
        assert!(err < 1e-9, "beta0 {beta0} kappa {kappa} t0 {t0}: {err:e}");
    }
}

#[test]
fn kappa_zero_monodromy_is_eq_2_50() {
    for beta0 in [-1.5, -0.3, 0.0, 0.2, 1.0, 2.5, 5.0] {
        let m = hill_monodromy(beta0, 0.0, -FRAC_PI_2).unwrap();
        let m12 = PI * (-beta0).exp() * bessel_i0(beta0);
        let m22 = (-2.0 * beta0).exp();
        assert!((m[(0, 0)] - 1.0).abs() < 1e-12, "{beta0}: {m}");
        assert!(m[(1, 0)].abs() < 1e-12, "{beta0}: {m}");
        assert!(
            (m[(0, 1)] / m12 - 1.0).abs() < 1e-9,
            "{beta0}: {} vs {m12}",
            m[(0, 1)]
        );
        assert!(
            (m[(1, 1)] / m22 - 1.0).abs() < 1e-9,
            "{beta0}: {} vs {m22}",
            m[(1, 1)]
        );
        // Multipliers 1 and e^{-2β0} (below eq. 2.50).
        let f = hill_floquet(beta0, 0.0).unwrap();
        let mut moduli = [f.multipliers[0].re, f.multipliers[1].re];
        moduli.sort_by(f64::total_cmp);
        let mut want = [1.0, m22];
        want.sort_by(f64::total_cmp);
        assert!((moduli[0] - want[0]).abs() < 1e-9 * want[0].max(1.0));
        assert!((moduli[1] - want[1]).abs() < 1e-9 * want[1].max(1.0));
    }
}

#[test]
fn monodromy_matches_an_independent_adaptive_integrator() {
    /// Eq. 2.25 as an `OdeSystem` (x in slot 0, ẋ in slot 6) for DOP853.
    struct Hill(f64, f64);
    impl OdeSystem for Hill {
        fn rhs(&self, t: f64, y: &State, dydt: &mut State) -> paritysim_dynamics::Result<()> {
            *dydt = State::default();
            dydt.coords[0] = y.rates[0];
            dydt.rates[0] = -self.0 * t.cos().abs() * y.rates[0] - self.1 * y.coords[0];
            Ok(())
        }
        fn n_active(&self) -> usize {
            1
        }
    }
    let rk = RungeKutta::new(Method::Dop853, 1e-13, 1e-15, 1_000_000).unwrap();
    let mut rng = Rng(12345);
    for _ in 0..20 {
        let (beta0, kappa, t0) = (
            rng.uniform(-1.0, 3.0),
            rng.uniform(-1.0, 4.0),
            rng.uniform(-2.0, 2.0),
        );
        let m = hill_monodromy(beta0, kappa, t0).unwrap();
        for j in 0..2 {
            // The kinks of |cos t| are integration breakpoints for DOP853 too.
            let mut y = State::default();
            *slot(&mut y, if j == 0 { 0 } else { 6 }) = 1.0;
            let mut t = t0;
            let mut stops: Vec<f64> = (-3..4)
                .map(|k| FRAC_PI_2 + k as f64 * PI)
                .filter(|&s| s > t0 && s < t0 + PI)
                .collect();
            stops.push(t0 + PI);
            for s in stops {
                y = rk.integrate(&Hill(beta0, kappa), t, &y, s, &[s]).unwrap()[0];
                t = s;
            }
            let scale = 1.0 + m.amax();
            assert!(
                (y.coords[0] - m[(0, j)]).abs() < 1e-9 * scale,
                "{beta0} {kappa} {t0}"
            );
            assert!(
                (y.rates[0] - m[(1, j)]).abs() < 1e-9 * scale,
                "{beta0} {kappa} {t0}"
            );
        }
    }
}

#[test]
fn errata_8_hill_form_coefficient_is_minus_one_quarter() {
    // y = x exp(½β0∫|cos|) (eq. 2.26) satisfies ÿ + (κ − ¼β0²cos²t − ½β0 d|cos t|/dt) y = 0
    // (docs/errata.md#8), not the printed +½β0²cos²t of eq. 2.27. Checked by second differences
    // of y built from the integrated solution on the smooth piece t in (−π/2, π/2).
    let (beta0, kappa, t0) = (0.8, 1.3, -FRAC_PI_2);
    let y = |t: f64| {
        let x = hill_solution_matrix(beta0, kappa, t0, t).unwrap()[(0, 1)];
        x * (0.5 * beta0 * (1.0 + t.sin())).exp()
    };
    let h = 1e-3;
    let (mut worst_corrected, mut worst_printed) = (0.0f64, 0.0f64);
    for k in 0..=20 {
        let t = -1.2 + 2.4 * k as f64 / 20.0;
        let ydd = (y(t + h) - 2.0 * y(t) + y(t - h)) / (h * h);
        let d_abs_cos = -t.sin(); // d|cos t|/dt for cos t > 0
        let corrected = kappa - 0.25 * beta0 * beta0 * t.cos().powi(2) - 0.5 * beta0 * d_abs_cos;
        let printed = kappa + 0.5 * beta0 * beta0 * t.cos().powi(2) - 0.5 * beta0 * d_abs_cos;
        worst_corrected = worst_corrected.max((ydd + corrected * y(t)).abs());
        worst_printed = worst_printed.max((ydd + printed * y(t)).abs());
    }
    assert!(worst_corrected < 1e-5, "{worst_corrected:e}");
    assert!(worst_printed > 0.1, "{worst_printed:e}");
}

#[test]
fn errata_9_region_one_is_the_schur_cohn_triangle() {
    // Region I ⇔ both roots of eq. 2.36 inside the closed unit disc, over an (a, b) grid.
    for i in 0..=80 {
        for j in 0..=60 {
            let (a, b) = (-2.0 + 4.0 * i as f64 / 80.0, -0.5 + 2.5 * j as f64 / 60.0);
            let rmax = roots(a, b).iter().map(|r| r.norm()).fold(0.0, f64::max);
            if (rmax - 1.0).abs() < 1e-9 {
                continue; // on a boundary
            }
            let r = region(a, b).unwrap();
            assert_eq!(
                r == Region::I,
                rmax < 1.0,
                "a {a} b {b}: {r:?}, max|rho| {rmax}"
            );
            let complex = a * a < b;
            match r {
                Region::II => assert!(complex && b > 1.0),
                Region::III => assert!(!complex && a > 0.0),
                Region::IV => assert!(!complex && a < 0.0),
                Region::I => {}
            }
        }
    }
    // A Hill point the printed bound a > (b − 1)/2 puts in Region III, yet stable: real roots,
    // a > 0, and solutions that decay over 100 periods.
    let f = hill_floquet(1.0, 0.05).unwrap();
    assert!(
        f.a > 0.0 && f.a * f.a > f.b && f.a > 0.5 * (f.b - 1.0),
        "{f:?}"
    );
    assert_eq!(f.region, Region::I);
    let long = hill_solution_matrix(1.0, 0.05, -FRAC_PI_2, -FRAC_PI_2 + 100.0 * PI).unwrap();
    assert!(long.amax() < 1e-2, "{long}");
}

#[test]
fn errata_10_eqs_2_52_to_2_54() {
    for beta0 in [0.3, 0.9, 2.0] {
        let m = hill_monodromy(beta0, 0.0, -FRAC_PI_2).unwrap();
        let i0 = bessel_i0(beta0);
        // Eq. 2.52 gives Q with M = exp(πQ), not log (docs/errata.md#10).
        let q = Matrix2::new(
            0.0,
            -2.0 * i0 * beta0 * beta0.exp() / (1.0 - (2.0 * beta0).exp()),
            0.0,
            -2.0 * beta0 / PI,
        );
        let e = (q * PI).exp();
        assert!((e - m).amax() < 1e-9, "{beta0}: exp(pi Q) = {e} vs M = {m}");
        // Eq. 2.53 as printed is M^(n+1).
        let n = 4;
        let printed = Matrix2::new(
            1.0,
            PI * (-beta0).exp() * i0 * (1.0 - (-2.0 * (n as f64 + 1.0) * beta0).exp())
                / (1.0 - (-2.0 * beta0).exp()),
            0.0,
            (-2.0 * (n as f64 + 1.0) * beta0).exp(),
        );
        assert!((m.pow(n + 1) - printed).amax() < 1e-9);
        let ratio = printed[(1, 1)] / m.pow(n)[(1, 1)];
        assert!((ratio / (-2.0 * beta0).exp() - 1.0).abs() < 1e-9, "not M^n");
        // Eq. 2.54 needs a factor π: x(∞) = x0 + ẋ0 π I0 e^{−β0}/(1 − e^{−2β0}).
        let far = hill_solution_matrix(beta0, 0.0, -FRAC_PI_2, -FRAC_PI_2 + 40.0 * PI).unwrap();
        let limit = PI * i0 * (-beta0).exp() / (1.0 - (-2.0 * beta0).exp());
        assert!((far[(0, 1)] / limit - 1.0).abs() < 1e-9, "{beta0}");
        assert!((far[(0, 0)] - 1.0).abs() < 1e-12 && far[(1, 1)].abs() < 1e-9);
        assert!(
            (far[(0, 1)] / (limit / PI) - PI).abs() < 1e-8,
            "the printed form is off by pi"
        );
    }
}

#[test]
fn chart_is_row_major_parallel_and_matches_pointwise() {
    let beta0 = [-0.5, 0.0, 0.7, 3.0];
    let kappa = [-0.3, 0.0, 0.25, 1.0, 4.2];
    let chart = stability_chart(&beta0, &kappa).unwrap();
    assert_eq!(chart.a.len(), 20);
    for (i, &b0) in beta0.iter().enumerate() {
        for (j, &k) in kappa.iter().enumerate() {
            let idx = i * kappa.len() + j;
            let f = hill_floquet(b0, k).unwrap();
            assert_eq!((chart.beta0[idx], chart.kappa[idx]), (b0, k));
            assert_eq!(chart.a[idx], f.a);
            assert_eq!(chart.b[idx], f.b);
            assert_eq!(chart.region[idx], Some(f.region));
            assert_eq!(chart.spectral_radius[idx], f.spectral_radius());
            // Negative damping: b = e^{-2β0} > 1, never stable (eq. 2.51). A negative spring
            // has a real multiplier above 1.
            if b0 < 0.0 || k < 0.0 {
                assert!(f.region != Region::I, "{b0} {k}");
            }
            if b0 > 0.0 && (0.0..=0.25).contains(&k) {
                assert_eq!(
                    f.region,
                    Region::I,
                    "weak spring, positive damping: {b0} {k}"
                );
            }
        }
    }
    let err = stability_chart(&[0.0, f64::NAN], &[1.0]).unwrap_err();
    assert_eq!(err.field(), Some("beta0[1]"));
    let err = stability_chart(&[0.0], &[]).unwrap_err();
    assert_eq!(err.kind(), "InvalidParameter");
    assert_eq!(
        hill_monodromy(1e9, 0.0, 0.0).unwrap_err().field(),
        Some("beta0")
    );
    assert_eq!(
        hill_solution_matrix(0.0, 0.0, 1.0, 0.0)
            .unwrap_err()
            .field(),
        Some("t1")
    );
}

#[test]
fn brockett_closed_forms() {
    // δ = 0: the intervals [(n−1)π, nπ] cover every period.
    for period in [0.1, 3.0, 100.0] {
        let b = brockett(0.0, period, 0.0).unwrap();
        assert!(b.bounded, "{b:?}");
    }
    // δ = 1/2: s = √3/2, asin s = π/3: n = 1 covers T ≤ 2π/(3s) = 2.4184, n = 2 the single
    // point 4π/(3s) = 4.8368; nothing else.
    let s = 0.75f64.sqrt();
    let b = brockett(0.5, 2.4, 1.0).unwrap();
    assert_eq!(b.n, Some(1));
    assert!((b.interval.unwrap().1 - 2.0 * PI / (3.0 * s)).abs() < 1e-12);
    assert!(brockett(0.5, 4.0 * PI / (3.0 * s), 1.0).unwrap().bounded);
    for period in [2.5, 3.5, 4.8, 6.0, 20.0] {
        assert!(!brockett(0.5, period, 1.0).unwrap().bounded, "{period}");
    }
    // Eq. 2.58: negative mean damping guarantees nothing; δ ≥ 1 has no interval.
    assert!(!brockett(0.0, 1.0, -1e-3).unwrap().bounded);
    assert!(brockett(1.2, 1.0, 1.0).unwrap().n.is_none());
    assert_eq!(brockett(-0.1, 1.0, 0.0).unwrap_err().field(), Some("delta"));
    assert_eq!(brockett(0.1, 0.0, 0.0).unwrap_err().field(), Some("period"));
    assert_eq!(brockett_hill(1.0, 0.0).unwrap_err().field(), Some("kappa"));
}

#[test]
fn brockett_guarantee_implies_floquet_stability() {
    let mut guaranteed = 0;
    for i in 0..=30 {
        for j in 1..=40 {
            let (beta0, kappa) = (3.0 * i as f64 / 30.0, 6.0 * j as f64 / 40.0);
            let b = brockett_hill(beta0, kappa).unwrap();
            if b.bounded {
                guaranteed += 1;
                let f = hill_floquet(beta0, kappa).unwrap();
                assert!(f.spectral_radius() <= 1.0 + 1e-9, "{beta0} {kappa}: {f:?}");
            }
        }
    }
    assert!(guaranteed > 50, "{guaranteed}");
}

// ------------------------------------------------------------------ docs/errata.md#7: physical mapping

#[test]
fn errata_7_drag_generalised_forces_carry_t_cubed() {
    // Eq. 2.15 device: M_q = diag(2IT², 2IT²L²). From the right-hand side, the drag part of the
    // generalised force is −2ΩT³ sgn(q̇1)(q̇1² + L²q̇2²) on q1 and −4ΩT³L²|q̇1|q̇2 on q2
    // (docs/errata.md#7; eqs. 2.17–2.19 print ΩT²) whenever L|q̇2| < |q̇1|.
    let (i, omega, t, l, k1, k2) = (29.0, 31.3, 2.5, 2.5, 467.0, 20.0);
    let device = eq_2_16_device(linear_map(), k2);
    let actuator = device.spec().actuator.clone().unwrap();
    for (q, qd, time) in [
        ([0.05, 0.01], [0.3, 0.02], 0.7),
        ([-0.1, -0.02], [-0.25, 0.05], 3.1),
        ([0.0, 0.03], [0.1, -0.03], 5.0),
    ] {
        let mut y = State::default();
        (y.coords[0], y.coords[1], y.rates[0], y.rates[1]) = (q[0], q[1], qd[0], qd[1]);
        let mut f = State::default();
        device.rhs(time, &y, &mut f).unwrap();
        let q1_force = 2.0 * i * t * t * f.rates[0] - (actuator.force(time) - k1 * q[0]);
        let q2_force = 2.0 * i * t * t * l * l * f.rates[1] + k2 * q[1];
        let s = qd[0].signum();
        let want1 = -2.0 * omega * t.powi(3) * s * (qd[0].powi(2) + l * l * qd[1].powi(2));
        let want2 = -4.0 * omega * t.powi(3) * l * l * qd[0].abs() * qd[1];
        assert!(
            (q1_force - want1).abs() < 1e-10 * want1.abs(),
            "{q1_force} vs {want1}"
        );
        assert!(
            (q2_force - want2).abs() < 1e-10 * want2.abs(),
            "{q2_force} vs {want2}"
        );
    }
    // Hence β0 = 2ΩTA/I = 2ΩΦ/I, κ1 = K1/(2IT²ω0²), κ2 = K2/(2IT²L²ω0²).
    let p = PhysicalParameters {
        inertia: i,
        drag: omega,
        transmission_ratio: t,
        arm_length: l,
        k1,
        k2,
        stroke_amplitude: 0.5,
        frequency_hz: 110.0,
    };
    let h = p.hill().unwrap();
    let w0 = 2.0 * PI * 0.110;
    assert!((h.beta0 - 2.0 * omega * 0.5 / i).abs() < 1e-14);
    assert!((h.kappa1 - k1 / (2.0 * i * t * t * w0 * w0)).abs() < 1e-14);
    assert!((h.kappa2 - k2 / (2.0 * i * t * t * l * l * w0 * w0)).abs() < 1e-14);
    let lti = p.lti().unwrap();
    assert!((lti.beta_star - 2.0 / PI * h.beta0 * w0).abs() < 1e-14);
    let bad = PhysicalParameters { inertia: 0.0, ..p };
    assert_eq!(bad.hill().unwrap_err().field(), Some("inertia"));
}

#[test]
fn errata_7_whippletree_block_determinant_is_exp_minus_four_beta0() {
    // On a symmetric orbit the (q2, q̇2) block of the monodromy decouples. Liouville in
    // (q2, p2): its determinant is exp(−∮ c22/m22 dt) = exp(−(2Ω/I)∮|φ̇|dt) = exp(−8ΩΦ/I) for a
    // single-hump stroke of amplitude Φ, for the linear map and the nonlinear linkage alike.
    // One drive period is two periods of eq. 2.25, so this is b² = e^{−4β0} (eq. 2.45) with
    // β0 = 2ΩΦ/I (docs/errata.md#7; the printed 2ΩA/I would give e^{−4β0/T}).
    for drivetrain in [
        linear_map(),
        Drivetrain::LinkageDifferential(LinkageDifferential::thesis()),
    ] {
        let device = eq_2_16_device(drivetrain, 200.0);
        let f = floquet(&device, &options()).unwrap();
        let lin = linearise(&device, &f.orbit, 2000).unwrap();
        let beta0 = lin.hill.beta0;
        assert!((beta0 - 2.0 * 31.3 * lin.physical.stroke_amplitude / 29.0).abs() < 1e-12);
        let [r1, r2] = f.whippletree.unwrap();
        let det = (r1 * r2).re;
        let want = (-4.0 * beta0).exp();
        assert!(f.whippletree_coupling.unwrap() < 1e-5, "symmetric orbit");
        assert!(
            (det / want - 1.0).abs() < 1e-3,
            "{}: {det:e} vs {want:e}",
            drivetrain.name()
        );
        // The q1 block obeys the same identity.
        let m = &f.monodromy;
        let det1 = m[(0, 0)] * m[(2, 2)] - m[(0, 2)] * m[(2, 0)];
        assert!((det1 / want - 1.0).abs() < 1e-3, "{det1:e} vs {want:e}");
    }
}

#[test]
fn linear_map_whippletree_multipliers_follow_eq_2_25() {
    // With eq. 2.15 the q2 variational equation is eq. 2.24 with β0|cos τ| replaced by
    // 2Ω|φ̇(t)|/(I ω0) of the simulated (nearly sinusoidal) stroke: its multipliers over one
    // drive period are those of eq. 2.25 over two of its periods, ρ², at (β0, κ2) from
    // `linearise`. The stroke is not exactly sinusoidal, so agree within 5 %.
    for k2 in [50.0, 200.0, 400.0] {
        let device = eq_2_16_device(linear_map(), k2);
        let f = floquet(&device, &options()).unwrap();
        let lin = linearise(&device, &f.orbit, 2000).unwrap();
        let hill = hill_floquet(lin.hill.beta0, lin.hill.kappa2).unwrap();
        let mut want: Vec<Complex<f64>> = hill.multipliers.iter().map(|r| r * r).collect();
        let mut got: Vec<Complex<f64>> = f.whippletree.unwrap().to_vec();
        for v in [&mut want, &mut got] {
            v.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
        }
        let trace_got = got[0] + got[1];
        let trace_want = want[0] + want[1];
        assert!(
            (trace_got - trace_want).norm() < 0.05 * trace_want.norm(),
            "K2 {k2}: {got:?} vs {want:?}"
        );
    }
}
