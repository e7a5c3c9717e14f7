//! `drivetrain.balance_preload`: a constant torque P on the whippletree, read from the spec
//! and applied by the one drive load (`Q2 = P − K2 q2`).
//!
//! Closed form on the §3.3 Drag PARITY, Control trial (eq. 2.15 with arms h = L, both wings
//! alike, springs only on the whippletree): with `q̇2 = 0` both wings stroke at `φ̇ = −T q̇1`,
//! so their drag torques are equal and cancel on `q2`, and `M_q` is diagonal. The preloaded
//! orbit is therefore the unpreloaded one with the whippletree held at `q2 = P / K2`, the
//! left stroke shifted by `+T L P / K2` and the right by `−T L P / K2`.

use paritysim_dynamics::simulate;
use paritysim_spec::from_toml;

fn control_trial(k2: f64, preload: f64) -> String {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let text = std::fs::read_to_string(
        root.join("python/paritysim/devices/sreetharan2012_3_3_parity.toml"),
    )
    .unwrap();
    assert!(text.contains("balance_spring = 0.0\n"));
    text.replace(
        "balance_spring = 0.0\n",
        &format!("balance_spring = {k2:?}\nbalance_preload = {preload:?}\n"),
    )
}

fn largest(values: impl Iterator<Item = f64>) -> f64 {
    values.map(f64::abs).fold(0.0, f64::max)
}

#[test]
fn a_static_preload_shifts_the_whippletree_by_preload_over_stiffness() {
    let (k2, preload) = (40.0, 2.0);
    let shift = preload / k2;
    let run = |preload: f64| {
        let (spec, notes) = from_toml(&control_trial(k2, preload)).unwrap();
        assert!(notes.is_empty(), "{notes:?}");
        let (device, options) = spec.model().unwrap();
        let r = simulate(&device, &options).unwrap();
        assert!(r.converged, "preload {preload}");
        r
    };
    let (plain, loaded) = (run(0.0), run(preload));
    let col = |r: &paritysim_dynamics::SimulationResult, name: &str| {
        r.trajectory.column(name).unwrap().to_vec()
    };
    // The whippletree: at rest at 0 without the preload, at P / K2 with it.
    assert!(largest(col(&plain, "q2").into_iter()) < 1e-9);
    let q2 = col(&loaded, "q2");
    let off = largest(q2.iter().map(|q| q - shift));
    assert!(off < 1e-9 * shift, "q2 − P/K2 up to {off:e}");
    // The drive coordinate q1 is untouched; each stroke moves by ±T L P / K2.
    let t = 35f64.to_radians() / 0.2;
    let l = 2.5;
    let (before, after) = (col(&plain, "q1"), col(&loaded, "q1"));
    let q1 = largest(before.iter().zip(&after).map(|(a, b)| a - b));
    assert!(q1 < 1e-9 * largest(before.iter().copied()), "{q1:e}");
    for (wing, sign) in [("left", 1.0), ("right", -1.0)] {
        let name = format!("{wing}_phi");
        let (before, after) = (col(&plain, &name), col(&loaded, &name));
        let moved = before
            .iter()
            .zip(after)
            .map(|(a, b)| b - a - sign * t * l * shift);
        let off = largest(moved);
        assert!(off < 1e-8 * t * l * shift, "{wing}: {off:e}");
    }
}

#[test]
fn the_preload_is_validated_and_named() {
    // Outside its range: the field path and the range are named.
    let err = from_toml(&control_trial(40.0, 500.0))
        .unwrap_err()
        .to_string();
    assert!(err.contains("drivetrain.balance_preload"), "{err}");
    assert!(err.contains("[-100, 100]"), "{err}");
    // A 1-DOF drivetrain has no whippletree, so no such field (the nearest name is offered).
    let hmf = control_trial(0.0, 0.0)
        .replace("kind = \"linear_differential\"", "kind = \"hmf_four_bar\"")
        .replace("transmission_ratio = 3.0543261909900763\n", "")
        .replace("arm_length_mm = 2.5\narm_ratio = 1.0\n", "")
        .replace("balance_spring = 0.0\n", "");
    let err = from_toml(&hmf).unwrap_err().to_string();
    assert!(err.contains("balance_preload"), "{err}");
    // Without a balance spring a preload has no equilibrium (q2 would run to its stop).
    let err = from_toml(&control_trial(0.0, 2.0))
        .and_then(|(spec, _)| spec.model())
        .unwrap_err()
        .to_string();
    assert!(err.contains("drivetrain.balance_preload"), "{err}");
    assert!(err.contains("balance spring"), "{err}");
}

/// The SIMD lanes carry the preload per lane: a sweep over it gives the scalar sweep's bits at
/// every lane width, and each row's mean strokes are `±T L P / K2` (the drive's own mean is 0).
#[test]
fn preloaded_sweeps_are_bit_identical_in_lanes_and_match_the_closed_form() {
    use paritysim_dynamics::lanes::points_completed_in_lanes;
    use paritysim_dynamics::sweep::{PointOutput, SweepControl, run_points_with_lanes};

    let k2 = 40.0;
    let preloads: Vec<f64> = (0..8).map(|k| -3.0 + 6.0 * k as f64 / 7.0).collect();
    let points: Vec<_> = preloads
        .iter()
        .map(|&p| from_toml(&control_trial(k2, p)).and_then(|(spec, _)| spec.model()))
        .collect();
    let metrics: Vec<String> = ["left_stroke_mean", "right_stroke_mean", "q2_amplitude"]
        .map(String::from)
        .to_vec();
    let run = |lanes: usize| -> Vec<PointOutput> {
        run_points_with_lanes(
            &points,
            &metrics,
            false,
            Some(1),
            Some(lanes),
            &SweepControl::new(),
        )
        .unwrap()
        .into_iter()
        .map(|slot| slot.expect("not cancelled").unwrap())
        .collect()
    };
    let bits = |o: &PointOutput| -> Vec<u64> {
        let mut v: Vec<u64> = o.metrics.iter().map(|x| x.to_bits()).collect();
        v.push(o.residual.to_bits());
        v.extend(o.step_grid.iter().map(|x| x.to_bits()));
        v
    };
    let scalar = run(1);
    let before = points_completed_in_lanes();
    let lanes = run(4);
    assert!(
        points_completed_in_lanes() - before >= points.len(),
        "the lanes ran"
    );
    let t_l = 35f64.to_radians() / 0.2 * 2.5;
    for (i, (a, b)) in scalar.iter().zip(&lanes).enumerate() {
        assert_eq!(bits(a), bits(b), "point {i}");
        assert!(a.converged, "point {i}");
        let shift = t_l * preloads[i] / k2;
        let [left, right, q2_amplitude] = [0, 1, 2].map(|m| a.metrics[m]);
        assert!((left - shift).abs() < 1e-7, "point {i}: {left} vs {shift}");
        assert!(
            (right + shift).abs() < 1e-7,
            "point {i}: {right} vs {}",
            -shift
        );
        assert!(q2_amplitude < 1e-7, "point {i}: q2 moves by {q2_amplitude}");
    }
}
