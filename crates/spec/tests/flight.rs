//! The `body` section: defaults, validation, paths, and runs through `Simulation::run`.

use paritysim_error::Error;
use paritysim_spec::{from_toml, paths};

fn device_toml(name: &str) -> String {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    std::fs::read_to_string(root.join("python/paritysim/devices").join(name)).unwrap()
}

fn with_body(body: &str) -> String {
    let base = device_toml("sreetharan2012_3_4_parity.toml");
    // [body] goes before [options] (TOML tables are independent).
    format!("{base}\n[body]\n{body}\n")
}

#[test]
fn fixed_body_is_the_engine_bit_for_bit() {
    let plain = from_toml(&device_toml("sreetharan2012_3_4_parity.toml"))
        .unwrap()
        .0;
    let fixed = from_toml(&with_body("mode = \"fixed\"\nmass_mg = 80.0"))
        .unwrap()
        .0;
    assert!(!fixed.flies());
    let (device, options) = plain.model().unwrap();
    let a = paritysim_dynamics::simulate(&device, &options).unwrap();
    let (device, options) = fixed.model().unwrap();
    let mut b = fixed.run(&device, &options).unwrap();
    // The body's mass adds the weight ratios (tests/force_metrics.rs), nothing else.
    b.metrics
        .retain(|(n, _)| n != "lift_to_weight" && n != "actuator_power_per_weight");
    assert_eq!(a, b);
}

#[test]
fn free_body_runs_from_a_spec_and_reports_body_columns() {
    let spec = from_toml(&with_body("mode = \"free\"")).unwrap().0;
    assert!(spec.flies());
    let (device, mut options) = spec.model().unwrap();
    options.record_cycles = 2;
    let r = spec.run(&device, &options).unwrap();
    let names = spec.column_names(&device).unwrap();
    for c in [
        "left_phi",
        "body_roll",
        "body_qw",
        "body_x",
        "body_omega_pitch",
        "lift",
    ] {
        assert!(names.iter().any(|n| n == c), "{c}");
        assert_eq!(
            r.trajectory.column(c).unwrap().len(),
            2 * options.samples_per_cycle + 1
        );
    }
    let metric = |k: &str| r.metrics.iter().find(|(n, _)| n == k).unwrap().1;
    // The §3.4 wings lift more than the 60 mg default airframe weighs (and the ratio is
    // computed from the run, not typed).
    assert!(
        metric("lift_to_weight") > 1.0,
        "{}",
        metric("lift_to_weight")
    );
    assert!(metric("left_stroke_amplitude") > 0.3);
    let qn: f64 = ["body_qw", "body_qx", "body_qy", "body_qz"]
        .iter()
        .map(|c| r.trajectory.column(c).unwrap().last().unwrap().powi(2))
        .sum();
    assert!((qn - 1.0).abs() < 1e-12, "unit quaternion: {qn}");
}

#[test]
fn body_fields_are_validated_with_their_path_and_listed_as_paths() {
    let err = from_toml(&with_body("mode = \"free\"\nmass_mg = -1.0")).unwrap_err();
    let text = err.to_string();
    assert!(text.contains("body.mass_mg"), "{text}");
    let err = from_toml(&with_body("mode = \"flying\"")).unwrap_err();
    assert!(err.to_string().contains("body.mode"), "{err}");
    let err = from_toml(&with_body("mas_mg = 3.0")).unwrap_err();
    assert!(err.to_string().contains("mass_mg"), "nearest key: {err}");
    // A non-positive-definite inertia fails at build time, naming the field.
    let spec = from_toml(&with_body(
        "mode = \"free\"\ninertia = [[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]]",
    ))
    .unwrap()
    .0;
    assert!(spec.model().is_err(), "validation builds the flight model");
    let device = spec.device().unwrap();
    match spec.flight(&device) {
        Err(Error::InvalidParameter { field, .. }) => assert_eq!(field, "body.inertia"),
        other => panic!("expected an inertia error, got {other:?}"),
    }
    let spec = from_toml(&with_body("mode = \"free\"")).unwrap().0;
    let listed: Vec<String> = paths::spec_paths(&spec)
        .into_iter()
        .map(|p| p.path)
        .collect();
    for p in [
        "body.mass_mg",
        "body.force_radius_mm",
        "body.gravity_mm_per_ms2[0]",
        "body.inertia[1][1]",
    ] {
        assert!(listed.iter().any(|l| l == p), "{p} not in {listed:?}");
    }
}

#[test]
fn sweeps_run_flying_specs() {
    use paritysim_spec::sweep::{SweepPlan, run_plan};
    // Clamped: the airframe mass does not enter the dynamics, only the weight, so doubling
    // it halves lift / weight exactly; a bad point is an error row.
    let base = from_toml(&with_body("mode = \"clamped\"")).unwrap().0;
    let names = vec!["body.mass_mg".to_string()];
    let rows = vec![vec![60.0.into()], vec![120.0.into()], vec![(-5.0).into()]];
    let metrics = vec![
        "lift_to_weight".to_string(),
        "body_force_x_mean".to_string(),
    ];
    let plan = SweepPlan::new(base.clone(), &names, rows, Some(&metrics), false, Some(2)).unwrap();
    let out = run_plan(plan).unwrap();
    assert_eq!(out.ok, vec![true, true, false]);
    let (a, b) = (out.metrics[0], out.metrics[2]);
    assert!(a > 1.0 && (a / b - 2.0).abs() < 1e-12, "{a} {b}");
    assert_eq!(out.metrics[1].to_bits(), out.metrics[3].to_bits());
    // The same point through Simulation::run.
    let (device, options) = base.model().unwrap();
    let direct = base.run(&device, &options).unwrap();
    let ltw = direct
        .metrics
        .iter()
        .find(|(n, _)| n == "lift_to_weight")
        .unwrap()
        .1;
    assert_eq!(ltw.to_bits(), a.to_bits());
}

/// The §3.4 PARITY device with its drivetrain section replaced by `drivetrain` (TOML body).
fn with_drivetrain(drivetrain: &str, body: &str) -> String {
    let base = device_toml("sreetharan2012_3_4_parity.toml");
    let start = base.find("[drivetrain]").unwrap();
    let end = start + base[start..].find("\n[actuator]").unwrap();
    format!(
        "{}[drivetrain]\n{drivetrain}\n{}\n[body]\n{body}\n",
        &base[..start],
        &base[end..]
    )
}

fn invalid_field(text: &str) -> String {
    let spec = from_toml(text).unwrap().0;
    match spec.model() {
        Err(Error::InvalidParameter { field, .. }) => field.to_string(),
        other => panic!("expected a field error, got {:?}", other.map(|_| ())),
    }
}

#[test]
fn per_side_drive_and_eq_5_1_inputs_are_checked_against_the_drivetrain() {
    // Per-side fields need a dual drivetrain; side inputs need one; q2_bias / log_q3 need a
    // whippletree; each error names its field.
    let linear = device_toml("sreetharan2012_3_4_parity.toml");
    let sided = linear.replace(
        "dc_offset = \"ignore\"",
        "dc_offset = \"ignore\"\nside_gain = [1.0, 1.2]",
    );
    assert_eq!(invalid_field(&sided), "actuator.side_gain");
    let offset = linear.replace(
        "dc_offset = \"ignore\"",
        "dc_offset = \"ignore\"\nside_offset_v = [0.0, 5.0]",
    );
    assert_eq!(invalid_field(&offset), "actuator.side_offset_v");
    let bad_gain = with_drivetrain("kind = \"dual_four_bar\"", "mode = \"fixed\"").replace(
        "dc_offset = \"ignore\"",
        "dc_offset = \"ignore\"\nside_gain = [1.0, -2.0]",
    );
    match from_toml(&bad_gain) {
        Err(e) => assert!(e.to_string().contains("actuator.side_gain[1]"), "{e}"),
        Ok(_) => panic!("a negative side gain is accepted"),
    }
    let side_on_parity = with_body(
        "mode = \"roll\"\n[[body.set_points]]\ninput = \"side_gain_left\"\ntimes_ms = [0]\nvalues = [0.1]",
    );
    assert_eq!(invalid_field(&side_on_parity), "body.set_points[0].input");
    let q3_on_dual = with_drivetrain(
        "kind = \"dual_four_bar\"",
        "mode = \"roll\"\n[body.control]\ninput = \"log_q3\"\nkp = 1.0",
    );
    assert_eq!(invalid_field(&q3_on_dual), "body.control.input");
    let bad_period = with_body(
        "mode = \"roll\"\n[[body.set_points]]\ninput = \"log_q3\"\ntimes_ms = [0, 12]\nvalues = [0.1, -0.1]\nperiod_ms = 9.0",
    );
    assert_eq!(invalid_field(&bad_period), "body.set_points[0].times_ms");
}

#[test]
fn a_dual_drive_spec_runs_with_per_side_gains() {
    // The dual four-bar from a spec: a larger right gain gives a larger right stroke only
    // (one drive per wing).
    let run = |gain: &str| {
        let text = with_drivetrain("kind = \"dual_four_bar\"", "mode = \"fixed\"")
            .replace("amplitude_v = 100.0", "amplitude_v = 40.0")
            .replace(
                "dc_offset = \"ignore\"",
                &format!("dc_offset = \"ignore\"\nside_gain = {gain}"),
            );
        let spec = from_toml(&text).unwrap().0;
        let (device, mut options) = spec.model().unwrap();
        options.record_cycles = 1;
        let r = spec.run(&device, &options).unwrap();
        let amp = |c: &str| {
            r.trajectory
                .column(c)
                .unwrap()
                .iter()
                .fold(0.0f64, |m, x| m.max(x.abs()))
        };
        (amp("left_phi"), amp("right_phi"))
    };
    let (l0, r0) = run("[1.0, 1.0]");
    let (l1, r1) = run("[1.0, 1.25]");
    assert!((l1 - l0).abs() < 1e-6 * l0, "left unchanged: {l0} -> {l1}");
    assert!(r1 > 1.1 * r0, "right grows: {r0} -> {r1}");
}
