//! The closed-form wing terms (stroke only, stroke plane, free deviation) against the general
//! App. A terms.

use super::*;

/// The closed-form stroke-only wing terms equal the general shoulder terms at θ = ψ = 0.
#[test]
fn stroke_terms_equal_general_terms_on_the_stroke_plane() {
    for (a2, a3) in [(90.0, 0.0), (90.0, 30.0), (90.0, 60.0)] {
        let blade = paritysim_aero::BladeElementModel::new(
            paritysim_aero::Omegas::new(46.8, 0.59, 17.5, 0.71).unwrap(),
            paritysim_aero::CoefficientSet::default(),
        )
        .unwrap();
        let wing = Wing::new(
            shoulder(a2, a3),
            full_inertia(),
            springs([3.0, 0.0, 0.0, 2.0, 0.0, 1.0]),
            WingAero::BladeElement(blade),
        )
        .unwrap();
        for (phi, rate) in [(0.3, 0.7), (-0.9, -0.2), (1.2, 0.05), (0.0, 0.0)] {
            let fast = wing
                .stroke_plane_terms(&Vector3::new(phi, 0.0, 0.0), &Vector3::new(rate, 0.0, 0.0));
            let general = wing
                .terms(&Vector3::new(phi, 0.0, 0.0), &Vector3::new(rate, 0.0, 0.0))
                .unwrap();
            let tol = 1e-12;
            assert_relative_eq!(fast.mass, general.mass, epsilon = tol);
            assert_relative_eq!(fast.coriolis, general.coriolis, epsilon = tol);
            assert_relative_eq!(fast.spring, general.spring, epsilon = tol);
            assert_relative_eq!(fast.aero, general.aero, epsilon = tol);
            assert_relative_eq!(fast.aero_frame6, general.aero_frame6, epsilon = tol);
            assert_relative_eq!(fast.j6, general.j6, epsilon = tol);
            assert_relative_eq!(fast.omega, general.omega, epsilon = tol);
            assert_relative_eq!(fast.jdot_pdot, general.jdot_pdot, epsilon = tol);
            assert_relative_eq!(fast.rotation, general.rotation, epsilon = tol);
            assert_relative_eq!(fast.potential, general.potential, epsilon = tol);
            assert_relative_eq!(fast.kinetic, general.kinetic, epsilon = tol);
            assert!(general.theta_w.abs() < tol);
        }
    }
}

/// The closed-form stroke-plane terms (θ = θ̇ = 0) equal the general shoulder terms.
#[test]
fn stroke_plane_terms_equal_general_terms() {
    use paritysim_dynamics::TunableHinge;
    for (a2, a3) in [(90.0, 0.0), (90.0, 40.0)] {
        let blade = paritysim_aero::BladeElementModel::new(
            paritysim_aero::Omegas::new(46.8, 0.59, 17.5, 0.71).unwrap(),
            paritysim_aero::CoefficientSet::default(),
        )
        .unwrap();
        let wing = Wing::new(
            shoulder(a2, a3),
            full_inertia(),
            springs([3.0, 0.0, 0.0, 2.0, 0.0, 1.5]),
            WingAero::BladeElement(blade),
        )
        .unwrap()
        .with_tunable_hinge(TunableHinge::new(2.0, 0.5, 3.0).unwrap());
        assert!(wing.has_closed_form_stroke_plane());
        for (phi, psi, rate, spin) in [
            (0.3, 0.7, 0.6, -0.4),
            (-0.9, -1.1, -0.2, 1.3),
            (1.2, 0.1, 0.05, 0.0),
        ] {
            let (p, v) = (Vector3::new(phi, 0.0, psi), Vector3::new(rate, 0.0, spin));
            let fast = wing.stroke_plane_terms(&p, &v);
            let general = wing.terms(&p, &v).unwrap();
            let tol = 1e-12;
            assert_relative_eq!(fast.mass, general.mass, epsilon = tol);
            assert_relative_eq!(fast.coriolis, general.coriolis, epsilon = tol);
            assert_relative_eq!(fast.spring, general.spring, epsilon = tol);
            assert_relative_eq!(fast.aero, general.aero, epsilon = tol);
            assert_relative_eq!(fast.j6, general.j6, epsilon = tol);
            assert_relative_eq!(fast.jdot_pdot, general.jdot_pdot, epsilon = tol);
            assert_relative_eq!(fast.rotation, general.rotation, epsilon = tol);
            assert_relative_eq!(fast.potential, general.potential, epsilon = tol);
            assert_relative_eq!(fast.kinetic, general.kinetic, epsilon = tol);
        }
    }
}

/// The closed-form free-deviation terms (α2 = 90°, α3 = 0, any θ) equal the general shoulder
/// terms (joint-angle solve of eqs. 2.11–2.13, closure partials), every field.
#[test]
fn free_deviation_terms_equal_general_terms() {
    use paritysim_dynamics::TunableHinge;
    let blade = paritysim_aero::BladeElementModel::new(
        paritysim_aero::Omegas::new(46.8, 0.59, 17.5, 0.71).unwrap(),
        paritysim_aero::CoefficientSet::default(),
    )
    .unwrap();
    let wing = Wing::new(
        shoulder(90.0, 0.0),
        full_inertia(),
        springs([3.0, 0.0, 0.0, 2.0, 0.0, 1.5]),
        WingAero::BladeElement(blade),
    )
    .unwrap()
    .with_tunable_hinge(TunableHinge::new(2.0, 0.5, 3.0).unwrap());
    assert!(wing.has_closed_form_free_deviation());
    let drag_wing = Wing::new(
        shoulder(90.0, 0.0),
        full_inertia(),
        springs([3.0, 0.0, 0.0, 2.0, 0.0, 1.5]),
        drag(31.3),
    )
    .unwrap();
    let mut checked = 0;
    for wing in [&wing, &drag_wing] {
        for k in 0..300 {
            let x = k as f64;
            // Strokes to ±80°, deviations to ±60°, rotations to ±70°, rates of both signs.
            let p = Vector3::new(
                1.4 * (0.37 * x).sin(),
                1.05 * (0.61 * x).cos(),
                1.2 * (1.3 * x).sin(),
            );
            let v = Vector3::new(
                0.8 * (0.71 * x).cos(),
                -0.5 * (0.23 * x).sin(),
                1.5 * (2.1 * x).cos(),
            );
            let fast = wing.free_deviation_terms(&p, &v).unwrap();
            let general = wing.terms(&p, &v).unwrap();
            let tol = 1e-12;
            assert_relative_eq!(fast.mass, general.mass, epsilon = tol, max_relative = tol);
            assert_relative_eq!(
                fast.coriolis,
                general.coriolis,
                epsilon = tol,
                max_relative = tol
            );
            assert_relative_eq!(
                fast.spring,
                general.spring,
                epsilon = tol,
                max_relative = tol
            );
            assert_relative_eq!(fast.aero, general.aero, epsilon = tol, max_relative = tol);
            assert_relative_eq!(
                fast.aero_frame6,
                general.aero_frame6,
                epsilon = tol,
                max_relative = tol
            );
            assert_relative_eq!(fast.j6, general.j6, epsilon = tol, max_relative = tol);
            assert_relative_eq!(fast.omega, general.omega, epsilon = tol, max_relative = tol);
            assert_relative_eq!(
                fast.jdot_pdot,
                general.jdot_pdot,
                epsilon = tol,
                max_relative = tol
            );
            assert_relative_eq!(
                fast.rotation,
                general.rotation,
                epsilon = tol,
                max_relative = tol
            );
            assert_relative_eq!(
                fast.theta_w,
                general.theta_w,
                epsilon = tol,
                max_relative = tol
            );
            assert_relative_eq!(
                fast.potential,
                general.potential,
                epsilon = tol,
                max_relative = tol
            );
            assert_relative_eq!(
                fast.kinetic,
                general.kinetic,
                epsilon = tol,
                max_relative = tol
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 600);
    // Other shoulders keep the general terms.
    let other = Wing::new(
        shoulder(90.0, 30.0),
        full_inertia(),
        springs([0.0; 6]),
        drag(31.3),
    )
    .unwrap();
    assert!(!other.has_closed_form_free_deviation());
}
