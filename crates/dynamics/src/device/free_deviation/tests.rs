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
        let lean = d
            .form
            .free_deviation()
            .expect("a free-deviation device")
            .clone();
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
    assert!(d.form.free_deviation().is_none() && d.form.stroke_plane().is_some());
    let d = device("lift_parity");
    assert_implausible_coordinates_get_the_general_error(&d);
}

/// The §2.5 Lift PARITY fixture with deviation springs of `stiffness` (mN·mm/rad) on both
/// wings, driven at `amplitude_v` about `offset_v` (DC ignored).
fn lift_variant(stiffness: f64, amplitude_v: f64, offset_v: f64) -> Device {
    use crate::{Actuator, DcOffset, JointSpring, Waveform, Wing};
    let mut spec = device("lift_parity").spec().clone();
    spec.actuator = Some(
        Actuator::new(
            crate::actuator::THESIS_FORCE_PER_VOLT,
            crate::actuator::THESIS_STIFFNESS,
            Waveform::sine(amplitude_v, 110.0, offset_v, 0.0).unwrap(),
            DcOffset::Ignore,
        )
        .unwrap(),
    );
    for w in spec.wings.iter_mut() {
        let mut springs = *w.springs();
        springs[3] = JointSpring::linear(stiffness, 0.0).unwrap();
        let hinge = *w.tunable_hinge().unwrap();
        *w = Wing::new(
            *w.shoulder(),
            w.structural_inertia(),
            springs,
            w.aero().clone(),
        )
        .unwrap()
        .with_tunable_hinge(hinge);
    }
    Device::new(spec).unwrap()
}

/// A sweep of the §2.5 Lift PARITY along the deviation stiffness (8 → 12 mN·mm/rad, drive
/// 85 V + 85 V sin): its points are not continued from their neighbours (the free-deviation
/// devices have coexisting stable orbits, docs/findings.md §23, so a chain could land on the
/// neighbour's), and each row is its own cold run, bit for bit. Its cold runs approach their
/// orbits alternating (a multiplier in (−1, 0)) and end by one-cycle shooting (their
/// multipliers reported; docs/findings.md §22).
#[test]
fn a_lift_parity_sweep_row_is_its_cold_run_bit_for_bit() {
    use crate::SimulationOptions;
    let metrics = [
        "tau_r_peak".to_string(),
        "right_rotation_amplitude".to_string(),
    ];
    let points: Vec<_> = (0..8)
        .map(|k| {
            let stiffness = 8.0 + 4.0 * k as f64 / 7.0;
            let options = SimulationOptions {
                columns: Some(Vec::new()),
                metrics: Some(metrics.to_vec()),
                max_cycles: 200,
                ..Default::default()
            };
            Ok((lift_variant(stiffness, 85.0, 85.0), options))
        })
        .collect();
    let control = crate::sweep::SweepControl::new();
    let chain = crate::sweep::run_points(&points, &metrics, false, Some(1), &control).unwrap();
    let mut worst: f64 = 0.0;
    for (i, slot) in chain.iter().enumerate() {
        let point = slot.as_ref().unwrap().as_ref().unwrap();
        let (device, options) = points[i].as_ref().unwrap();
        let cold = crate::simulate(device, options).unwrap();
        assert!(point.converged && point.orbit_cycles == 1, "point {i}");
        assert!(
            !cold.multipliers.is_empty() && cold.monodromy.is_some(),
            "point {i}: the cold run ends by one-cycle shooting"
        );
        assert_eq!(point.cycles_run, cold.cycles_run, "point {i}");
        for (k, name) in metrics.iter().enumerate() {
            let (_, value) = cold.metrics.iter().find(|(n, _)| n == name).unwrap();
            worst = worst.max((point.metrics[k] - value).abs() / value.abs());
        }
    }
    assert_eq!(worst, 0.0, "sweep rows vs cold runs");
}

/// A §2.5 Lift point next to a flip (deviation stiffness 9.6 mN·mm/rad, 92 V + 100 V offset):
/// its cold run used to end unconverged after 200 cycles (one-cycle change 2.7e-3, decaying
/// about 2 % per cycle). Its warm-up shooting finds an unstable orbit (μ = 1.93, rightly
/// rejected); the two-cycle shooting then fails (μ² − 1 ≈ 0 near a flip); the one-cycle retry
/// from there finds the stable orbit, whose Broyden-updated multiplier (1.011) the variational
/// equations correct (−0.855). Checked independently: an rtol-1e-10 variational period from
/// the result's state returns to it within 1e-7 and has every multiplier inside the unit
/// circle (docs/findings.md §23).
#[test]
fn a_lift_point_next_to_a_flip_converges_by_shooting() {
    use crate::SimulationOptions;
    use crate::integrate::{Method, RungeKutta};
    let d = lift_variant(9.6, 92.0, 100.0);
    let options = SimulationOptions {
        columns: Some(Vec::new()),
        metrics: Some(vec!["tau_r_peak".into()]),
        max_cycles: 200,
        ..Default::default()
    };
    let r = crate::simulate(&d, &options).unwrap();
    eprintln!(
        "converged {} after {} cycles, residual {:e}, largest multiplier {:?}",
        r.converged,
        r.cycles_run,
        r.residual,
        r.multipliers.first().map(|m| m.norm())
    );
    assert!(r.converged && r.orbit_cycles == 1 && r.monodromy.is_some());
    assert!(r.cycles_run < 200, "{} cycles", r.cycles_run);
    let tight = RungeKutta::new(Method::Dop853, 1e-10, 1e-12, 1_000_000).unwrap();
    let period = d.period().unwrap();
    let (end, monodromy) = tight
        .flow_with_sensitivity(&d, 0.0, &r.steady_state, period)
        .unwrap();
    let returned = relative_difference(&end.without_work(), &r.steady_state.without_work());
    let largest = crate::floquet::eigenvalues(&monodromy)
        .unwrap()
        .first()
        .map_or(0.0, |m| m.norm());
    eprintln!("independent check: returns within {returned:e}, largest multiplier {largest}");
    assert!(returned < 1e-7, "returns within {returned:e}");
    assert!(largest < 1.0, "largest multiplier {largest}");
}

/// The held-branch equations in batches (the variational equations' central differences,
/// `rhs_on_batch`) are the scalar ones bit for bit, with an implausible state among them.
#[test]
fn held_branch_batches_equal_the_scalar_right_hand_side_bit_for_bit() {
    // The Dual PARITY (five coordinates) in batches.
    let dual = device("dual_parity");
    assert_batches_are_scalar_bit_for_bit(&dual, &states(&dual));
    let d = device("lift_parity");
    let mut ys = states(&d);
    // Beyond the linkage's plausible range: the general path (and its error) in a batch.
    let mut far = ys[0];
    far.coords[0] = 50.0;
    ys.insert(3, far);
    assert_batches_are_scalar_bit_for_bit(&d, &ys);
}

/// The sides of the switching functions at `y`, with switch `flip` flipped when given.
fn flipped_sides(d: &Device, y: &State, flip: Option<usize>) -> Sides {
    let mut g = [0.0; MAX_SWITCHES];
    d.switches(0.61, y, &mut g).unwrap();
    let own = Sides::of(&g[..6]);
    flip.map_or(own, |i| own.with(i, !own.positive(i)))
}

/// `rhs_on_batch` of `ys` equals the scalar held-branch right-hand side state by state (every
/// entry's bits), on own and flipped sides, and fails at the scalar path's first failing state.
fn assert_batches_are_scalar_bit_for_bit(d: &Device, ys: &[State]) {
    let bits = |s: &State| {
        let mut v: Vec<u64> = s
            .coords
            .iter()
            .chain(&s.rates)
            .map(|x| x.to_bits())
            .collect();
        v.extend([s.work_actuator.to_bits(), s.work_aero.to_bits()]);
        v
    };
    let lean = d
        .form
        .free_deviation()
        .expect("a free-deviation device")
        .clone();
    let t = 0.61;
    for flip in [None, Some(1), Some(4)] {
        let sides = flipped_sides(d, &ys[1], flip);
        let mut out = vec![State::default(); ys.len()];
        let batch = d
            .rhs_on_batch(t, sides, ys, &mut out)
            .expect("a batch form");
        let mut first_error = None;
        for (k, y) in ys.iter().enumerate() {
            let mut one = State::default();
            match d.rhs_free_deviation(&lean, t, y, Some(branches(sides)), &mut one) {
                Ok(()) if first_error.is_none() => {
                    assert_eq!(bits(&out[k]), bits(&one), "state {k}")
                }
                Ok(()) => {}
                Err(_) => {
                    first_error.get_or_insert(k);
                }
            }
        }
        assert_eq!(
            batch.err().map(|(k, _)| k),
            first_error,
            "the first failing state"
        );
    }
}
