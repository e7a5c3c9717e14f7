//! continuation tests (submodule of the one dynamics integration binary): a device's periodic
//! orbit continued in a parameter, checked against brute-force Floquet analysis.

use paritysim_continuation::{BifurcationKind, ContinuationOptions, Stability, StopReason};
use paritysim_dynamics::continuation::continue_balance_spring;
use paritysim_dynamics::stability::{ShootingOptions, floquet, with_balance_spring};

use super::*;

/// The §3.3 Drag PARITY device (rod-crank linkage, both wings Control) at balance spring `k2`.
fn section_3_3(k2: f64) -> Device {
    two_wing_device(
        [
            fixed_wing(WingAero::stroke_drag(31.3, 3.4609).unwrap()),
            fixed_wing(WingAero::stroke_drag(31.3, 3.4609).unwrap()),
        ],
        "drag_parity_fixed",
        Drivetrain::LinkageDifferential(LinkageDifferential::thesis()),
        k2,
        Actuator::thesis(Waveform::sine(100.0, 110.0, 0.0, 0.0).unwrap()),
        Formulation::Auto,
    )
}

/// docs/findings.md: the whippletree mode of the §3.3 linkage is stable only above K2 ≈ 377.
/// Continuing the symmetric orbit down in K2 finds where it loses stability as a branch point
/// (symmetry breaking: a real multiplier through +1, the branch does not turn), and brute-force
/// Floquet analysis on either side of it agrees.
#[test]
fn whippletree_stability_boundary_by_continuation_matches_brute_force() {
    let shooting = ShootingOptions {
        rtol: 1e-11,
        atol: 1e-13,
        ..ShootingOptions::default()
    };
    let spec = section_3_3(1000.0).spec().clone();
    let mut options = ContinuationOptions::new(0, 100.0);
    options.parameter_scale = 100.0;
    options.initial_step = 0.5;
    options.max_step = 1.0;
    options.tolerance = 1e-9;
    let branch = continue_balance_spring(&spec, 1000.0, &options, &shooting).unwrap();
    assert_eq!(branch.stop_reason, StopReason::ReachedStop);
    let kinds: Vec<_> = branch
        .bifurcations
        .iter()
        .map(|b| (b.kind, b.point.parameter))
        .collect();
    assert_eq!(kinds.len(), 1, "{kinds:?}");
    let boundary = &branch.bifurcations[0];
    assert_eq!(boundary.kind, BifurcationKind::BranchPoint);
    assert!(boundary.located);
    let k_star = boundary.point.parameter;
    assert!((300.0..450.0).contains(&k_star), "K2* = {k_star}");
    assert_eq!(branch.points.first().unwrap().stability, Stability::Stable);
    assert_eq!(branch.points.last().unwrap().stability, Stability::Unstable);
    // Brute force, independently of the continuation: Newton shooting and the monodromy at
    // K2* ± 2 mN·mm/rad.
    let radius = |k2: f64| {
        let device = Device::new(with_balance_spring(&spec, k2).unwrap()).unwrap();
        floquet(&device, &shooting).unwrap().spectral_radius()
    };
    assert!(
        radius(k_star - 2.0) > 1.0,
        "below K2* the orbit must be unstable"
    );
    assert!(
        radius(k_star + 2.0) < 1.0,
        "above K2* the orbit must be stable"
    );
}
