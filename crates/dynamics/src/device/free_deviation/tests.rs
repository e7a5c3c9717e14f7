//! The lean free-deviation right-hand side against the general null-space path.

use super::*;
use crate::device::switches::branches;
use crate::device::switches::tests::{
    assert_implausible_coordinates_get_the_general_error, device, relative_difference, states,
};
use crate::integrate::{MAX_SWITCHES, OdeSystem, Sides};

/// The lean right-hand side (closed-form wing terms on the `n` coordinates, `J⁻¹` of the
/// linear map) equals the general one (`evaluate_on`: the Newton inverse of the drivetrain,
/// the 6-vector `p̈`) to 1e-12 relative, work integrals included: over states on both sides
/// of every blade-element switch, with no branch, on each state's own sides and on every
/// held side of each switching function (the continued branches event location evaluates).
#[test]
fn lean_free_deviation_rhs_equals_the_null_space_path() {
    for configuration in ["lift_parity", "dual_parity"] {
        let d = device(configuration);
        let lean = d.free_deviation_rhs.expect("a free-deviation device");
        let ys = states(&d);
        assert!(ys.len() > 20, "{} states", ys.len());
        let mut worst: f64 = 0.0;
        let mut compared = 0;
        for (k, y) in ys.iter().enumerate() {
            let t = 0.37 * k as f64;
            let (mut fast, mut general) = (State::default(), State::default());
            d.rhs(t, y, &mut fast).unwrap();
            d.rhs_null_space(t, y, &mut general).unwrap();
            worst = worst.max(relative_difference(&fast, &general));
            let mut g = [0.0; MAX_SWITCHES];
            d.switches(t, y, &mut g).unwrap();
            let own = Sides::of(&g[..6]);
            for flip in 0..=6 {
                let sides = if flip == 6 {
                    own
                } else {
                    own.with(flip, !own.positive(flip))
                };
                let b = Some(branches(sides));
                d.rhs_free_deviation(&lean, t, y, b, &mut fast).unwrap();
                d.rhs_null_space_on(t, y, b, &mut general).unwrap();
                worst = worst.max(relative_difference(&fast, &general));
                compared += 1;
            }
        }
        eprintln!("{configuration}: lean vs general {worst:e} over {compared} held sides");
        assert!(worst < 1e-12, "{configuration}: lean vs general {worst:e}");
    }
}

/// The §3.4 stroke-plane device (θ held) keeps its own lean path, and an implausible
/// drivetrain coordinate of a free-deviation device gets the general path's error naming it.
#[test]
fn lean_path_applies_to_free_deviation_only_and_reports_implausible_coordinates() {
    let d = device("drag_parity");
    assert!(d.free_deviation_rhs.is_none() && d.stroke_plane_rhs.is_some());
    let d = device("lift_parity");
    assert_implausible_coordinates_get_the_general_error(&d);
}
