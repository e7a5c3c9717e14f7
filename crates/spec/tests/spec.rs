//! Spec round trips, validation messages, paths and the shipped schema.

use nalgebra::Matrix3;
use paritysim_constraints::Constraints;
use paritysim_dynamics::device::{DeviceSpec, Formulation, Transmission};
use paritysim_dynamics::{Actuator, DcOffset, Device, JointSpring, Waveform, Wing, WingAero};
use paritysim_error::Error;
use paritysim_kinematics::drivetrain::LinkageDifferential;
use paritysim_kinematics::{Drivetrain, RodCrank, SphericalShoulder};
use paritysim_spec::{from_json, from_toml, paths, schema};

fn root() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn example(name: &str) -> String {
    std::fs::read_to_string(root().join("examples").join(name)).unwrap()
}

#[test]
fn shipped_schema_is_current() {
    // PARITYSIM_BLESS=1 cargo test -p paritysim-spec regenerates it.
    let file = root().join("python/paritysim/spec.schema.json");
    let fresh = schema::schema_json();
    if std::env::var_os("PARITYSIM_BLESS").is_some() {
        std::fs::write(&file, &fresh).unwrap();
    }
    let shipped = std::fs::read_to_string(&file).unwrap_or_default();
    assert!(
        shipped == fresh,
        "python/paritysim/spec.schema.json is stale: run PARITYSIM_BLESS=1 cargo test -p paritysim-spec"
    );
}

#[test]
fn examples_round_trip_through_toml_and_json() {
    for name in ["drag_parity.toml", "hmf.toml"] {
        let (spec, _) = from_toml(&example(name)).unwrap();
        let (again, notes) = from_toml(&spec.to_toml()).unwrap();
        assert_eq!(spec, again, "{name}");
        assert!(notes.is_empty());
        assert_eq!(from_json(&spec.to_json()).unwrap().0, spec);
    }
}

#[test]
fn the_spec_builds_the_same_device_as_the_engine_constructors() {
    let (spec, notes) = from_toml(&example("drag_parity.toml")).unwrap();
    assert!(notes.is_empty(), "{notes:?}");
    // The old name still reads, with a deprecation note.
    let old = example("drag_parity.toml").replace("balance_spring", "balance_stiffness");
    let (same, notes) = from_toml(&old).unwrap();
    assert_eq!((&same, notes.len()), (&spec, 1));
    let wing = Wing::new(
        SphericalShoulder::new(std::f64::consts::FRAC_PI_2, 0.0).unwrap(),
        Matrix3::new(29.0, 0.0, 0.0, 0.0, 29.0, 0.0, 0.0, 0.0, 1.0),
        [JointSpring::default(); 6],
        WingAero::stroke_drag(31.3, 3.4609).unwrap(),
    )
    .unwrap();
    let linkage = LinkageDifferential::new(RodCrank::new(0.4, 0.8).unwrap(), 5.0, 1.0).unwrap();
    let by_hand = Device::new(DeviceSpec {
        wings: vec![wing.clone(), wing],
        constraints: Constraints::configuration("drag_parity_fixed").unwrap(),
        transmission: Some(
            Transmission::new(Drivetrain::LinkageDifferential(linkage), 1.0).unwrap(),
        ),
        actuator: Some(
            Actuator::new(
                1.2,
                467.0,
                Waveform::sine(100.0, 110.0, 0.0, 0.0).unwrap(),
                DcOffset::AsForce,
            )
            .unwrap(),
        ),
        formulation: Formulation::Auto,
    })
    .unwrap();
    assert_eq!(spec.device().unwrap(), by_hand);
}

fn problems(e: Error) -> Vec<(String, String)> {
    match e {
        Error::InvalidSpec(p) => p.into_iter().map(|p| (p.field, p.allowed)).collect(),
        Error::InvalidParameter { field, allowed, .. } => vec![(field.into_owned(), allowed)],
        other => panic!("not a validation error: {other}"),
    }
}

#[test]
fn every_problem_is_reported_with_path_and_range() {
    let text = example("hmf.toml")
        .replace("crank_mm = 0.4", "crank_mm = -0.4")
        .replace("rtol = 1e-8", "rtol = 1e-8\nmax_cycles = true")
        .replace("omega1 = 31.3\n", "omega1 = 31.3\nomegaa2 = 1.0\n");
    let found = problems(from_toml(&text).unwrap_err());
    let fields: Vec<&str> = found.iter().map(|(f, _)| f.as_str()).collect();
    // Only the right wing's line has no comment after `omega1 = 31.3`.
    assert_eq!(
        fields,
        [
            "drivetrain.crank_mm",
            "options.max_cycles",
            "wings[1].aero.omegaa2"
        ]
    );
    assert!(found[0].1.contains("[1e-6, 10] mm"), "{:?}", found[0]);
    assert!(found[1].1.contains("integer"), "{:?}", found[1]);
    // stroke_drag has omega1 and coefficient: the nearest is omega1.
    assert!(
        found[2].1.contains("did you mean `omega1`"),
        "{:?}",
        found[2]
    );
}

#[test]
fn unknown_kinds_and_keys_suggest_the_nearest_name() {
    let text = example("hmf.toml").replace("kind = \"hmf_four_bar\"", "kind = \"hmf_fourbar\"");
    let found = problems(from_toml(&text).unwrap_err());
    assert_eq!(found[0].0, "drivetrain.kind");
    assert!(found[0].1.contains("did you mean `hmf_four_bar`"));
    let text = example("hmf.toml").replace("[options]", "[option]");
    let found = problems(from_toml(&text).unwrap_err());
    assert_eq!(found[0].0, "option");
    assert!(found[0].1.contains("did you mean `options`"));
    // An empty configuration name is a typed error, not "no constraints".
    let text = example("hmf.toml").replace("name = \"hmf_fixed\"", "name = \"\"");
    let (spec, _) = from_toml(&text).unwrap();
    assert_eq!(
        spec.device().unwrap_err().field(),
        Some("configuration.name")
    );
}

#[test]
fn parameter_paths_resolve_aliases_and_deprecated_names() {
    let (spec, _) = from_toml(&example("drag_parity.toml")).unwrap();
    let listed = paths::spec_paths(&spec);
    let k2 = paths::resolve(&spec, "drivetrain.k2").unwrap();
    assert_eq!(
        k2.targets,
        [("drivetrain.balance_spring".to_string(), None)]
    );
    assert_eq!(k2.notes.len(), 1);
    let hinge = paths::resolve(&spec, "wings[1].springs[5].cubic").unwrap();
    assert_eq!(hinge.targets[0].0, "wings[1].springs.hinge.cubic");
    let both = paths::resolve(&spec, "wings[*].aero.omega1").unwrap();
    assert_eq!(both.targets.len(), 2);
    let ratio = paths::resolve(&spec, "wings.left.omega_ratio").unwrap();
    let scaled = paths::apply(&spec, &[(&ratio, &serde_json::json!(0.5))]).unwrap();
    match &scaled.wings[0].aero {
        Some(paritysim_spec::Aero::StrokeDrag(a)) => assert_eq!(a.omega1, 0.5 * 31.3),
        other => panic!("{other:?}"),
    }
    let err = paths::resolve(&spec, "drivetrain.crank").unwrap_err();
    assert!(
        err.to_string()
            .contains("did you mean `drivetrain.crank_mm`"),
        "{err}"
    );
    for p in &listed {
        assert!(paths::resolve(&spec, &p.path).is_ok(), "{}", p.path);
    }
    let unit = |path: &str| listed.iter().find(|p| p.path == path).unwrap().unit.clone();
    assert_eq!(unit("actuator.stiffness"), "mN/mm");
    assert_eq!(unit("wings[0].inertia[2][2]"), "mg mm^2");
}

/// A spec crosses Python -> JSON -> Rust bit for bit: serde_json's default float parser is not
/// correctly rounded (`float_roundtrip` is enabled for this), and 0.42·31.3 came back 1 ulp off.
#[test]
fn floats_survive_json_bit_for_bit() {
    let values: [f64; 6] = [
        0.42 * 31.3,
        0.1 + 0.2,
        1.0 / 3.0,
        2.533928021702924,
        5e-324,
        1.7976931348623157e308,
    ];
    for x in values {
        let text = serde_json::to_string(&x).unwrap();
        let back: f64 = serde_json::from_str(&text).unwrap();
        assert_eq!(back.to_bits(), x.to_bits(), "{text}");
    }
}

/// A spec perturbed in place equals one perturbed on a copy, and the value is restored
/// whether the perturbed spec is valid or not.
#[test]
fn applying_in_place_equals_applying_to_a_copy_and_restores_the_value() {
    let (spec, _) = from_toml(&example("drag_parity.toml")).unwrap();
    let listed = paths::field_paths(&spec);
    let wings = paths::resolve_in(&spec, &listed, "wings[*].aero.omega1").unwrap();
    let spring = paths::resolve_in(&spec, &listed, "drivetrain.balance_spring").unwrap();
    let original = serde_json::to_value(&spec).unwrap();
    let mut value = original.clone();
    let (x, k) = (serde_json::json!(0.75), serde_json::json!(12.5));
    let overrides = [(&wings, &x), (&spring, &k)];
    let in_place = paths::apply_in_place(&spec, &mut value, &overrides).unwrap();
    assert_eq!(value, original);
    let copied = paths::apply_to(original.clone(), &overrides).unwrap();
    assert_eq!(
        serde_json::to_value(&in_place).unwrap(),
        serde_json::to_value(&copied).unwrap()
    );
    assert_eq!(
        serde_json::to_value(&in_place).unwrap()["drivetrain"]["balance_spring"],
        k
    );
    // A negative spring is refused, and the value is still restored.
    let negative = serde_json::json!(-1.0);
    let e = paths::apply_in_place(&spec, &mut value, &[(&wings, &x), (&spring, &negative)])
        .unwrap_err();
    assert_eq!(e.kind(), "InvalidParameter", "{e}");
    assert_eq!(value, original);
}

/// The listing without texts (what resolving a name reads) holds the same paths, units and
/// values as `spec_paths`; `get` reads what `set` writes.
#[test]
fn field_paths_are_spec_paths_without_their_texts_and_get_reads_what_set_writes() {
    for file in ["drag_parity.toml", "hmf.toml"] {
        let (spec, _) = from_toml(&example(file)).unwrap();
        let full = paths::spec_paths(&spec);
        let lean = paths::field_paths(&spec);
        assert_eq!(full.len(), lean.len(), "{file}");
        for (f, l) in full.iter().zip(&lean) {
            assert_eq!((&f.path, &f.unit, &f.value), (&l.path, &l.unit, &l.value));
            assert!(l.allowed.is_empty());
        }
        assert!(full.iter().all(|f| !f.allowed.is_empty()), "{file}");
        let mut value = serde_json::to_value(&spec).unwrap();
        for info in &full {
            assert_eq!(
                paths::get(&value, &info.path).unwrap_or(&serde_json::Value::Null),
                &info.value,
                "{}",
                info.path
            );
        }
        paths::set(
            &mut value,
            "drivetrain.balance_spring",
            serde_json::json!(7.5),
        )
        .unwrap();
        assert_eq!(
            paths::get(&value, "drivetrain.balance_spring"),
            Some(&serde_json::json!(7.5))
        );
        assert_eq!(paths::get(&value, "drivetrain.no_such_field"), None);
    }
}

/// Resolving names against the fields on their way only (`resolve_all`) gives the parameters
/// and listed entries of the whole listing, for every path and every alias, and the same
/// error (with the same nearest paths) for an unknown name.
#[test]
fn names_resolved_along_their_paths_equal_names_resolved_against_the_whole_listing() {
    for file in ["drag_parity.toml", "hmf.toml"] {
        let (spec, _) = from_toml(&example(file)).unwrap();
        let all = paths::field_paths(&spec);
        let mut names: Vec<String> = all.iter().map(|i| i.path.clone()).collect();
        names.extend(
            [
                "wings[*].aero.omega1",
                "wings.left.springs.hinge.stiffness",
                "wings.right.omega_ratio",
                "wings[0].omega_ratio",
                "actuator.frequency_hz",
                "actuator.voltage_v",
                "drivetrain.k2",
            ]
            .map(String::from),
        );
        for name in &names {
            let whole = paths::resolve_in(&spec, &all, name);
            let Ok(whole) = whole else { continue }; // a name this spec does not have
            let (along, listed) = paths::resolve_all(&spec, std::slice::from_ref(name)).unwrap();
            assert_eq!(along[0], whole, "{file}: {name}");
            assert!(
                listed.len() < all.len() / 4,
                "{file}: {name}: {}",
                listed.len()
            );
            for (target, _) in &whole.targets {
                let entry = |l: &[paths::PathInfo]| l.iter().find(|i| &i.path == target).cloned();
                assert_eq!(entry(&listed), entry(&all), "{file}: {target}");
            }
        }
        // A typo of a real path: one letter dropped.
        let real = &all
            .iter()
            .find(|i| i.path.ends_with("stiffness"))
            .unwrap()
            .path;
        let unknown = [real[..real.len() - 1].to_string()];
        let e = paths::resolve_all(&spec, &unknown).unwrap_err();
        let whole = paths::resolve_in(&spec, &all, &unknown[0]).unwrap_err();
        assert_eq!(e.to_string(), whole.to_string());
        assert!(e.to_string().contains(real.as_str()), "{e}");
    }
}

/// A spec read in place checks the schema along the overridden fields only: for every field
/// of two specs set to values in and out of its range, or of the wrong type, it gives the
/// spec or the error (path, value, allowed range) that checking the whole value gives.
#[test]
fn a_spec_checked_along_its_overridden_fields_equals_one_checked_whole() {
    for file in ["drag_parity.toml", "hmf.toml"] {
        let (spec, _) = from_toml(&example(file)).unwrap();
        let original = serde_json::to_value(&spec).unwrap();
        let mut value = original.clone();
        let (mut refused, mut read) = (0, 0);
        for info in paths::field_paths(&spec) {
            let param = paths::Parameter {
                name: info.path.clone(),
                targets: vec![(info.path.clone(), None)],
                notes: Vec::new(),
            };
            for new in [
                serde_json::json!(-1e9),
                serde_json::json!(1e9),
                serde_json::json!(0.5),
                serde_json::json!("x"),
                serde_json::json!(null),
            ] {
                let overrides = [(&param, &new)];
                let whole = paths::apply_to(original.clone(), &overrides);
                let along = paths::apply_in_place(&spec, &mut value, &overrides);
                assert_eq!(value, original, "{file}: {}", info.path);
                match (whole, along) {
                    (Ok(w), Ok(a)) => {
                        read += 1;
                        assert_eq!(
                            serde_json::to_value(w).unwrap(),
                            serde_json::to_value(a).unwrap()
                        );
                    }
                    (Err(w), Err(a)) => {
                        refused += 1;
                        assert_eq!(w.to_string(), a.to_string(), "{file}: {}", info.path);
                    }
                    (w, a) => panic!("{file}: {} = {new}: whole {w:?}, along {a:?}", info.path),
                }
            }
        }
        assert!(
            refused > 50 && read > 50,
            "{file}: {refused} refused, {read} read"
        );
    }
}

#[test]
fn a_document_that_is_not_a_table_names_spec() {
    // The root's problem named the empty field: "invalid `` = []: must be a table".
    let e = from_json("[]").unwrap_err();
    assert_eq!(e.field(), Some("spec"));
    assert!(e.to_string().contains("invalid `spec` = "), "{e}");
}

#[test]
fn a_continuation_start_out_of_range_names_its_path_once() {
    // The start's error was prefixed with the path it already named:
    // `drivetrain.balance_spring.drivetrain.balance_spring`.
    let (spec, _) = from_toml(&example("drag_parity.toml")).unwrap();
    let e = paritysim_spec::continuation::continue_path(
        &spec,
        "drivetrain.balance_spring",
        -5.0,
        10.0,
        &Default::default(),
    )
    .unwrap_err();
    assert_eq!(e.field(), Some("drivetrain.balance_spring"), "{e}");
}
