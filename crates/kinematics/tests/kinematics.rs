//! Integration tests of paritysim-kinematics (one binary for the crate).

use approx::assert_relative_eq;
use nalgebra::{Matrix3, Vector2, Vector3};
use paritysim_kinematics::drivetrain::{
    DualFourBar, DualLinear, HmfFourBar, LinearDifferential, LinkageDifferential, OddPolynomial,
    SingleLinear,
};
use paritysim_kinematics::rotation::{rot_axis, rot_x, rot_y, rot_z, skew};
use paritysim_kinematics::{Drivetrain, Error, RodCrank, SphericalShoulder};
use proptest::prelude::*;

const CONFIGS_DEG: [(f64, f64); 5] = [
    (90.0, 0.0),
    (90.0, 45.0),
    (120.0, 60.0),
    (100.0, 20.0),
    (150.0, 30.0),
];

fn shoulder(a2: f64, a3: f64) -> SphericalShoulder {
    SphericalShoulder::new(a2.to_radians(), a3.to_radians()).unwrap()
}

// ---------------------------------------------------------------- rotations

#[test]
fn rotations_match_axis_angle_and_skew_is_cross_product() {
    let ang = 0.73;
    assert_relative_eq!(
        rot_x(ang),
        rot_axis(&Vector3::x_axis(), ang),
        epsilon = 1e-15
    );
    assert_relative_eq!(
        rot_y(ang),
        rot_axis(&Vector3::y_axis(), ang),
        epsilon = 1e-15
    );
    assert_relative_eq!(
        rot_z(ang),
        rot_axis(&Vector3::z_axis(), ang),
        epsilon = 1e-15
    );
    let (a, b) = (Vector3::new(0.3, -1.2, 2.0), Vector3::new(-0.7, 0.4, 1.1));
    assert_relative_eq!(skew(&a) * b, a.cross(&b), epsilon = 1e-15);
    // Right-handed: R_z(π/2) maps x to y.
    assert_relative_eq!(
        rot_z(std::f64::consts::FRAC_PI_2) * Vector3::x(),
        Vector3::y(),
        epsilon = 1e-15
    );
}

// ---------------------------------------------------------------- shoulder pose

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    /// Eq. 2.8: both chains place joint 3 at the same point, and the full rotation of link 4
    /// closes through joint 3 (R_4^5 = R_ŝ3(γ3)).
    #[test]
    fn loop_closure_holds_to_round_off(cfg in 0usize..5, phi in -1.5f64..1.5, theta in -1.5f64..1.5, psi in -3.0f64..3.0) {
        let (a2, a3) = CONFIGS_DEG[cfg];
        let sh = shoulder(a2, a3);
        prop_assume!(sh.sin_gamma3(phi, theta).abs() < 0.999);
        let pose = match sh.pose(phi, theta, psi) { Ok(p) => p, Err(Error::Singular(_)) => return Ok(()), Err(e) => panic!("{e}") };
        let [_, g2, g3, _, g5, _] = pose.joint_angles;
        let s3 = sh.axis3().into_inner();
        let lhs = rot_x(phi) * rot_y(g5) * s3;
        let rhs = rot_y(theta) * rot_axis(&sh.axis2(), g2) * s3;
        prop_assert!((lhs - rhs).amax() < 1e-12, "eq. 2.8 residual {}", (lhs - rhs).amax());
        let r45 = pose.link_rotations[4].transpose() * pose.link_rotations[3];
        prop_assert!((r45 - rot_axis(&sh.axis3(), g3)).amax() < 1e-12);
        // Every link rotation is orthonormal.
        for r in pose.link_rotations { prop_assert!((r.transpose() * r - Matrix3::identity()).amax() < 1e-13); }
        // The wing frame is R_x(φ_w) R_y(θ_w) R_z(ψ_w).
        let w = pose.wing_angles;
        prop_assert!((rot_x(w.x) * rot_y(w.y) * rot_z(w.z) - pose.link_rotations[5]).amax() < 1e-13);
    }
}

/// docs/errata.md#6: for (α2, α3) = (90°, 0°), tan θ_w = cos φ tan θ exactly.
#[test]
fn erratum_6_exact_relation_at_90_0() {
    let sh = shoulder(90.0, 0.0);
    for &phi in &[-1.2, -0.5, 0.0, 0.3, 1.0] {
        for &theta in &[-1.0, -0.2, 0.4, 1.1] {
            let tw = sh.pose(phi, theta, 0.0).unwrap().wing_angles.y;
            assert_relative_eq!(tw.tan(), phi.cos() * theta.tan(), epsilon = 1e-12);
        }
    }
}

/// §2.3.3: with (90°, 45°) the box θ_w ∈ {0°, 45°} edges are exactly decoupled from φ.
#[test]
fn box_edges_are_decoupled_at_90_45() {
    let sh = shoulder(90.0, 45.0);
    for i in -60..=60 {
        let phi = (i as f64).to_radians();
        assert!(sh.pose(phi, 0.0, 0.0).unwrap().wing_angles.y.abs() < 1e-12);
        let tw = sh.pose(phi, 45f64.to_radians(), 0.0).unwrap().wing_angles.y;
        assert_relative_eq!(tw, 45f64.to_radians(), epsilon = 1e-12);
    }
    // ...but not elsewhere: at θ = 20°, θ_w depends on φ.
    let a = sh.pose(0.0, 20f64.to_radians(), 0.0).unwrap().wing_angles.y;
    let b = sh.pose(1.0, 20f64.to_radians(), 0.0).unwrap().wing_angles.y;
    assert!((a - b).abs() > 1e-3);
}

#[test]
fn joint_limit_is_a_typed_error_not_nan() {
    let sh = shoulder(90.0, 45.0);
    let (phi, theta) = (1.4, 1.2);
    assert!(!sh.is_reachable(phi, theta));
    match sh.pose(phi, theta, 0.0) {
        Err(Error::OutOfDomain { detail, .. }) => assert!(detail.contains("eq. 2.10"), "{detail}"),
        other => panic!("expected OutOfDomain, got {other:?}"),
    }
    assert!(matches!(
        sh.pose(f64::NAN, 0.0, 0.0),
        Err(Error::InvalidParameter { .. })
    ));
}

#[test]
fn invalid_parameters_name_the_field() {
    let e = SphericalShoulder::new(1.0, 1.0).unwrap_err();
    assert_eq!(e.field(), Some("alpha3"));
    let e = SphericalShoulder::new(4.0, 0.0).unwrap_err();
    assert_eq!(e.field(), Some("alpha2"));
    assert!(e.to_string().contains("(0, pi]"));
    assert!(SphericalShoulder::new(std::f64::consts::PI, 0.0).is_err());
    assert!(SphericalShoulder::new(f64::NAN, 0.0).is_err());
    assert!(SphericalShoulder::new(1.0, -0.1).is_err());
}

// ---------------------------------------------------------------- partials

fn dependent(sh: &SphericalShoulder, phi: f64, theta: f64) -> Vector3<f64> {
    let (g2, g3, g5) = sh.dependent_angles(phi, theta).unwrap();
    Vector3::new(g2, g3, g5)
}

/// Central finite differences of (γ2, γ3, γ5): gradient columns and second derivatives.
fn fd(sh: &SphericalShoulder, phi: f64, theta: f64) -> ([Vector3<f64>; 2], [Vector3<f64>; 3]) {
    let h = 1e-4;
    let f = |a: f64, b: f64| dependent(sh, phi + a, theta + b);
    let d_phi = (f(h, 0.0) - f(-h, 0.0)) / (2.0 * h);
    let d_theta = (f(0.0, h) - f(0.0, -h)) / (2.0 * h);
    let f0 = f(0.0, 0.0);
    let pp = (f(h, 0.0) - 2.0 * f0 + f(-h, 0.0)) / (h * h);
    let tt = (f(0.0, h) - 2.0 * f0 + f(0.0, -h)) / (h * h);
    let pt = (f(h, h) - f(h, -h) - f(-h, h) + f(-h, -h)) / (4.0 * h * h);
    ([d_phi, d_theta], [pp, pt, tt])
}

fn random_reachable_poses(sh: &SphericalShoulder, n: usize, seed: u64) -> Vec<(f64, f64)> {
    // Small LCG: deterministic, no extra dependency.
    let mut state = seed;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.4 - 1.2
    };
    let mut out = Vec::new();
    while out.len() < n {
        let (phi, theta) = (next(), next());
        if sh.sin_gamma3(phi, theta).abs() < 0.95 && sh.partials(phi, theta).is_ok() {
            out.push((phi, theta));
        }
    }
    out
}

#[test]
fn partials_match_finite_differences() {
    for (a2, a3) in CONFIGS_DEG {
        let sh = shoulder(a2, a3);
        for (phi, theta) in random_reachable_poses(&sh, 40, 7) {
            let p = sh.partials(phi, theta).unwrap();
            let ([dp, dt], [pp, pt, tt]) = fd(&sh, phi, theta);
            let grads = [p.gamma2, p.gamma3, p.gamma5];
            let hess = [p.gamma2_hessian, p.gamma3_hessian, p.gamma5_hessian];
            for k in 0..3 {
                let tol1 = 1e-7 * (1.0 + grads[k].amax());
                assert!(
                    (grads[k][0] - dp[k]).abs() < tol1,
                    "({a2},{a3}) d/dphi gamma{k}: {} vs {}",
                    grads[k][0],
                    dp[k]
                );
                assert!(
                    (grads[k][1] - dt[k]).abs() < tol1,
                    "({a2},{a3}) d/dtheta gamma{k}"
                );
                let tol2 = 2e-5 * (1.0 + hess[k].amax());
                assert!(
                    (hess[k][(0, 0)] - pp[k]).abs() < tol2,
                    "({a2},{a3}) d2/dphi2 gamma{k}: {} vs {}",
                    hess[k][(0, 0)],
                    pp[k]
                );
                assert!(
                    (hess[k][(0, 1)] - pt[k]).abs() < tol2,
                    "({a2},{a3}) d2/dphidtheta gamma{k}: {} vs {}",
                    hess[k][(0, 1)],
                    pt[k]
                );
                assert!(
                    (hess[k][(1, 1)] - tt[k]).abs() < tol2,
                    "({a2},{a3}) d2/dtheta2 gamma{k}"
                );
            }
        }
    }
}

/// The thesis' overdetermined form (A.18/A.19/A.26–A.28), solved by least squares (A.15).
/// `joint2_axis_as_printed` uses x̂2 (the printed text) instead of ŝ2¹ (docs/errata.md#2);
/// `a28_as_printed` multiplies A.28 by the θ-partials (docs/errata.md#1).
struct ThesisForm {
    g2: Vector2<f64>,
    g5: Vector2<f64>,
    g2_pt: f64,
    g5_pt: f64,
    g2_pp: f64,
    g5_pp: f64,
}

fn thesis_form(
    sh: &SphericalShoulder,
    phi: f64,
    theta: f64,
    joint2_axis_as_printed: bool,
    a28_as_printed: bool,
) -> ThesisForm {
    let (_, _, g5) = sh.dependent_angles(phi, theta).unwrap();
    let x1 = Vector3::x();
    let y1 = Vector3::y();
    let axis2 = if joint2_axis_as_printed {
        rot_y(theta) * Vector3::x()
    } else {
        rot_y(theta) * sh.axis2().into_inner()
    };
    let y3 = rot_x(phi) * Vector3::y();
    let s3 = rot_x(phi) * rot_y(g5) * sh.axis3().into_inner();
    let lsq = |m: nalgebra::Matrix3x2<f64>, v: Vector3<f64>| -> Vector2<f64> {
        (m.transpose() * m).try_inverse().unwrap() * m.transpose() * v // A.15
    };
    let b = nalgebra::Matrix3x2::from_columns(&[skew(&axis2) * s3, -skew(&y3) * s3]);
    let g_phi = lsq(b, skew(&x1) * s3); // A.18
    let g_theta = lsq(b, -skew(&y1) * s3); // A.19
    let ds3_phi = (skew(&x1) + skew(&y3) * g_phi[1]) * s3; // A.22
    let dsy3_phi = skew(&x1) * skew(&y3) - skew(&y3) * skew(&x1); // A.23 (x̂3¹ = x̂1¹)
    let ds3_theta = skew(&y3) * s3 * g_theta[1]; // A.24
    let dsx2_theta = skew(&y1) * skew(&axis2) - skew(&axis2) * skew(&y1); // A.25
    // A.26
    let rhs_pp = skew(&x1) * ds3_phi
        + nalgebra::Matrix3x2::from_columns(&[
            -skew(&axis2) * ds3_phi,
            dsy3_phi * s3 + skew(&y3) * ds3_phi,
        ]) * g_phi;
    let pp = lsq(b, rhs_pp);
    // A.28, with the column separators restored (docs/errata.md#3).
    let cols = nalgebra::Matrix3x2::from_columns(&[
        -(dsx2_theta * s3 + skew(&axis2) * ds3_theta),
        skew(&y3) * ds3_theta,
    ]);
    let rhs_pt = skew(&x1) * ds3_theta + cols * if a28_as_printed { g_theta } else { g_phi };
    let pt = lsq(b, rhs_pt);
    ThesisForm {
        g2: Vector2::new(g_phi[0], g_theta[0]),
        g5: Vector2::new(g_phi[1], g_theta[1]),
        g2_pt: pt[0],
        g5_pt: pt[1],
        g2_pp: pp[0],
        g5_pp: pp[1],
    }
}

/// docs/errata.md#1 to #3: the corrected A.18/A.26/A.28 agree with our closure formulation for all
/// (α2, α3); the printed x̂2 fails unless α2 = 90°; the printed A.28 fails everywhere.
#[test]
fn errata_1_to_3_appendix_partials() {
    for (a2, a3) in CONFIGS_DEG {
        let sh = shoulder(a2, a3);
        for (phi, theta) in random_reachable_poses(&sh, 10, 3) {
            let ours = sh.partials(phi, theta).unwrap();
            let fixed = thesis_form(&sh, phi, theta, false, false);
            assert_relative_eq!(fixed.g2, ours.gamma2, epsilon = 1e-9, max_relative = 1e-9);
            assert_relative_eq!(fixed.g5, ours.gamma5, epsilon = 1e-9, max_relative = 1e-9);
            assert_relative_eq!(
                fixed.g2_pp,
                ours.gamma2_hessian[(0, 0)],
                epsilon = 1e-8,
                max_relative = 1e-8
            );
            assert_relative_eq!(
                fixed.g5_pp,
                ours.gamma5_hessian[(0, 0)],
                epsilon = 1e-8,
                max_relative = 1e-8
            );
            assert_relative_eq!(
                fixed.g2_pt,
                ours.gamma2_hessian[(0, 1)],
                epsilon = 1e-8,
                max_relative = 1e-8
            );
            assert_relative_eq!(
                fixed.g5_pt,
                ours.gamma5_hessian[(0, 1)],
                epsilon = 1e-8,
                max_relative = 1e-8
            );

            let printed_axis = thesis_form(&sh, phi, theta, true, false);
            let axis_err =
                (printed_axis.g5 - ours.gamma5).amax() + (printed_axis.g2 - ours.gamma2).amax();
            if a2 == 90.0 {
                assert!(axis_err < 1e-9, "x̂2 = ŝ2 at alpha2 = 90°");
            } else {
                assert!(
                    axis_err > 1e-3,
                    "printed A.18 should be wrong at ({a2},{a3}), err {axis_err}"
                );
            }
            let printed_a28 = thesis_form(&sh, phi, theta, false, true);
            let a28_err = (printed_a28.g5_pt - ours.gamma5_hessian[(0, 1)]).abs();
            let is_degenerate =
                (ours.gamma2 - Vector2::new(ours.gamma2[1], ours.gamma2[0])).amax() < 1e-6;
            if !is_degenerate {
                assert!(
                    a28_err > 1e-4,
                    "printed A.28 should be wrong at ({a2},{a3}), phi {phi}, theta {theta}: {a28_err}"
                );
            }
        }
    }
}

/// J6 (A.9) against the angular velocity from finite differences of R_6^1:
/// `S(ω⁶) = R6ᵀ Ṙ6`.
#[test]
fn jacobian_j6_matches_rotation_rates() {
    for (a2, a3) in CONFIGS_DEG {
        let sh = shoulder(a2, a3);
        for (i, (phi, theta)) in random_reachable_poses(&sh, 10, 11).into_iter().enumerate() {
            let psi = 0.3 * i as f64 - 1.0;
            let pose = sh.pose(phi, theta, psi).unwrap();
            let j6 = sh.jacobian(&pose, &sh.partials(phi, theta).unwrap());
            let rate = Vector3::new(0.7, -1.3, 2.1);
            let h = 1e-6;
            let r = |t: f64| {
                sh.pose(phi + rate.x * t, theta + rate.y * t, psi + rate.z * t)
                    .unwrap()
                    .link_rotations[5]
            };
            let r_dot = (r(h) - r(-h)) / (2.0 * h);
            let w = pose.link_rotations[5].transpose() * r_dot;
            let omega_fd = Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
            assert_relative_eq!(j6 * rate, omega_fd, epsilon = 1e-7);
        }
    }
}

// ---------------------------------------------------------------- drivetrains

fn all_drivetrains() -> Vec<Drivetrain> {
    vec![
        Drivetrain::HmfFourBar(HmfFourBar::new(RodCrank::THESIS)),
        Drivetrain::LinearDifferential(LinearDifferential::new(2.5, 2.5, 1.0).unwrap()),
        Drivetrain::LinkageDifferential(LinkageDifferential::thesis()),
        Drivetrain::LinkageDifferential(
            LinkageDifferential::new(RodCrank::new(0.35, 1.0).unwrap(), 5.0, 0.5).unwrap(),
        ),
        Drivetrain::DualFourBar(DualFourBar::new(RodCrank::THESIS)),
        // Polynomial transmissions (issue 35): stiffening and softening cubics, a quintic.
        Drivetrain::SingleLinear(
            SingleLinear::new(2.67, OddPolynomial::new(2.67, 40.0, &[]).unwrap()).unwrap(),
        ),
        Drivetrain::DualLinear(
            DualLinear::new(2.67, OddPolynomial::new(2.67, -20.0, &[150.0]).unwrap()).unwrap(),
        ),
        Drivetrain::LinearDifferential(
            LinearDifferential::new(2.5, 2.5, 0.7)
                .unwrap()
                .with_polynomial(OddPolynomial::new(2.5, 30.0, &[-40.0, 90.0]).unwrap()),
        ),
    ]
}

/// `φ = τ1 σ + τ2 σ³/3 + a5 σ⁵ + a7 σ⁷` of the rod-top displacement σ (closed form), whatever
/// the internal scaling by powers of τ1; τ2 = 0 is eq. 2.15's map bit for bit; a softening
/// cubic is refused beyond its turning point σ* = √(τ1/|τ2|) and the coefficients are named.
#[test]
fn polynomial_transmissions_are_the_odd_polynomial_of_the_rod_displacement() {
    let (t1, t2, a5, a7) = (2.67, 35.0, -60.0, 400.0);
    let poly = OddPolynomial::new(t1, t2, &[a5, a7]).unwrap();
    let closed = |s: f64| t1 * s + t2 * s.powi(3) / 3.0 + a5 * s.powi(5) + a7 * s.powi(7);
    let slope = |s: f64| t1 + t2 * s * s + 5.0 * a5 * s.powi(4) + 7.0 * a7 * s.powi(6);
    let single = Drivetrain::SingleLinear(SingleLinear::new(t1, poly).unwrap());
    let dual = Drivetrain::DualLinear(DualLinear::new(t1, poly).unwrap());
    let (hl, hr) = (2.0 * 2.5 * 0.7 / 1.7, 2.0 * 2.5 / 1.7);
    let diff = Drivetrain::LinearDifferential(
        LinearDifferential::new(t1, 2.5, 0.7)
            .unwrap()
            .with_polynomial(poly),
    );
    for &(q1, q2) in &[(0.0, 0.0), (0.11, -0.02), (-0.17, 0.04)] {
        // σ = −q1 (+ hL q2 left, − hR q2 right): positive q1 strokes both wings negative.
        let e = single.evaluate(q1, 0.0).unwrap();
        assert_relative_eq!(
            e.stroke.x,
            closed(-q1),
            max_relative = 1e-14,
            epsilon = 1e-16
        );
        assert_relative_eq!(e.jacobian[(0, 0)], -slope(-q1), max_relative = 1e-14);
        let e = dual.evaluate(q1, q2).unwrap();
        assert_relative_eq!(
            e.stroke.x,
            closed(-q1),
            max_relative = 1e-14,
            epsilon = 1e-16
        );
        assert_relative_eq!(
            e.stroke.y,
            closed(-q2),
            max_relative = 1e-14,
            epsilon = 1e-16
        );
        let e = diff.evaluate(q1, q2).unwrap();
        let (sl, sr) = (-q1 + hl * q2, -q1 - hr * q2);
        assert_relative_eq!(
            e.stroke.x,
            closed(sl),
            max_relative = 1e-13,
            epsilon = 1e-16
        );
        assert_relative_eq!(
            e.stroke.y,
            closed(sr),
            max_relative = 1e-13,
            epsilon = 1e-16
        );
        assert_relative_eq!(e.jacobian[(1, 1)], -hr * slope(sr), max_relative = 1e-13);
        // τ2 = 0: the linear map's own numbers.
        let linear = LinearDifferential::new(t1, 2.5, 0.7).unwrap();
        let zero = Drivetrain::LinearDifferential(
            linear.with_polynomial(OddPolynomial::new(t1, 0.0, &[]).unwrap()),
        );
        assert_eq!(zero.evaluate(q1, q2).unwrap(), linear.evaluate(q1, q2));
        let via_map = Drivetrain::DualLinear(
            DualLinear::new(t1, OddPolynomial::new(t1, 0.0, &[]).unwrap()).unwrap(),
        )
        .evaluate(q1, q2)
        .unwrap();
        assert_eq!(via_map.stroke, Vector2::new(-t1 * q1, -t1 * q2));
        assert_eq!(via_map.hessian, [nalgebra::Matrix2::zeros(); 2]);
    }
    // Softening: P'(σ) = τ1 − 20 σ² vanishes at σ* = √(2.67/20) = 0.365 mm.
    let soft = Drivetrain::SingleLinear(
        SingleLinear::new(t1, OddPolynomial::new(t1, -20.0, &[]).unwrap()).unwrap(),
    );
    assert!(soft.evaluate(-0.36, 0.0).is_ok());
    assert!(matches!(
        soft.evaluate(-0.37, 0.0),
        Err(Error::OutOfDomain { .. })
    ));
    for (bad, field) in [
        (OddPolynomial::new(t1, f64::NAN, &[]), "cubic_ratio"),
        (
            OddPolynomial::new(t1, 0.0, &[1.0, f64::INFINITY]),
            "higher_odd_ratios[1]",
        ),
        (OddPolynomial::new(t1, 0.0, &[1.0; 4]), "higher_odd_ratios"),
    ] {
        match bad {
            Err(Error::InvalidParameter { field: f, .. }) => assert_eq!(f, field),
            other => panic!("{other:?}"),
        }
    }
}

#[test]
fn dual_four_bar_is_one_hmf_side_per_actuator() {
    // Each wing's stroke is the HMF stroke of its own actuator coordinate, untouched by the
    // other one (diagonal Jacobian).
    let hmf = Drivetrain::HmfFourBar(HmfFourBar::new(RodCrank::THESIS));
    let dual = Drivetrain::DualFourBar(DualFourBar::new(RodCrank::THESIS));
    for &(q1, q2) in &[(0.0, 0.0), (0.12, -0.07), (-0.18, 0.15)] {
        let d = dual.evaluate(q1, q2).unwrap();
        let (l, r) = (
            hmf.evaluate(q1, 0.0).unwrap(),
            hmf.evaluate(q2, 0.0).unwrap(),
        );
        assert_relative_eq!(d.stroke.x, l.stroke.x, epsilon = 1e-15);
        assert_relative_eq!(d.stroke.y, r.stroke.y, epsilon = 1e-15);
        assert_relative_eq!(d.jacobian[(0, 0)], l.jacobian[(0, 0)], epsilon = 1e-15);
        assert_relative_eq!(d.jacobian[(1, 1)], r.jacobian[(1, 0)], epsilon = 1e-15);
        assert_eq!((d.jacobian[(0, 1)], d.jacobian[(1, 0)]), (0.0, 0.0));
    }
    assert_eq!(dual.dof(), 2);
}

#[test]
fn drivetrain_derivatives_match_finite_differences() {
    let h = 1e-5;
    for d in all_drivetrains() {
        for &(q1, q2) in &[
            (0.0, 0.0),
            (0.12, 0.0),
            (-0.15, 0.03),
            (0.08, -0.04),
            (0.19, 0.02),
        ] {
            let e = d.evaluate(q1, q2).unwrap();
            let f = |a: f64, b: f64| d.evaluate(q1 + a, q2 + b).unwrap().stroke;
            let j_fd = nalgebra::Matrix2::from_columns(&[
                (f(h, 0.0) - f(-h, 0.0)) / (2.0 * h),
                (f(0.0, h) - f(0.0, -h)) / (2.0 * h),
            ]);
            let j_fd = if d.dof() == 1 {
                nalgebra::Matrix2::from_columns(&[j_fd.column(0).into_owned(), Vector2::zeros()])
            } else {
                j_fd
            };
            assert_relative_eq!(e.jacobian, j_fd, epsilon = 1e-7, max_relative = 1e-7);
            let jac = |a: f64, b: f64| d.evaluate(q1 + a, q2 + b).unwrap().jacobian;
            for k in 0..2 {
                for i in 0..2 {
                    let dj_dq1 = (jac(h, 0.0) - jac(-h, 0.0))[(k, i)] / (2.0 * h);
                    let dj_dq2 = (jac(0.0, h) - jac(0.0, -h))[(k, i)] / (2.0 * h);
                    let tol = 1e-5 * (1.0 + e.hessian[k].amax());
                    assert!(
                        (e.hessian[k][(i, 0)] - dj_dq1).abs() < tol,
                        "{} H{k}[{i},0]",
                        d.name()
                    );
                    assert!(
                        (e.hessian[k][(i, 1)] - dj_dq2).abs() < tol,
                        "{} H{k}[{i},1]",
                        d.name()
                    );
                }
            }
            // φ̈ = J q̈ + h(q, q̇): check along a path q(t) = q0 + v t + a t²/2.
            let (v, a) = (Vector2::new(3.0, -0.8), Vector2::new(-5.0, 2.0));
            let q = |t: f64| Vector2::new(q1, q2) + v * t + a * (0.5 * t * t);
            let phi = |t: f64| {
                let qq = q(t);
                d.evaluate(qq[0], qq[1]).unwrap().stroke
            };
            let hh = 2e-5; // the polynomials have large fourth derivatives along this path
            let phi_dd = (phi(hh) - 2.0 * phi(0.0) + phi(-hh)) / (hh * hh);
            let (v, a) = if d.dof() == 1 {
                (Vector2::new(v[0], 0.0), Vector2::new(a[0], 0.0))
            } else {
                (v, a)
            };
            if d.dof() == 2 {
                assert_relative_eq!(
                    phi_dd,
                    e.jacobian * a + e.velocity_product(&v),
                    epsilon = 1e-4,
                    max_relative = 1e-5
                );
            } else {
                let _ = (a, v);
            }
        }
    }
}

/// HMF (§2.3.1): a 400 µm stroke gives about 60° and both wings move together.
#[test]
fn hmf_four_bar_stroke_and_symmetry() {
    let d = Drivetrain::HmfFourBar(HmfFourBar::new(RodCrank::THESIS));
    let up = d.evaluate(0.2, 0.0).unwrap().stroke;
    let down = d.evaluate(-0.2, 0.0).unwrap().stroke;
    let stroke_deg = (down[0] - up[0]).to_degrees();
    assert!((stroke_deg - 60.0).abs() < 1.0, "stroke {stroke_deg}°");
    assert_eq!(up[0], up[1]);
    // q2 has no effect on the 1-DOF HMF.
    assert_eq!(
        d.evaluate(0.1, 0.3).unwrap().stroke,
        d.evaluate(0.1, 0.0).unwrap().stroke
    );
}

/// The nonlinear linkage linearises exactly to eq. 2.15 with T = 1/L3 and L = L0/2,
/// and with a biased pivot the q2 column follows the arm ratio (§2.4.2).
#[test]
fn linkage_linearises_to_eq_2_15() {
    for ratio in [1.0, 0.5, 2.0] {
        let side = RodCrank::THESIS;
        let linkage =
            Drivetrain::LinkageDifferential(LinkageDifferential::new(side, 5.0, ratio).unwrap());
        let linear = Drivetrain::LinearDifferential(
            LinearDifferential::new(1.0 / side.crank(), 2.5, ratio).unwrap(),
        );
        let j_nl = linkage.evaluate(0.0, 0.0).unwrap().jacobian;
        let j_l = linear.evaluate(0.0, 0.0).unwrap().jacobian;
        assert_relative_eq!(j_nl, j_l, epsilon = 1e-12);
        assert_relative_eq!(j_l[(0, 1)] / -j_l[(1, 1)], ratio, epsilon = 1e-12);
    }
}

/// Drag PARITY: q2 = 0 gives exactly symmetric strokes; q1 = 0 gives antisymmetric strokes to
/// first order (the rod-crank is not an odd function, so φL + φR = O(q2²)).
#[test]
fn parity_linkage_symmetric_and_antisymmetric_modes() {
    let d = Drivetrain::LinkageDifferential(LinkageDifferential::thesis());
    for q1 in [-0.2, -0.05, 0.1, 0.2] {
        let s = d.evaluate(q1, 0.0).unwrap().stroke;
        assert_eq!(s[0], s[1]);
    }
    let rest = d.evaluate(0.0, 0.0).unwrap();
    assert_relative_eq!(
        rest.jacobian[(0, 1)],
        -rest.jacobian[(1, 1)],
        max_relative = 1e-12
    );
    let even_curvature = 0.5 * (rest.hessian[0][(1, 1)] + rest.hessian[1][(1, 1)]);
    for q2 in [-0.06, -0.01, 0.02, 0.05] {
        let e = d.evaluate(0.0, q2).unwrap();
        assert!(e.stroke[0] * e.stroke[1] < 0.0);
        // The symmetric residual is exactly the quadratic term of the expansion, up to O(q2³).
        let residual = e.stroke[0] + e.stroke[1] - even_curvature * q2 * q2;
        assert!(
            residual.abs() < 50.0 * q2.abs().powi(3),
            "q2 {q2}: residual {residual}"
        );
    }
    // ±200 µm gives about ±30° with the thesis lengths (see the module docs on ±35°).
    let up = d.evaluate(0.2, 0.0).unwrap().stroke[0].to_degrees();
    let down = d.evaluate(-0.2, 0.0).unwrap().stroke[0].to_degrees();
    assert!(
        (up + 30.0).abs() < 1.0 && (down - 30.0).abs() < 1.0,
        "{up} {down}"
    );
}

#[test]
fn drivetrain_errors_are_typed() {
    assert_eq!(
        RodCrank::new(-1.0, 1.0).unwrap_err().field(),
        Some("crank_mm")
    );
    assert_eq!(
        LinkageDifferential::new(RodCrank::THESIS, 5.0, 0.0)
            .unwrap_err()
            .field(),
        Some("arm_ratio")
    );
    let d = Drivetrain::LinkageDifferential(LinkageDifferential::thesis());
    assert!(matches!(
        d.evaluate(2.0, 0.0),
        Err(Error::OutOfDomain { .. })
    ));
    assert!(matches!(
        d.evaluate(0.0, 2.0),
        Err(Error::InvalidParameter { .. })
    ));
    assert!(matches!(
        d.evaluate(f64::NAN, 0.0),
        Err(Error::InvalidParameter { .. })
    ));
}

/// Inputs that would overflow the linear map are rejected at the argument (issue 14).
#[test]
fn drivetrain_rejects_implausible_inputs() {
    let d = Drivetrain::LinearDifferential(LinearDifferential::new(3.05, 2.5, 1.0).unwrap());
    assert_eq!(d.evaluate(1e308, 0.0).unwrap_err().field(), Some("q1"));
    assert_eq!(d.evaluate(0.0, -1e300).unwrap_err().field(), Some("q2"));
    assert_eq!(d.evaluate(f64::NAN, 0.0).unwrap_err().field(), Some("q1"));
    let e = d.evaluate(0.2, 0.1).unwrap();
    assert!(e.stroke.iter().all(|s| s.is_finite()));
}

/// `RodCrank::reach` (triangle inequality) against the solver: just below the closed-form
/// lift the linkage evaluates, just above it is out of its domain, for several proportions.
#[test]
fn rod_crank_reach_is_where_the_linkage_stops_solving() {
    for (crank, rod) in [(0.4, 0.8), (0.4, 1.0), (0.3, 2.0), (1.0, 0.9)] {
        let side = RodCrank::new(crank, rod).unwrap();
        let reach = side.reach();
        assert!((reach - ((rod * rod + 2.0 * rod * crank).sqrt() - rod)).abs() < 1e-15);
        let d = Drivetrain::HmfFourBar(HmfFourBar::new(side));
        assert!(
            d.evaluate(reach * (1.0 - 1e-6), 0.0).is_ok(),
            "{crank} {rod}"
        );
        let err = d.evaluate(reach * (1.0 + 1e-6), 0.0).unwrap_err();
        assert_eq!(err.kind(), "OutOfDomain", "{err}");
        assert_eq!(d.rod_crank(), Some(side));
    }
}

/// An attributed error keeps its kind and names the field; `at_index` and `in_field` locate it.
#[test]
fn attributed_errors_keep_their_kind_and_name_the_field() {
    let base = Error::OutOfDomain {
        what: "x".into(),
        detail: "y".into(),
    };
    let e = base.clone().attributed("q1", 2.0, "at most 1 mm");
    assert_eq!(e.kind(), "OutOfDomain");
    assert_eq!(e.field(), Some("q1"));
    assert_eq!(e.cause(), &base);
    assert!(
        e.to_string()
            .contains("most responsible: `q1` = 2: must be at most 1 mm")
    );
    assert_eq!(e.clone().at_index(3, None).field(), Some("q1[3]"));
    assert_eq!(e.in_field("drivetrain").field(), Some("drivetrain.q1"));
}
