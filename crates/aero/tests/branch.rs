//! The blade-element model's smooth branches (event location, issue 17): equal to the model on
//! their own side, and smooth across the switching surfaces where the model itself jumps.

use nalgebra::{Matrix3, Vector3};
use paritysim_aero::{
    AeroLoads, BladeElementModel, Branch, CoefficientSet, NormalForceLaw, Omegas, WhitneyWood2010,
};

fn model(coefficients: CoefficientSet) -> BladeElementModel {
    let o = Omegas::new(46.8, 0.587, 17.5, 0.712)
        .unwrap()
        .with_force(3.1)
        .unwrap();
    BladeElementModel::new(o, coefficients).unwrap()
}

fn flat(l: &AeroLoads) -> [f64; 9] {
    let t = l.torque();
    [
        l.lift.x, l.lift.y, l.lift.z, l.drag.x, l.drag.y, l.drag.z, t.x, t.y, t.z,
    ]
}

fn rot() -> Matrix3<f64> {
    nalgebra::Rotation3::from_euler_angles(0.3, -0.2, 0.7).into_inner()
}

#[test]
fn a_branch_on_its_own_side_is_the_model() {
    for (set, law) in [
        (CoefficientSet::default(), NormalForceLaw::Coefficient),
        (CoefficientSet::default(), NormalForceLaw::Unit),
        (
            CoefficientSet::WhitneyWood2010(WhitneyWood2010::default()),
            NormalForceLaw::Coefficient,
        ),
    ] {
        let m = model(set).with_normal_force_law(law);
        for w in [
            Vector3::new(0.3, 0.2, -0.1),
            Vector3::new(-0.3, 0.05, 0.4),
            Vector3::new(0.01, -0.5, 0.2),
            Vector3::new(-0.2, -0.1, -0.3),
        ] {
            let a = flat(&m.loads_omega(&w, &rot()).unwrap());
            let b = flat(&m.loads_omega_branch(&w, &rot(), Branch::of(&w)).unwrap());
            for (x, y) in a.iter().zip(&b) {
                assert!(
                    (x - y).abs() <= 1e-14 * x.abs().max(1.0),
                    "{w:?}: {a:?} vs {b:?}"
                );
            }
            assert_eq!(
                m.moments_omega(&w),
                m.moments_omega_branch(&w, Branch::of(&w))
            );
            // The lean wing-frame wrench: the same loads rotated back.
            let loads = m.loads_omega(&w, &rot()).unwrap();
            let (f6, t6) = m.wing_frame_wrench_branch(&w, Branch::of(&w)).unwrap();
            let (f, t) = (rot() * f6, rot() * t6);
            let (f_ref, t_ref) = (loads.lift + loads.drag, loads.torque());
            assert!((f - f_ref).amax() <= 1e-13 * f_ref.amax(), "{f} vs {f_ref}");
            assert!((t - t_ref).amax() <= 1e-13 * t_ref.amax(), "{t} vs {t_ref}");
        }
    }
}

/// Largest second difference `|f(+e) − 2 f(0) + f(−e)|` and jump `|f(+e) − f(−e)|` of the
/// loads along `dir` through `at`, on the branch of `at + e dir` or of the model.
fn differences(m: &BladeElementModel, at: Vector3<f64>, dir: Vector3<f64>, e: f64) -> [f64; 3] {
    let branch = Branch::of(&(at + dir * e));
    let on = |w: Vector3<f64>| flat(&m.loads_omega_branch(&w, &rot(), branch).unwrap());
    let raw = |w: Vector3<f64>| flat(&m.loads_omega(&w, &rot()).unwrap());
    let (p, z, n) = (on(at + dir * e), on(at), on(at - dir * e));
    let (rp, rn) = (raw(at + dir * e), raw(at - dir * e));
    let mut out = [0.0f64; 3];
    for i in 0..9 {
        out[0] = out[0].max((p[i] - 2.0 * z[i] + n[i]).abs());
        out[1] = out[1].max((p[i] - n[i]).abs());
        out[2] = out[2].max((rp[i] - rn[i]).abs());
    }
    out
}

#[test]
fn branches_are_smooth_where_the_model_jumps() {
    let m = model(CoefficientSet::default());
    let e = 1e-4;
    // Stroke reversal ω_x = 0 (both signs of ω_y), α = 90° (ω_y = 0), ω_z = 0.
    for (at, dir) in [
        (Vector3::new(0.0, 0.4, 0.1), Vector3::x()),
        (Vector3::new(0.0, -0.4, 0.1), Vector3::x()),
        (Vector3::new(0.4, 0.0, 0.1), Vector3::y()),
        (Vector3::new(0.4, 0.2, 0.0), Vector3::z()),
    ] {
        let [second, jump_branch, jump_model] = differences(&m, at, dir, e);
        println!("{at:?}: second {second:.2e}, branch {jump_branch:.2e}, model {jump_model:.2e}");
        // A smooth branch: second differences O(e²), differences O(e).
        assert!(second < 1e-5, "{at:?}: second difference {second}");
        assert!(jump_branch < 1e3 * e, "{at:?}: branch jump {jump_branch}");
        if dir != Vector3::z() {
            // The model itself jumps (C_N(0) ≠ 0; C_L(90°) ≠ 0 mirrored).
            assert!(
                jump_model > 10.0 * jump_branch,
                "{at:?}: model jump {jump_model}"
            );
        }
    }
    let w = Vector3::new(0.1, 0.2, 0.3);
    assert_eq!(m.switching_functions(&w), [0.1, 0.2, 0.3]);
    let ww = model(CoefficientSet::WhitneyWood2010(WhitneyWood2010::default()));
    assert_eq!(ww.switching_functions(&w), [0.1, 1.0, 0.3]);
}

/// The closed-form slopes of the coefficient branches equal central differences of the
/// branches (both built-in fits, both sides of α = π/2, continued past it), and the stroke-plane
/// moments' derivatives by `(φ̇, ψ, ψ̇)` equal central differences of the torque the stroke-plane
/// right-hand side takes (closed form on the own side, the `atan2` form past a surface), for
/// both force laws.
#[test]
fn coefficient_slopes_and_stroke_plane_moment_derivatives_equal_central_differences() {
    use paritysim_aero::CoefficientModel;
    let sets = [
        CoefficientSet::default(),
        CoefficientSet::WhitneyWood2010(WhitneyWood2010::default()),
    ];
    for set in sets {
        for k in 0..=40 {
            let alpha = -0.2 + 3.5 * k as f64 / 40.0;
            for below in [true, false] {
                let ((cl, cd), (dcl, dcd)) = set.lift_drag_slope_branch(alpha, below);
                assert_eq!((cl, cd), set.lift_drag_branch(alpha, below));
                let h = 1e-6;
                let (lp, dp) = set.lift_drag_branch(alpha + h, below);
                let (lm, dm) = set.lift_drag_branch(alpha - h, below);
                assert!(
                    (dcl - (lp - lm) / (2.0 * h)).abs() < 1e-8,
                    "{set:?} C_L' at {alpha}"
                );
                assert!(
                    (dcd - (dp - dm) / (2.0 * h)).abs() < 1e-8,
                    "{set:?} C_D' at {alpha}"
                );
            }
        }
    }
    let torque = |m: &BladeElementModel, v: [f64; 3], branch: Option<Branch>| {
        let (s, c) = v[1].sin_cos();
        let omega = Vector3::new(c * v[0], -s * v[0], v[2]);
        // The stroke-plane right-hand side's rule: the closed form on the branch's own side.
        let own = branch.is_none_or(|b| {
            b.chordwise_positive == (omega.x >= 0.0) && b.normal_positive == (omega.y >= 0.0)
        });
        match branch {
            Some(b) if !(c > 0.0 && own) => m.moments_omega_branch(&omega, b).torque(),
            _ => m
                .moments_stroke_plane(v[0], v[1], (s, c), v[2], branch)
                .torque(),
        }
    };
    let mut checked = 0;
    for set in sets {
        for law in [NormalForceLaw::Coefficient, NormalForceLaw::Unit] {
            let m = model(set).with_normal_force_law(law);
            for v in [
                [2.1f64, 0.4, -1.3],
                [-3.0, -0.7, 0.9],
                [0.8, 0.05, 2.0],
                [-1.2, 0.3, -0.4],
            ] {
                let (s, c) = v[1].sin_cos();
                let own = Branch::of(&Vector3::new(c * v[0], -s * v[0], v[2]));
                let past = Branch {
                    chordwise_positive: !own.chordwise_positive,
                    normal_positive: !own.normal_positive,
                    spanwise_positive: own.spanwise_positive,
                };
                for branch in [None, Some(own), Some(past)] {
                    let (t0, slopes) = m
                        .moments_stroke_plane_jacobian(v[0], v[1], (s, c), v[2], branch)
                        .expect("cos ψ > 0");
                    let reference = torque(&m, v, branch);
                    assert!((t0 - reference).norm() <= 1e-12 * (1.0 + reference.norm()));
                    for (j, slope) in slopes.iter().enumerate() {
                        let h = 1e-6;
                        let (mut plus, mut minus) = (v, v);
                        plus[j] += h;
                        minus[j] -= h;
                        let difference =
                            (torque(&m, plus, branch) - torque(&m, minus, branch)) / (2.0 * h);
                        let size = 1.0 + difference.norm();
                        assert!(
                            (slope - difference).norm() <= 1e-7 * size,
                            "{set:?} {law:?} {v:?} {branch:?} d/d{j}: {slope:?} vs {difference:?}"
                        );
                        checked += 1;
                    }
                }
            }
        }
    }
    assert_eq!(checked, 2 * 2 * 4 * 3 * 3);
}
