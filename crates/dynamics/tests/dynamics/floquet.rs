//! floquet tests (submodule of the one dynamics integration binary).
//!
//! §2.6: the eq. 2.25 monodromy against Liouville (eq. 2.45), the κ = 0 closed form (eq. 2.50)
//! and an independent adaptive integrator; docs/errata.md#7 to #10 each checked numerically. Full
//! model: shooting against long simulation, multipliers against independent differences of the
//! stroboscopic map and against kick growth in `simulate`, and a Liouville identity for the
//! whippletree block. §2.7: eq. 2.59 against the nonlinear disturbance response.

use std::f64::consts::{FRAC_PI_2, PI};

use nalgebra::{Complex, DMatrix, Matrix2};
use paritysim_dynamics::floquet::*;
use paritysim_dynamics::integrate::{Integrator, Method, OdeSystem, RungeKutta};
use paritysim_dynamics::{State, SteadyState};
use paritysim_kinematics::drivetrain::LinearDifferential;

use super::*;

// ------------------------------------------------------------------ helpers

/// Modified Bessel function I0 by its power series Σ (x/2)^{2k}/(k!)² (independent of the code).
fn bessel_i0(x: f64) -> f64 {
    let (mut term, mut sum, mut k) = (1.0, 1.0, 1.0);
    while term > 1e-18 * sum {
        term *= (0.5 * x) * (0.5 * x) / (k * k);
        sum += term;
        k += 1.0;
    }
    sum
}

/// A small deterministic generator (xorshift64*), uniform in [lo, hi).
struct Rng(u64);

impl Rng {
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let bits = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11;
        lo + (hi - lo) * (bits as f64 / (1u64 << 53) as f64)
    }
}

/// Roots of ρ² − 2aρ + b by the textbook formula in complex arithmetic (independent of
/// `multipliers`).
fn roots(a: f64, b: f64) -> [Complex<f64>; 2] {
    let d = Complex::new(a * a - b, 0.0).sqrt();
    [Complex::new(a, 0.0) + d, Complex::new(a, 0.0) - d]
}

/// The §3.3 Drag PARITY device (examples/drag_parity.toml): nonlinear linkage, C_N(90°) drag,
/// 100 V at 110 Hz, balance-beam stiffness `k2`.
fn section_3_3(omega_left: f64, k2: f64) -> Device {
    section_3_3_at(omega_left, k2, 100.0)
}

/// The same at `volts` (a cut wing at 100 V strokes beyond the linkage's reach; 70 V is safe).
fn section_3_3_at(omega_left: f64, k2: f64, volts: f64) -> Device {
    two_wing_device(
        [
            fixed_wing(WingAero::stroke_drag(omega_left, 3.4609).unwrap()),
            fixed_wing(WingAero::stroke_drag(31.3, 3.4609).unwrap()),
        ],
        "drag_parity_fixed",
        Drivetrain::LinkageDifferential(LinkageDifferential::thesis()),
        k2,
        Actuator::thesis(Waveform::sine(volts, 110.0, 0.0, 0.0).unwrap()),
        Formulation::Auto,
    )
}

/// Eq. 2.15 with T = 2.5 rad/mm, L = 2.5 mm (the linearisation of the §3.3 linkage), eq. 2.16
/// drag (C = 1), 50 V.
fn linear_map() -> Drivetrain {
    Drivetrain::LinearDifferential(LinearDifferential::new(2.5, 2.5, 1.0).unwrap())
}

fn eq_2_16_device(drivetrain: Drivetrain, k2: f64) -> Device {
    parity_device_with(31.3, k2, "drag_parity_fixed", Formulation::Auto, drivetrain)
}

fn options() -> ShootingOptions {
    ShootingOptions::default()
}

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

// ------------------------------------------------------------------ §2.7

#[test]
fn eq_2_59_closed_forms() {
    let lti = LtiModel::new(2.0, 0.3).unwrap();
    assert_eq!(lti.transfer(0.0).unwrap(), Complex::new(1.0, 0.0));
    // At ω = √κ0 the response is κ0/(iβ*ω): magnitude √κ0/β*, phase −π/2.
    let f = 0.3f64.sqrt() / (2.0 * PI * 1e-3);
    let h = lti.transfer(f).unwrap();
    assert!((h.norm() - 0.3f64.sqrt() / 2.0).abs() < 1e-14);
    assert!((h.arg() + FRAC_PI_2).abs() < 1e-12);
    // High frequency: κ0/ω² roll-off.
    let w = 2.0 * PI * 10.0;
    assert!((lti.transfer(1e4).unwrap().norm() * w * w / 0.3 - 1.0).abs() < 1e-3);
    assert!(LtiModel::new(0.0, 0.0).unwrap().transfer(0.0).is_err());
    assert_eq!(
        lti.transfer(-1.0).unwrap_err().field(),
        Some("frequency_hz")
    );
}

#[test]
fn roll_disturbance_obeys_momentum_balance() {
    // The body roll torque (wing momentum balance) equals the drivetrain's reaction
    // τ_drive,L − τ_drive,R with τ_drive = J⁻ᵀ (F − K1 q1, −K2 q2), at arbitrary states.
    let device = section_3_3_at(0.599 * 31.3, 500.0, 70.0);
    let tr = device.spec().transmission.clone().unwrap();
    let actuator = device.spec().actuator.clone().unwrap();
    let system = RollDisturbance::new(&device, 2.0, 300.0).unwrap();
    for (q, qd, t) in [
        ([0.05, 0.02], [0.3, -0.1], 0.4),
        ([-0.12, -0.05], [0.1, 0.2], 2.9),
    ] {
        let mut y = State::default();
        (y.coords[0], y.coords[1], y.rates[0], y.rates[1]) = (q[0], q[1], qd[0], qd[1]);
        let roll = system.body_roll(t, &y).unwrap();
        let j = tr.kinematics().evaluate(q[0], q[1]).unwrap().jacobian;
        let generalised = nalgebra::Vector2::new(actuator.force(t) - 467.0 * q[0], -500.0 * q[1]);
        let tau = j.transpose().lu().solve(&generalised).unwrap();
        assert!(
            (roll - (tau.x - tau.y)).abs() < 1e-9 * (1.0 + roll.abs()),
            "{roll} vs {}",
            tau.x - tau.y
        );
    }
    // Without a disturbance it is `simulate`'s roll_total.
    let quiet = RollDisturbance::new(&device, 0.0, 300.0).unwrap();
    let r = simulate(
        &device,
        &SimulationOptions {
            max_cycles: 5,
            samples_per_cycle: 16,
            ..Default::default()
        },
    )
    .unwrap();
    let tr = &r.trajectory;
    for k in 0..tr.time.len() {
        let mut y = State::default();
        for (name, s) in [("q1", 0), ("q2", 1), ("q1_dot", 6), ("q2_dot", 7)] {
            *slot(&mut y, s) = tr.column(name).unwrap()[k];
        }
        let roll = quiet.body_roll(tr.time[k], &y).unwrap();
        let want = tr.column("roll_total").unwrap()[k];
        assert!(
            (roll - want).abs() < 1e-9 * (1.0 + want.abs()),
            "{roll} vs {want}"
        );
    }
}

#[test]
fn lti_and_nonlinear_disturbance_responses_agree_at_low_amplitude() {
    // Eq. 2.15 drivetrain with eq. 2.16 drag (β0 ≈ 2, the setting of §2.6–2.7). Eq. 2.59
    // replaces the damping 2Ω|φ̇(t)|/I, which swings between 0 and π/2 times its mean, by the
    // mean; the neglected modulation at twice the flapping frequency mixes the response into
    // sidebands and back. Stated tolerance: 10 % in |H| and 0.1 rad in phase from 30 to 300 Hz.
    let device = eq_2_16_device(linear_map(), 200.0);
    let f = floquet(&device, &options()).unwrap();
    let lin = linearise(&device, &f.orbit, 2000).unwrap();
    // For the linear map the three LTI constructions coincide.
    assert!((lin.lti.beta_star / lin.lti_sinusoidal.beta_star - 1.0).abs() < 1e-5);
    assert!((lin.lti.kappa0 / lin.lti_sinusoidal.kappa0 - 1.0).abs() < 1e-12);
    assert!((lin.lti_averaged.beta_star / lin.lti.beta_star - 1.0).abs() < 1e-5);
    assert!((lin.lti_averaged.kappa0 / lin.lti.kappa0 - 1.0).abs() < 1e-6);
    assert!(lin.geometric_stiffness.abs() < 1e-3);
    for freq in [30.0, 60.0, 150.0, 300.0] {
        let small =
            disturbance_response(&device, &f.orbit, freq, 0.1, &Default::default()).unwrap();
        let larger =
            disturbance_response(&device, &f.orbit, freq, 0.4, &Default::default()).unwrap();
        assert!(small.drift < 1e-4, "{freq}: settled {}", small.drift);
        assert!(small.commensurability_error < 1e-9);
        assert!(
            (small.transfer - larger.transfer).norm() < 1e-3 * small.transfer.norm(),
            "linear response"
        );
        let h = lin.lti.transfer(freq).unwrap();
        let ratio = small.transfer / h;
        assert!(
            (ratio.norm() - 1.0).abs() < 0.1,
            "{freq} Hz: {} vs {}",
            small.transfer,
            h
        );
        assert!(
            ratio.arg().abs() < 0.1,
            "{freq} Hz: {} vs {}",
            small.transfer,
            h
        );
    }
}

#[test]
fn linkage_geometric_stiffness_is_negative() {
    // docs/findings.md item 3: the rod-crank's gain rises towards the stroke ends, so the
    // averaged whippletree stiffness loses a few hundred mN·mm/rad to geometry.
    let device = section_3_3(31.3, 500.0);
    let f = floquet(&device, &options()).unwrap();
    let lin = linearise(&device, &f.orbit, 1000).unwrap();
    assert!(
        lin.geometric_stiffness < -100.0,
        "{}",
        lin.geometric_stiffness
    );
    assert!(lin.lti_averaged.kappa0 < lin.lti.kappa0);
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

/// Entry `s` of the flat layout `[coords (6), rates (6)]`.
fn slot(y: &mut State, s: usize) -> &mut f64 {
    if s < 6 {
        &mut y.coords[s]
    } else {
        &mut y.rates[s - 6]
    }
}

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
