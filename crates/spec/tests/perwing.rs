//! A linear drive per wing (`dual_linear`), one actuator on a linear or polynomial transmission
//! (`single_linear`, one wing or two tied wings) and polynomial transmissions on the linear
//! differential (issue 35), through the spec: whole runs against each other and closed forms.
//!
//! Closed forms on the §3.3 Drag PARITY (Control trial: equal wings, no stroke springs):
//! * with equal sides a drive per wing is the shared drive with the actuator doubled: each
//!   side obeys `I T² q̈ = F − K1 q − T τ(φ̇)` and the shared drive `2 I T² q̈ = 2F − 2K1 q −
//!   2T τ(φ̇)` (eq. 2.15 with `q2 ≡ 0` by symmetry), so every metric agrees to round-off;
//! * a DC offset on one side shifts that side's drive by `F0 / K1` and nothing else (the
//!   drag depends only on `φ̇` and the map is linear), so its stroke mean is `−T · 1.2 V0 / K1`.

use paritysim_dynamics::{SimulationResult, simulate};
use paritysim_spec::from_toml;

const T: f64 = 3.0543261909900763;
const DIFFERENTIAL: &str = "[drivetrain]\nkind = \"linear_differential\"\ntransmission_ratio = 3.0543261909900763\narm_length_mm = 2.5\narm_ratio = 1.0\nbalance_spring = 0.0\n";

fn control_trial() -> String {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let text = std::fs::read_to_string(
        root.join("python/paritysim/devices/sreetharan2012_3_3_parity.toml"),
    )
    .unwrap();
    assert!(text.contains(DIFFERENTIAL));
    text
}

fn with_drivetrain(text: &str, drivetrain: &str) -> String {
    text.replace(DIFFERENTIAL, drivetrain)
}

fn doubled_actuator(text: &str) -> String {
    assert!(text.contains("force_per_volt = 1.2\nstiffness = 467.0\n"));
    text.replace(
        "force_per_volt = 1.2\nstiffness = 467.0\n",
        "force_per_volt = 2.4\nstiffness = 934.0\n",
    )
}

fn dual(extra: &str) -> String {
    with_drivetrain(
        &control_trial(),
        &format!("[drivetrain]\nkind = \"dual_linear\"\ntransmission_ratio = {T:?}\n{extra}"),
    )
}

fn run(text: &str) -> SimulationResult {
    let (spec, notes) = from_toml(text).unwrap();
    assert!(notes.is_empty(), "{notes:?}");
    let (device, options) = spec.model().unwrap();
    let r = simulate(&device, &options).unwrap();
    assert!(r.converged);
    r
}

fn metric(r: &SimulationResult, name: &str) -> f64 {
    r.metrics.iter().find(|(n, _)| n == name).unwrap().1
}

/// Every metric both report except the drive's own (`q2` is the right drive on one and the
/// whippletree on the other; the force peak is per side on one and doubled on the other).
fn assert_same_metrics(a: &SimulationResult, b: &SimulationResult, what: &str) {
    let mut compared = 0;
    for (name, x) in &a.metrics {
        if name.starts_with("q2") || name == "actuator_force_peak" || x.is_nan() {
            continue;
        }
        let Some((_, y)) = b.metrics.iter().find(|(n, _)| n == name) else {
            continue;
        };
        // Steady-state tolerance 1e-7 on the orbit; sample peaks and means to round-off of it.
        let scale = 1.0 + x.abs().max(y.abs());
        assert!(
            (x - y).abs() <= 1e-8 * scale,
            "{what}: {name} {x} vs {y} ({:e})",
            (x - y).abs() / scale
        );
        compared += 1;
    }
    assert!(compared > 30, "{what}: {compared} metrics");
}

#[test]
fn a_drive_per_wing_with_equal_sides_is_the_shared_drive_with_the_actuator_doubled() {
    let per_wing = run(&dual(""));
    let shared = run(&doubled_actuator(&control_trial()));
    assert_same_metrics(&per_wing, &shared, "linear_differential");
    // The one-actuator linear drive on two tied wings (hmf_fixed) is the same shared drive.
    let tied = doubled_actuator(&with_drivetrain(
        &control_trial(),
        &format!("[drivetrain]\nkind = \"single_linear\"\ntransmission_ratio = {T:?}\n"),
    ))
    .replace("name = \"drag_parity_fixed\"", "name = \"hmf_fixed\"");
    assert_same_metrics(&per_wing, &run(&tied), "single_linear on hmf_fixed");
    // The drive's force peak is per side: 1.2 mN/V × 100 V.
    assert!((metric(&per_wing, "actuator_force_peak") - 120.0).abs() < 1e-9);
    // A polynomial with τ2 = 0 written out is the linear map (same bits).
    let zero = run(&dual("cubic_ratio = 0.0\nhigher_odd_ratios = []\n"));
    assert_eq!(bits(&per_wing), bits(&zero));
}

fn bits(r: &SimulationResult) -> Vec<u64> {
    let mut v: Vec<u64> = r.metrics.iter().map(|(_, x)| x.to_bits()).collect();
    v.extend(r.step_grid.iter().map(|x| x.to_bits()));
    v.push(r.residual.to_bits());
    v
}

/// τ2 = 1e-300 sends the device through the polynomial equations (configuration-dependent
/// `M_q`, velocity product, their Jacobian, the Newton inverse of the kinematics) with terms
/// below round-off: the whole run is the linear map's, bit for bit. A real τ2 changes it.
#[test]
fn a_vanishing_cubic_term_is_the_linear_map_bit_for_bit() {
    let linear = run(&control_trial());
    let tiny = run(&control_trial().replace(
        "balance_spring = 0.0\n",
        "balance_spring = 0.0\ncubic_ratio = 1e-300\n",
    ));
    assert_eq!(bits(&linear), bits(&tiny));
    let cubic = run(&control_trial().replace(
        "balance_spring = 0.0\n",
        "balance_spring = 0.0\ncubic_ratio = 5.0\n",
    ));
    let (a, b) = (
        metric(&linear, "left_stroke_amplitude"),
        metric(&cubic, "left_stroke_amplitude"),
    );
    assert!((a - b).abs() > 1e-3, "{a} {b}");
}

#[test]
fn side_gains_and_offsets_act_on_their_own_wing() {
    let actuator = "dc_offset = \"as_force\"\n";
    let sides = |gain: [f64; 2], offset: [f64; 2]| {
        dual("").replace(
            actuator,
            &format!("{actuator}side_gain = {gain:?}\nside_offset_v = {offset:?}\n"),
        )
    };
    let plain = run(&dual(""));
    let a0 = metric(&plain, "left_stroke_amplitude");
    // A stronger left drive: the left wing strokes more, the right less (each side alone
    // responds monotonically to its force), and the left's drag torque peaks higher.
    let r = run(&sides([1.2, 0.8], [0.0, 0.0]));
    let (left, right) = (
        metric(&r, "left_stroke_amplitude"),
        metric(&r, "right_stroke_amplitude"),
    );
    assert!(left > a0 && a0 > right, "{left} {a0} {right}");
    assert!(metric(&r, "tau_l_peak") > metric(&r, "tau_r_peak"));
    // Each side is its own one-wing system: the right side at gain 0.8 is the plain device
    // driven at 80 V (equal sides), whatever the left does.
    let at_80 = run(&dual("").replace("amplitude_v = 100.0", "amplitude_v = 80.0"));
    let expected = metric(&at_80, "right_stroke_amplitude");
    assert!((right - expected).abs() < 1e-8, "{right} vs {expected}");
    // A DC offset of 10 V on the left drive: its stroke mean is −T F0 / K1, the right's 0.
    let r = run(&sides([1.0, 1.0], [10.0, 0.0]));
    let shift = -T * 1.2 * 10.0 / 467.0;
    let left_mean = metric(&r, "left_stroke_mean");
    assert!((left_mean - shift).abs() < 1e-7, "{left_mean} vs {shift}");
    assert!(metric(&r, "right_stroke_mean").abs() < 1e-7);
    assert!((metric(&r, "left_stroke_amplitude") - a0).abs() < 1e-7);
}

#[test]
fn the_new_fields_are_validated_and_named() {
    let err = |text: &str| match from_toml(text).and_then(|(spec, _)| spec.model()) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("accepted"),
    };
    let e = err(&dual("cubic_ratio = 2e4\n"));
    assert!(e.contains("drivetrain.cubic_ratio"), "{e}");
    let e = err(&dual("higher_odd_ratios = [1.0, 2.0, 3.0, 4.0]\n"));
    assert!(e.contains("drivetrain.higher_odd_ratios"), "{e}");
    // Side gains need a drive per wing.
    let shared = control_trial().replace(
        "dc_offset = \"as_force\"\n",
        "dc_offset = \"as_force\"\nside_gain = [1.2, 0.8]\n",
    );
    let e = err(&shared);
    assert!(
        e.contains("actuator.side_gain") && e.contains("dual_linear"),
        "{e}"
    );
    // One wing: a 2-DOF drivetrain and the two-wing configurations are refused by name.
    let one_wing = |text: String| {
        let second = text.rfind("[[wings]]").unwrap();
        let end = text.find("[options]").unwrap();
        format!("{}{}", &text[..second], &text[end..])
    };
    let e = err(&one_wing(dual("")).replace("drag_parity_fixed", "single_wing_fixed"));
    assert!(e.contains("drivetrain.kind"), "{e}");
    let single = with_drivetrain(
        &control_trial(),
        &format!("[drivetrain]\nkind = \"single_linear\"\ntransmission_ratio = {T:?}\n"),
    );
    let e = err(&one_wing(single.clone()));
    assert!(
        e.contains("configuration.name") && e.contains("single_wing"),
        "{e}"
    );
    let e = err(&single.replace("drag_parity_fixed", "single_wing_fixed"));
    assert!(
        e.contains("configuration.name") && e.contains("length 1"),
        "{e}"
    );
}
