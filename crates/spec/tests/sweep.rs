//! The core sweep handle: paths resolved before running, failing points as rows, results
//! equal to direct simulations, progress and cancellation.

use std::time::Duration;

use paritysim_spec::sweep::{SweepJob, SweepPlan, run_plan};
use paritysim_spec::{Error, from_toml};
use serde_json::json;

fn hmf() -> paritysim_spec::Simulation {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/hmf.toml"
    ))
    .unwrap();
    let (mut spec, _) = from_toml(&text).unwrap();
    spec.options.max_cycles = 4;
    spec.options.min_cycles = 4;
    spec
}

#[test]
fn points_equal_direct_simulations_and_bad_points_are_rows() {
    let names = vec![
        "actuator.frequency_hz".to_string(),
        "drivetrain.crank_mm".to_string(),
    ];
    let rows = vec![
        vec![json!(90.0), json!(0.4)],
        vec![json!(-5.0), json!(0.4)],
        vec![json!(120.0), serde_json::Value::Null],
    ];
    let metrics = vec!["left_stroke_amplitude".to_string()];
    let plan = SweepPlan::new(hmf(), &names, rows, Some(&metrics), false, Some(2)).unwrap();
    let direct: Vec<_> = [0, 2]
        .iter()
        .map(|&i| {
            let (device, options) = plan.point_spec(i).unwrap().model().unwrap();
            let r = paritysim_dynamics::simulate(&device, &options).unwrap();
            r.metrics
                .iter()
                .find(|(n, _)| n == "left_stroke_amplitude")
                .unwrap()
                .1
        })
        .collect();
    let out = run_plan(plan).unwrap();
    assert_eq!(out.ok, [true, false, true]);
    // Shooting points start from their converged neighbour: the same orbit as a direct run,
    // to its accuracy (not bit for bit; see paritysim_dynamics::sweep).
    assert_eq!(
        out.metrics[0].to_bits(),
        direct[0].to_bits(),
        "a chain's first point"
    );
    let relative = (out.metrics[2] - direct[1]).abs() / direct[1].abs();
    assert!(
        relative <= 1e-7,
        "{} vs {} ({relative:e})",
        out.metrics[2],
        direct[1]
    );
    let error = out.error[1].as_deref().unwrap();
    assert!(
        error.contains("actuator.waveform.frequency_hz") && error.contains("(0, 10000] Hz"),
        "{error}"
    );
}

#[test]
fn unknown_paths_and_duplicate_targets_fail_before_running() {
    let plan = |names: &[&str]| {
        let names: Vec<String> = names.iter().map(|s| s.to_string()).collect();
        SweepPlan::new(hmf(), &names, vec![], None, false, Some(1))
    };
    let e = plan(&["drivetrain.crank"]).unwrap_err();
    assert!(
        e.to_string().contains("did you mean `drivetrain.crank_mm`"),
        "{e}"
    );
    // Shorthand spellings are suggested too, and siblings of the last segment come first.
    for (typo, meant) in [
        ("actuator.voltag_v", "actuator.voltage_v"),
        ("wings.left.omega_rato", "wings.left.omega_ratio"),
        ("wings[1].aero.omegga1", "wings[1].aero.omega1"),
    ] {
        let e = plan(&[typo]).unwrap_err();
        assert!(
            e.to_string().contains(&format!("did you mean `{meant}`")),
            "{e}"
        );
        assert_eq!(e.field(), Some(typo));
    }
    let e = plan(&["actuator.frequency_hz", "actuator.waveform.frequency_hz"]).unwrap_err();
    assert!(e.to_string().contains("same field"), "{e}");
    assert!(plan(&["wings.left.omega_ratio"]).is_ok());
}

#[test]
fn the_job_reports_progress_and_cancel_keeps_finished_points() {
    let names = vec!["actuator.frequency_hz".to_string()];
    let rows = (0..400)
        .map(|i| vec![json!(80.0 + f64::from(i) * 0.1)])
        .collect();
    let plan = SweepPlan::new(hmf(), &names, rows, None, false, Some(2)).unwrap();
    let job = SweepJob::new(plan);
    assert!(matches!(job.wait(None), Err(Error::Constraint(_))));
    job.start().unwrap();
    while job.finished() < 5 {
        std::thread::sleep(Duration::from_millis(1));
    }
    job.cancel();
    assert!(job.wait(Some(Duration::from_secs(60))).unwrap());
    let out = job.outcome().unwrap();
    let done = out.finished.iter().filter(|f| **f).count();
    assert!((5..400).contains(&done) && done == job.finished(), "{done}");
    assert!(out.ok.iter().zip(&out.finished).all(|(ok, f)| ok == f));
    assert!(job.start().is_err());
}
