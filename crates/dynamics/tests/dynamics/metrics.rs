//! Streamed metrics against the same quantities computed from recorded columns.

use super::*;
use paritysim_dynamics::Error;

fn options(columns: Option<Vec<String>>) -> SimulationOptions {
    SimulationOptions {
        max_cycles: 8,
        samples_per_cycle: 64,
        record_cycles: 2,
        columns,
        ..Default::default()
    }
}

fn body(v: &[f64]) -> &[f64] {
    &v[..v.len() - 1]
}

fn abs_max(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m: f64, x| m.max(x.abs()))
}

#[test]
fn streamed_metrics_equal_those_of_the_recorded_columns() {
    let device = linear_parity(0.6 * 31.3, Formulation::Auto);
    let r = simulate(&device, &options(None)).unwrap();
    let m = |name: &str| {
        r.metrics
            .iter()
            .find(|(n, _)| n == name)
            .unwrap_or_else(|| panic!("{name}"))
            .1
    };
    let tr = &r.trajectory;
    let col = |name: &str| tr.column(name).unwrap();
    let (tl, tr_) = (col("left_roll_aero"), col("right_roll_aero"));
    let sum: Vec<f64> = tl.iter().zip(tr_).map(|(a, b)| a + b).collect();
    let delta = abs_max(&sum);
    let (peak_l, peak_r) = (abs_max(tl), abs_max(tr_));
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * (1.0 + b.abs());
    assert!(close(m("delta_tau_peak"), delta));
    assert!(close(m("tau_l_peak"), peak_l));
    assert!(close(
        m("imbalance_instantaneous_pct"),
        100.0 * delta / peak_r
    ));
    assert!(close(
        m("imbalance_peak_pct"),
        100.0 * (peak_r - peak_l) / peak_r
    ));
    // A cut wing: the imbalance is real.
    assert!(m("imbalance_instantaneous_pct") > 1.0);
    for (wing, axis) in [("left", "roll"), ("right", "yaw"), ("left", "pitch")] {
        let aero = col(&format!("{wing}_{axis}_aero"));
        let inertial = col(&format!("{wing}_{axis}_inertial"));
        let v: Vec<f64> = aero.iter().zip(inertial).map(|(a, b)| a + b).collect();
        let n = (v.len() - 1) as f64;
        let mean = body(&v).iter().sum::<f64>() / n;
        let rms = (body(&v).iter().map(|x| x * x).sum::<f64>() / n).sqrt();
        assert!(close(m(&format!("{wing}_{axis}_mean")), mean));
        assert!(close(m(&format!("{wing}_{axis}_rms")), rms));
        assert!(close(m(&format!("{wing}_{axis}_peak")), abs_max(&v)));
    }
    let roll = col("roll_total");
    let n = (roll.len() - 1) as f64;
    assert!(close(
        m("roll_total_rms"),
        (body(roll).iter().map(|x| x * x).sum::<f64>() / n).sqrt()
    ));
    // Energy: the actuator's work per cycle is the aerodynamic dissipation in steady state.
    assert!(
        (m("work_actuator_per_cycle") + m("work_aero_per_cycle")).abs()
            < 1e-4 * m("work_actuator_per_cycle")
    );
}

#[test]
fn metrics_need_no_columns_and_only_asked_columns_are_built() {
    let device = linear_parity(0.6 * 31.3, Formulation::Auto);
    let full = simulate(&device, &options(None)).unwrap();
    let none = simulate(&device, &options(Some(vec![]))).unwrap();
    let bits = |m: &[(String, f64)]| -> Vec<(String, u64)> {
        m.iter().map(|(n, v)| (n.clone(), v.to_bits())).collect()
    };
    assert_eq!(bits(&full.metrics), bits(&none.metrics));
    assert!(none.trajectory.time.is_empty() && none.trajectory.columns.is_empty());
    let asked = vec!["q2".to_string(), "left_phi".to_string()];
    let some = simulate(&device, &options(Some(asked.clone()))).unwrap();
    let names: Vec<&String> = some.trajectory.columns.iter().map(|(n, _)| n).collect();
    assert_eq!(names, asked.iter().collect::<Vec<_>>());
    assert_eq!(some.trajectory.column("q2"), full.trajectory.column("q2"));
    assert_eq!(some.trajectory.time, full.trajectory.time);
    match simulate(&device, &options(Some(vec!["nope".into()]))) {
        Err(Error::InvalidParameter { field, .. }) => assert_eq!(field, "columns"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn symmetric_device_has_no_imbalance() {
    let device = parity_device(31.3, 1.0, "drag_parity_fixed", Formulation::Auto);
    let r = simulate(&device, &options(Some(vec![]))).unwrap();
    let m = |name: &str| r.metrics.iter().find(|(n, _)| n == name).unwrap().1;
    assert!(
        m("imbalance_instantaneous_pct").abs() < 1e-6,
        "{}",
        m("imbalance_instantaneous_pct")
    );
    assert!(m("imbalance_peak_pct").abs() < 1e-6);
    assert!(m("roll_total_mean").abs() < 1e-6 * m("left_roll_peak"));
    // The mirrored roll torques cancel; the pitch torques (spanwise, not mirrored) add.
    assert!((m("left_roll_peak") - m("right_roll_peak")).abs() < 1e-6 * m("left_roll_peak"));
}
