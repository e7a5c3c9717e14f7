//! Continuation validated against closed forms, harmonic balance and brute-force simulation.

use std::f64::consts::TAU;

use approx::assert_relative_eq;
use nalgebra::DVector;
use paritysim_continuation::oscillators::{
    DRIVE_AMPLITUDE, DRIVE_FREQUENCY, Duffing, ForcedPendulum,
};
use paritysim_continuation::{
    BifurcationKind, ContinuationOptions, CurveOptions, Method, PeriodMap, RungeKuttaMap,
    Stability, StopReason, continue_fold_curve, continue_orbits,
};

/// Steady state by brute force: iterate the period map.
fn settle<M: PeriodMap>(map: &M, x: DVector<f64>, p: &[f64], periods: usize) -> DVector<f64> {
    (0..periods).fold(x, |x, _| map.image(&x, p).unwrap())
}

/// A linear oscillator's orbit and multipliers are known exactly along the whole branch.
#[test]
fn linear_oscillator_branch_matches_closed_form() {
    let (damping, stiffness, force) = (0.2, 1.0, 0.3);
    let ode = Duffing {
        damping,
        linear_stiffness: stiffness,
        cubic_stiffness: 0.0,
    };
    let map = RungeKuttaMap::new(ode, 2000).unwrap();
    for method in [Method::PseudoArclength, Method::Natural] {
        let mut options = ContinuationOptions::new(DRIVE_FREQUENCY, 2.0);
        options.method = method;
        let branch = continue_orbits(&map, &DVector::zeros(2), &[0.5, force], &options).unwrap();
        assert_eq!(branch.stop_reason, StopReason::ReachedStop);
        assert!(branch.bifurcations.is_empty(), "{:?}", branch.bifurcations);
        assert!(branch.points.len() > 10);
        assert_relative_eq!(
            branch.points.last().unwrap().parameter,
            2.0,
            epsilon = 1e-12
        );
        for p in &branch.points {
            let w = p.parameter;
            // x = A cos(ωt − φ): the amplitude from the state at t = 0.
            let amplitude = (p.state[0].powi(2) + (p.state[1] / w).powi(2)).sqrt();
            let exact = force / ((stiffness - w * w).powi(2) + (damping * w).powi(2)).sqrt();
            assert_relative_eq!(amplitude, exact, max_relative = 1e-8);
            // Multipliers exp(λ T) of λ = −δ/2 ± i·sqrt(k − δ²/4): modulus exp(−δT/2).
            let modulus = (-damping / 2.0 * TAU / w).exp();
            for mu in &p.multipliers {
                assert_relative_eq!(mu.norm(), modulus, max_relative = 1e-8);
            }
            assert_eq!(p.stability, Stability::Stable);
        }
    }
}

/// Harmonic balance of `x'' + δx' + x + βx³ = γ cos ωt`: `(1 + ¾βr² − ω²)² + (δω)² = (γ/r)²`.
/// The folds are the turning points of ω along the curve, found here on a fine scan of `r`.
fn harmonic_balance_folds(damping: f64, cubic: f64, force: f64) -> Vec<f64> {
    let mut folds = Vec::new();
    for sign in [1.0, -1.0] {
        let omega = |r: f64| -> Option<f64> {
            let kappa = 1.0 + 0.75 * cubic * r * r;
            let b = 2.0 * kappa - damping * damping;
            let disc = b * b - 4.0 * (kappa * kappa - (force / r).powi(2));
            (disc >= 0.0).then(|| ((b + sign * disc.sqrt()) / 2.0).sqrt())
        };
        let rs: Vec<f64> = (1..200_000).map(|k| k as f64 * 1e-5).collect();
        let ws: Vec<Option<f64>> = rs.iter().map(|&r| omega(r)).collect();
        for k in 1..ws.len() - 1 {
            if let (Some(a), Some(b), Some(c)) = (ws[k - 1], ws[k], ws[k + 1]) {
                if (b - a) * (c - b) < 0.0 {
                    folds.push(b);
                }
            }
        }
    }
    folds.sort_by(f64::total_cmp);
    folds
}

/// The hardening Duffing frequency response has two folds (jump up and jump down); arclength
/// continuation turns around both, with the middle branch unstable, and locates them where
/// harmonic balance puts them.
#[test]
fn duffing_folds_agree_with_harmonic_balance() {
    let (damping, cubic, force) = (0.05, 0.1, 0.1);
    let ode = Duffing {
        damping,
        linear_stiffness: 1.0,
        cubic_stiffness: cubic,
    };
    let map = RungeKuttaMap::new(ode, 800).unwrap();
    let p0 = [0.8, force];
    let x0 = settle(&map, DVector::zeros(2), &p0, 400);
    let mut options = ContinuationOptions::new(DRIVE_FREQUENCY, 1.6);
    options.max_step = 0.05;
    let branch = continue_orbits(&map, &x0, &p0, &options).unwrap();
    assert_eq!(branch.stop_reason, StopReason::ReachedStop);
    let mut folds: Vec<_> = branch
        .bifurcations
        .iter()
        .filter(|b| b.kind == BifurcationKind::Fold)
        .collect();
    // Along the branch: jump-down (upper) fold first, then back to the jump-up fold.
    assert!(folds.len() == 2 && folds[0].point.parameter > folds[1].point.parameter);
    folds.sort_by(|a, b| a.point.parameter.total_cmp(&b.point.parameter));
    assert_eq!(
        folds.len(),
        2,
        "{:?}",
        branch
            .bifurcations
            .iter()
            .map(|b| (b.kind, b.point.parameter))
            .collect::<Vec<_>>()
    );
    let expected = harmonic_balance_folds(damping, cubic, force);
    assert_eq!(expected.len(), 2, "{expected:?}");
    for (fold, hb) in folds.iter().zip(&expected) {
        assert!(fold.located);
        // One-harmonic balance neglects the third harmonic (here ~1e-4 of the fold frequency).
        assert_relative_eq!(fold.point.parameter, *hb, max_relative = 2e-3);
        // At a fold one multiplier is +1.
        let nearest = fold
            .point
            .multipliers
            .iter()
            .map(|m| (m - 1.0).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(nearest < 1e-4, "{:?}", fold.point.multipliers);
    }
    // Between the folds the branch passes through the unstable middle branch.
    assert!(
        branch
            .points
            .iter()
            .any(|p| p.stability == Stability::Unstable)
    );
    assert!(branch.points.first().unwrap().stability == Stability::Stable);
    assert!(branch.points.last().unwrap().stability == Stability::Stable);
    // Natural continuation from the same start stops at the first fold instead.
    options.method = Method::Natural;
    let natural = continue_orbits(&map, &x0, &p0, &options).unwrap();
    assert!(
        matches!(natural.stop_reason, StopReason::StepTooSmall(_)),
        "{:?}",
        natural.stop_reason
    );
    let reached = natural.points.last().unwrap().parameter;
    assert!(
        (reached - expected[1]).abs() < 0.02 || (reached - expected[0]).abs() < 0.02,
        "{reached} vs {expected:?}"
    );

    // The fold followed in the forcing amplitude: the cusp where the two folds meet is where
    // the jump disappears; both fold frequencies move apart as the forcing grows.
    let mut curve_options = CurveOptions::new(DRIVE_AMPLITUDE, 0.15);
    curve_options.max_step = 0.02;
    let curve = continue_fold_curve(&map, folds[0], &p0, DRIVE_FREQUENCY, &curve_options).unwrap();
    assert!(curve.points.len() > 3, "{:?}", curve.stop_reason);
    for pt in &curve.points {
        let (w, g) = pt.parameters;
        let nearest = pt
            .multipliers
            .iter()
            .map(|m| (m - 1.0).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(
            nearest < 1e-4,
            "multipliers {:?} at ({w}, {g})",
            pt.multipliers
        );
        let hb = harmonic_balance_folds(damping, cubic, g);
        let closest = hb
            .iter()
            .map(|f| (f - w).abs())
            .fold(f64::INFINITY, f64::min);
        assert!(
            closest < 5e-3 * w,
            "fold at ({w}, {g}) vs harmonic balance {hb:?}"
        );
    }
}

/// The damped driven pendulum (b = 0.5, ω = 2/3; Baker & Gollub): the symmetric orbit loses
/// its symmetry at a branch point (a multiplier through +1 without a turn), and the asymmetric
/// orbit then period-doubles; the located point is where brute-force simulation sees the period
/// change.
#[test]
fn pendulum_period_doubling_is_where_simulation_sees_it() {
    let ode = ForcedPendulum { damping: 0.5 };
    let map = RungeKuttaMap::new(ode, 600).unwrap();
    let w = 2.0 / 3.0;
    let symmetric = [w, 0.9];
    let x0 = settle(&map, DVector::zeros(2), &symmetric, 300);
    let mut options = ContinuationOptions::new(DRIVE_AMPLITUDE, 1.03);
    options.max_step = 0.02;
    let branch = continue_orbits(&map, &x0, &symmetric, &options).unwrap();
    let kinds: Vec<_> = branch
        .bifurcations
        .iter()
        .map(|b| (b.kind, b.point.parameter))
        .collect();
    assert_eq!(kinds.len(), 1, "{kinds:?}");
    assert_eq!(kinds[0].0, BifurcationKind::BranchPoint);
    // The asymmetric orbit that brute force finds past the branch point period-doubles.
    let asymmetric = [w, 1.03];
    let x1 = settle(&map, DVector::zeros(2), &asymmetric, 600);
    let mut options = ContinuationOptions::new(DRIVE_AMPLITUDE, 1.1);
    options.max_step = 0.01;
    let branch = continue_orbits(&map, &x1, &asymmetric, &options).unwrap();
    let pd = branch
        .bifurcations
        .iter()
        .find(|b| b.kind == BifurcationKind::PeriodDoubling)
        .unwrap_or_else(|| panic!("no period doubling: {:?}", branch.bifurcations));
    assert!(pd.located);
    let a_star = pd.point.parameter;
    let nearest = pd
        .point
        .multipliers
        .iter()
        .map(|m| (m + 1.0).norm())
        .fold(f64::INFINITY, f64::min);
    assert!(nearest < 1e-4, "{:?}", pd.point.multipliers);
    // Brute force on either side: period 1 just below, period 2 just above.
    let period_residuals = |a: f64| {
        let p = [w, a];
        let x = settle(&map, pd.point.state.clone(), &p, 3000);
        let once = (map.image(&x, &p).unwrap() - &x).norm();
        let twice = (map.image(&map.image(&x, &p).unwrap(), &p).unwrap() - &x).norm();
        (once, twice)
    };
    let (below_once, _) = period_residuals(a_star - 0.002);
    let (above_once, above_twice) = period_residuals(a_star + 0.002);
    assert!(below_once < 1e-6, "below {a_star}: {below_once}");
    assert!(
        above_once > 1e-3 && above_twice < 1e-6,
        "above {a_star}: {above_once} {above_twice}"
    );
}

#[test]
fn bad_options_name_the_field() {
    let ode = Duffing {
        damping: 0.2,
        linear_stiffness: 1.0,
        cubic_stiffness: 0.0,
    };
    let map = RungeKuttaMap::new(ode, 100).unwrap();
    let x0 = DVector::zeros(2);
    let field = |o: ContinuationOptions| {
        continue_orbits(&map, &x0, &[0.5, 0.3], &o)
            .unwrap_err()
            .field()
            .map(str::to_owned)
    };
    assert_eq!(
        field(ContinuationOptions::new(7, 1.0)).as_deref(),
        Some("parameter")
    );
    assert_eq!(
        field(ContinuationOptions::new(0, 0.5)).as_deref(),
        Some("stop")
    );
    let mut o = ContinuationOptions::new(0, 1.0);
    o.initial_step = -1.0;
    assert_eq!(field(o).as_deref(), Some("initial_step"));
    let mut o = ContinuationOptions::new(0, 1.0);
    o.cyclic = Some(5);
    assert_eq!(field(o).as_deref(), Some("cyclic"));
    assert_eq!(
        RungeKuttaMap::new(ode, 3).unwrap_err().field(),
        Some("steps")
    );
}

/// A cyclic coordinate: `x'' + δx' = γ cos ωt` has orbits for every shift of `x` (multiplier 1
/// everywhere). Pinned, it continues as a relative periodic orbit with zero drift, no fold is
/// reported, and the trivial multiplier is removed.
#[test]
fn cyclic_coordinate_is_not_a_fold() {
    let ode = Duffing {
        damping: 0.3,
        linear_stiffness: 0.0,
        cubic_stiffness: 0.0,
    };
    let map = RungeKuttaMap::new(ode, 1000).unwrap();
    let mut options = ContinuationOptions::new(DRIVE_FREQUENCY, 2.0);
    options.cyclic = Some(0);
    let branch = continue_orbits(
        &map,
        &DVector::from_vec(vec![0.7, 0.0]),
        &[0.5, 0.2],
        &options,
    )
    .unwrap();
    assert_eq!(branch.stop_reason, StopReason::ReachedStop);
    assert!(branch.bifurcations.is_empty());
    for p in &branch.points {
        assert_eq!(p.multipliers.len(), 1);
        assert_relative_eq!(
            p.multipliers[0].re,
            (-0.3 * TAU / p.parameter).exp(),
            max_relative = 1e-8
        );
        assert!(p.drift.abs() < 1e-9);
        assert_relative_eq!(p.state[0], 0.7);
        // v = γ/(δ² + ω²)^½ · cos(ωt − φ): the rate's amplitude from v(0) and x's equation.
        assert_eq!(p.stability, Stability::Stable);
    }
    // Without the pinning, the same problem is singular at the first point.
    options.cyclic = None;
    assert!(
        continue_orbits(
            &map,
            &DVector::from_vec(vec![0.7, 0.0]),
            &[0.5, 0.2],
            &options
        )
        .is_err()
    );
}
