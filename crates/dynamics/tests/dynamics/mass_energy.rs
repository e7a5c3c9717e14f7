//! The equations' mass matrix and Coriolis terms against Christoffel symbols, and energy:
//! conservation of an unforced wing, the actuator's work against dissipation, the tunable
//! hinge's forces as the gradient of its energy.

use super::*;

/// Angular velocity in frame 6 from finite differences of R_6^1 (independent of J6).
fn omega_fd(sh: &SphericalShoulder, p: &Vector3<f64>, v: &Vector3<f64>) -> Vector3<f64> {
    let h = 1e-6;
    let r = |s: f64| {
        sh.pose(p.x + v.x * s, p.y + v.y * s, p.z + v.z * s)
            .unwrap()
            .link_rotations[5]
    };
    let w = r(0.0).transpose() * (r(h) - r(-h)) / (2.0 * h);
    Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)])
}

/// `M = J6ᵀ I J6` with J6's columns from finite-differenced rotations.
fn mass_fd(sh: &SphericalShoulder, inertia: &Matrix3<f64>, p: &Vector3<f64>) -> Matrix3<f64> {
    let j = Matrix3::from_columns(&[
        omega_fd(sh, p, &Vector3::x()),
        omega_fd(sh, p, &Vector3::y()),
        omega_fd(sh, p, &Vector3::z()),
    ]);
    j.transpose() * inertia * j
}

#[test]
fn mass_and_coriolis_match_christoffel_symbols() {
    let inertia = full_inertia();
    for (a2, a3) in [(90.0, 0.0), (120.0, 60.0)] {
        let sh = shoulder(a2, a3);
        let wing = Wing::new(sh, inertia, [JointSpring::default(); 6], WingAero::None).unwrap();
        let states = [
            (Vector3::new(0.3, -0.2, 0.5), Vector3::new(0.7, -0.4, 1.3)),
            (Vector3::new(-0.6, 0.35, -0.9), Vector3::new(-1.1, 0.5, 0.2)),
            (Vector3::new(0.1, 0.5, 1.2), Vector3::new(0.3, 0.9, -0.8)),
        ];
        for (p, v) in states {
            let terms = wing.terms(&p, &v).unwrap();
            let m_fd = mass_fd(&sh, &inertia, &p);
            assert_relative_eq!(terms.mass, m_fd, epsilon = 1e-6, max_relative = 1e-6);
            // c_i = Σ_jk Γ_ijk v_j v_k with Γ from finite differences of our own M(p), which the
            // line above ties to the independent M.
            let h = 1e-5;
            let dm: Vec<Matrix3<f64>> = (0..3)
                .map(|k| {
                    let e = Vector3::ith(k, h);
                    (wing.terms(&(p + e), &v).unwrap().mass
                        - wing.terms(&(p - e), &v).unwrap().mass)
                        / (2.0 * h)
                })
                .collect();
            let mut c = Vector3::zeros();
            for i in 0..3 {
                for j in 0..3 {
                    for k in 0..3 {
                        c[i] += 0.5 * (dm[k][(i, j)] + dm[j][(i, k)] - dm[i][(j, k)]) * v[j] * v[k];
                    }
                }
            }
            assert_relative_eq!(terms.coriolis, c, epsilon = 1e-6, max_relative = 1e-6);
        }
    }
}

#[test]
fn unforced_wing_conserves_energy_over_100_oscillations() {
    use paritysim_dynamics::integrate::{Integrator, Method, RungeKutta};
    let device = free_wing_device(Formulation::NullSpace);
    let p0 = Vec6::new(0.4, -0.2, 0.6, 0.0, 0.0, 0.0);
    let v0 = Vec6::new(0.1, 0.05, -0.2, 0.0, 0.0, 0.0);
    let mut y = device.state_from(&p0, &v0).unwrap();
    let energy = |y: &paritysim_dynamics::State, t: f64| {
        let (p, v) = device.coordinates(y).unwrap();
        device.energy(&device.evaluate(t, &p, &v).unwrap())
    };
    let e0 = energy(&y, 0.0);
    let rk = RungeKutta::new(Method::Dop853, 1e-13, 1e-15, 1_000_000).unwrap();
    // Slowest mode: φ with I ≈ 29 mg·mm² and k ≈ 20 mN·mm/rad: period ≈ 7.6 ms. Each segment ends
    // on a solver step (dense output between steps is less accurate than the steps themselves).
    let (segment, mut t, mut worst, mut phi_max) = (7.6, 0.0, 0.0f64, 0.0f64);
    for _ in 0..100 {
        y = rk
            .integrate(&device, t, &y, t + segment, &[t + segment])
            .unwrap()[0];
        t += segment;
        worst = worst.max((energy(&y, t) - e0).abs() / e0);
        phi_max = phi_max.max(device.coordinates(&y).unwrap().0[0].abs());
    }
    assert!(worst < 1e-9, "relative energy drift {worst:e}");
    assert!(phi_max > 0.1, "it really oscillates");
}

#[test]
fn actuator_work_equals_dissipation_plus_energy_change() {
    let device = parity_device(18.75, 5.0, "drag_parity_fixed", Formulation::NullSpace);
    let options = SimulationOptions {
        rtol: 1e-12,
        atol: 1e-13,
        max_cycles: 3,
        min_cycles: 3,
        ..Default::default()
    };
    let r = simulate(&device, &options).unwrap();
    let t = &r.trajectory;
    let energy = t.column("mechanical_energy").unwrap();
    let w_act = *t.column("work_actuator").unwrap().last().unwrap();
    let w_aero = *t.column("work_aero").unwrap().last().unwrap();
    let delta_e = energy.last().unwrap() - energy[0];
    let balance = (w_act + w_aero - delta_e).abs() / w_act.abs();
    assert!(
        w_aero < 0.0 && w_act > 0.0,
        "aero dissipates, actuator injects: {w_act} {w_aero}"
    );
    assert!(balance < 1e-6, "energy balance residual {balance:e}");
}

/// The tunable hinge (§2.5.1): its generalised forces are the gradient of its energy, checked
/// by finite differences and by energy conservation of an undamped wing.
#[test]
fn tunable_hinge_forces_are_the_gradient_of_its_energy() {
    use paritysim_dynamics::TunableHinge;
    let hinge = TunableHinge::new(2.0, 1.5, 4.0).unwrap();
    let wing = Wing::new(
        shoulder(90.0, 0.0),
        full_inertia(),
        springs([5.0, 0.0, 0.0, 8.0, 0.0, 0.0]),
        WingAero::None,
    )
    .unwrap()
    .with_tunable_hinge(hinge);
    let h = 1e-6;
    for p in [Vector3::new(0.2, 0.3, -0.5), Vector3::new(-0.4, -0.2, 0.8)] {
        let v = Vector3::zeros();
        let t = wing.terms(&p, &v).unwrap();
        for k in 0..3 {
            let e = Vector3::ith(k, h);
            let dv = (wing.terms(&(p + e), &v).unwrap().potential
                - wing.terms(&(p - e), &v).unwrap().potential)
                / (2.0 * h);
            assert_relative_eq!(t.spring[k], dv, epsilon = 1e-7, max_relative = 1e-7);
        }
    }
    assert!(
        TunableHinge::new(1.0, 3.0, 1.0).is_err(),
        "k(theta) would go negative"
    );
    use paritysim_dynamics::integrate::{Integrator, Method, RungeKutta};
    let device = Device::new(DeviceSpec {
        wings: vec![wing],
        constraints: Constraints::none(3).unwrap(),
        transmission: None,
        actuator: None,
        formulation: Formulation::NullSpace,
    })
    .unwrap();
    let mut y = device
        .state_from(&Vec6::new(0.3, 0.2, 0.5, 0.0, 0.0, 0.0), &Vec6::zeros())
        .unwrap();
    let energy = |y: &paritysim_dynamics::State| {
        let (p, v) = device.coordinates(y).unwrap();
        device.energy(&device.evaluate(0.0, &p, &v).unwrap())
    };
    let e0 = energy(&y);
    let rk = RungeKutta::new(Method::Dop853, 1e-12, 1e-14, 1_000_000).unwrap();
    let mut worst = 0.0f64;
    for k in 0..20 {
        y = rk
            .integrate(
                &device,
                k as f64 * 10.0,
                &y,
                (k + 1) as f64 * 10.0,
                &[(k + 1) as f64 * 10.0],
            )
            .unwrap()[0];
        worst = worst.max((energy(&y) - e0).abs() / e0);
    }
    assert!(worst < 1e-8, "relative energy drift {worst:e}");
}
