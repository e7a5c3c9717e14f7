//! Deprecated spec spellings, rewritten to the current names before validation.
//!
//! | old                                   | new                                          |
//! |---------------------------------------|----------------------------------------------|
//! | `drivetrain.balance_stiffness`        | `drivetrain.balance_spring`                  |
//! | `wings[i].springs = [6 tables]`       | `wings[i].springs.{stroke, ..., hinge}`      |
//! | `wings[i].tunable_hinge.k0 / k1 / k2` | `stiffness_at_zero / stiffness_slope / stiffness_curvature` |
//! | `wings[i].aero.kind = "none"`         | no `aero` table                              |
//! | `configuration = "<name>"`            | `configuration.name = "<name>"`              |

use serde_json::{Map, Value};

use crate::wing::SPRING_NAMES;

/// The tunable-hinge renames `(old, new)`.
pub const HINGE_RENAMES: [(&str, &str); 3] = [
    ("k0", "stiffness_at_zero"),
    ("k1", "stiffness_slope"),
    ("k2", "stiffness_curvature"),
];

/// Rewrites deprecated spellings in place; returns one message per rewrite.
pub fn migrate(spec: &mut Value) -> Vec<String> {
    let mut notes = Vec::new();
    let Some(root) = spec.as_object_mut() else {
        return notes;
    };
    if let Some(Value::String(name)) = root.get("configuration").cloned() {
        let mut table = Map::new();
        table.insert("name".into(), Value::String(name));
        root.insert("configuration".into(), Value::Object(table));
        notes.push("`configuration = \"<name>\"` is deprecated: use `configuration.name`".into());
    }
    if let Some(Value::Object(d)) = root.get_mut("drivetrain") {
        if let Some(k2) = d.remove("balance_stiffness") {
            let one_dof = d.get("kind").and_then(Value::as_str) == Some("hmf_four_bar");
            // A 1-DOF drivetrain has no q2: its old K2 never acted and is dropped.
            if !(one_dof && k2.as_f64() == Some(0.0)) {
                d.insert("balance_spring".into(), k2);
            }
            notes.push(
                "`drivetrain.balance_stiffness` is deprecated: use `drivetrain.balance_spring`"
                    .into(),
            );
        }
    }
    if let Some(Value::Array(wings)) = root.get_mut("wings") {
        for (i, wing) in wings.iter_mut().enumerate() {
            let Some(w) = wing.as_object_mut() else {
                continue;
            };
            if let Some(Value::Array(list)) = w.get("springs") {
                if list.len() == SPRING_NAMES.len() {
                    let named: Map<String, Value> = SPRING_NAMES
                        .iter()
                        .zip(list.iter())
                        .map(|(name, s)| ((*name).to_string(), s.clone()))
                        .collect();
                    w.insert("springs".into(), Value::Object(named));
                    notes.push(format!(
                        "`wings[{i}].springs` as a list of 6 is deprecated: use named springs \
                         `springs.{{{}}}`",
                        SPRING_NAMES.join(", ")
                    ));
                }
            }
            if let Some(Value::Object(h)) = w.get_mut("tunable_hinge") {
                for (old, new) in HINGE_RENAMES {
                    if let Some(v) = h.remove(old) {
                        h.insert(new.into(), v);
                        notes.push(format!(
                            "`wings[{i}].tunable_hinge.{old}` is deprecated: use `{new}`"
                        ));
                    }
                }
            }
            let vacuum = w
                .get("aero")
                .and_then(|a| a.get("kind"))
                .and_then(Value::as_str)
                == Some("none");
            if vacuum {
                w.remove("aero");
                notes.push(format!(
                    "`wings[{i}].aero.kind = \"none\"` is deprecated: omit `aero`"
                ));
            }
        }
    }
    notes
}

/// The current spelling of a deprecated parameter path (None: not deprecated).
pub fn migrate_path(path: &str) -> Option<String> {
    if path == "drivetrain.k2" || path == "drivetrain.balance_stiffness" {
        return Some("drivetrain.balance_spring".into());
    }
    if let Some(at) = path.find(".springs[") {
        let rest = &path[at + ".springs[".len()..];
        let close = rest.find(']')?;
        let index: usize = rest[..close].parse().ok()?;
        let name = SPRING_NAMES.get(index)?;
        return Some(format!(
            "{}.springs.{name}{}",
            &path[..at],
            &rest[close + 1..]
        ));
    }
    for (old, new) in HINGE_RENAMES {
        if let Some(head) = path.strip_suffix(&format!(".tunable_hinge.{old}")) {
            return Some(format!("{head}.tunable_hinge.{new}"));
        }
    }
    None
}
