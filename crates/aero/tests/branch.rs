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
