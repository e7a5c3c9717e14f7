//! The one path language for sweeps, calibration and overrides.
//!
//! Canonical paths are dotted field names with list indices:
//! `wings[0].springs.hinge.stiffness`, `wings[1].inertia[0][0]`, `drivetrain.balance_spring`,
//! `actuator.waveform.frequency_hz`, `options.max_cycles`, `configuration.name`. Aliases:
//!
//! * `wings.left.<field>` / `wings.right.<field>`: `wings[0]` / `wings[1]` of a two-wing spec;
//! * `wings[*].<field>`: every wing at once;
//! * `actuator.frequency_hz`, `actuator.amplitude_v` (or `actuator.voltage_v`):
//!   the sine waveform's fields;
//! * `wings[i].omega_ratio`: multiplies that wing's `aero.omega1` (a cut wing of Table 3.2);
//! * deprecated spellings ([`crate::migrate::migrate_path`]): `drivetrain.k2`,
//!   `drivetrain.balance_stiffness`, `wings[i].springs[j].<field>`, `tunable_hinge.k0..k2`.

use paritysim_error::{Error, Result};
use serde::Serialize;
use serde_json::Value;

use crate::migrate::migrate_path;
use crate::schema::{
    Branch, Enter, classify, describe, enter, join, node, schema, suggestion_for, unit,
};
use crate::spec::Simulation;

/// One settable path of a spec.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PathInfo {
    /// Canonical path.
    pub path: String,
    /// Unit (`1` for dimensionless, empty for names and flags).
    pub unit: String,
    /// What the path accepts (type, range and unit).
    pub allowed: String,
    /// Its value in this spec (`null` when absent).
    pub value: Value,
}

/// Every canonical path of `spec`, in declaration order.
pub fn spec_paths(spec: &Simulation) -> Vec<PathInfo> {
    listing(
        spec,
        Walk {
            texts: true,
            only: None,
        },
    )
}

/// [`spec_paths`] without the `allowed` texts (left empty): what resolving a name needs, at a
/// tenth of the cost (the texts were 0.5 ms a call, per sweep row with gradients and per
/// `with_paths`; docs/findings.md §30).
pub fn field_paths(spec: &Simulation) -> Vec<PathInfo> {
    listing(
        spec,
        Walk {
            texts: false,
            only: None,
        },
    )
}

fn listing(spec: &Simulation, walk: Walk<'_>) -> Vec<PathInfo> {
    listing_of(
        &serde_json::to_value(spec).expect("a spec serialises"),
        walk,
    )
}

/// [`listing`] of a spec already serialised as `value`.
fn listing_of(value: &Value, walk: Walk<'_>) -> Vec<PathInfo> {
    let mut out = Vec::new();
    walk.walk(value, schema(), "", "", &mut out);
    out
}

/// A walk of a spec value along its schema, with or without the `allowed` texts, into every
/// field or only those on the way to the paths `only` (relative to the walk's node).
#[derive(Clone, Copy)]
struct Walk<'a> {
    texts: bool,
    only: Option<&'a [&'a str]>,
}

impl Walk<'_> {
    /// The walk of the child `step` of this node (`None`: not on the way), given to `then`.
    fn enter(self, step: &str, then: impl FnOnce(Walk<'_>)) {
        match self.only.map(|only| enter(only, step)) {
            None | Some(Enter::All) => then(Walk { only: None, ..self }),
            Some(Enter::Only(below)) => then(Walk {
                texts: self.texts,
                only: Some(&below),
            }),
            Some(Enter::Skip) => {}
        }
    }

    fn leaf(
        self,
        path: &str,
        value: &Value,
        schema: &Value,
        parent_unit: &str,
        out: &mut Vec<PathInfo>,
    ) {
        let n = node(schema);
        let own = unit(&n).unwrap_or_else(|| parent_unit.to_string());
        out.push(PathInfo {
            path: path.to_string(),
            unit: own,
            allowed: if self.texts {
                describe(schema)
            } else {
                String::new()
            },
            value: value.clone(),
        });
    }

    fn walk(
        self,
        value: &Value,
        schema: &Value,
        path: &str,
        parent_unit: &str,
        out: &mut Vec<PathInfo>,
    ) {
        let s = node(schema);
        let unit_here = unit(&s).unwrap_or_else(|| parent_unit.to_string());
        match classify(&s) {
            Branch::Optional(inner) => {
                if value.is_null() {
                    if is_scalar_schema(inner) {
                        self.leaf(path, value, schema, &unit_here, out);
                    }
                } else {
                    self.walk(value, inner, path, &unit_here, out);
                }
                return;
            }
            Branch::Tagged(variants) => {
                let kind = value
                    .get("kind")
                    .and_then(Value::as_str)
                    .unwrap_or_default();
                let tags: Vec<&str> = variants.iter().map(|(t, _)| t.as_str()).collect();
                let kind_path = join(path, "kind");
                if self
                    .only
                    .is_none_or(|only| !matches!(enter(only, "kind"), Enter::Skip))
                {
                    out.push(PathInfo {
                        path: kind_path,
                        unit: String::new(),
                        allowed: if self.texts {
                            format!("one of {}", tags.join(", "))
                        } else {
                            String::new()
                        },
                        value: Value::String(kind.to_string()),
                    });
                }
                if let Some((_, branch)) = variants.iter().find(|(t, _)| t == kind) {
                    self.walk_object(value, branch, path, &unit_here, out);
                }
                return;
            }
            Branch::Untagged(_) => {
                self.leaf(path, value, schema, &unit_here, out);
                return;
            }
            Branch::Plain => {}
        }
        if s.contains_key("properties") {
            self.walk_object(value, &s, path, &unit_here, out);
        } else if let (Some(items), Value::Array(list)) = (s.get("items"), value) {
            let fixed = s.get("minItems").is_some() && s.get("minItems") == s.get("maxItems");
            if fixed || !is_scalar_schema(items) {
                for (i, v) in list.iter().enumerate() {
                    self.enter(&format!("[{i}]"), |walk| {
                        walk.walk(v, items, &format!("{path}[{i}]"), &unit_here, out);
                    });
                }
            } else {
                self.leaf(path, value, schema, &unit_here, out);
            }
        } else {
            self.leaf(path, value, schema, &unit_here, out);
        }
    }

    fn walk_object(
        self,
        value: &Value,
        s: &serde_json::Map<String, Value>,
        path: &str,
        parent_unit: &str,
        out: &mut Vec<PathInfo>,
    ) {
        let Some(props) = s.get("properties").and_then(Value::as_object) else {
            return;
        };
        for (k, sub) in props {
            if k == "kind" && crate::schema::tag_of(s).is_some() {
                continue;
            }
            self.enter(k, |walk| {
                let v = value.get(k).unwrap_or(&Value::Null);
                walk.walk(v, sub, &join(path, k), parent_unit, out);
            });
        }
    }
}

fn is_scalar_schema(s: &Value) -> bool {
    let n = node(s);
    if n.contains_key("enum") || n.contains_key("const") {
        return true;
    }
    match n.get("type") {
        Some(Value::String(t)) => {
            matches!(t.as_str(), "number" | "integer" | "string" | "boolean")
        }
        Some(Value::Array(ts)) => ts
            .iter()
            .filter_map(Value::as_str)
            .any(|t| matches!(t, "number" | "integer" | "string" | "boolean")),
        _ => false,
    }
}

/// Where a parameter goes: canonical paths and an optional scale (for `omega_ratio`).
#[derive(Clone, Debug, PartialEq)]
pub struct Parameter {
    /// The name the caller used.
    pub name: String,
    /// `(canonical path, scale)`; the value written is `value * scale` when a scale is given.
    pub targets: Vec<(String, Option<f64>)>,
    /// Deprecation notes for the name.
    pub notes: Vec<String>,
}

/// Resolves a parameter name against `spec`.
///
/// # Errors
/// [`Error::InvalidParameter`] naming the path, with the nearest valid path.
pub fn resolve(spec: &Simulation, name: &str) -> Result<Parameter> {
    let (mut parameters, _) = resolve_all(spec, &[name.to_string()])?;
    Ok(parameters.remove(0))
}

/// [`resolve`] for several names, and the paths they were resolved against: only the fields
/// on the way to the paths the names can spell are listed (the whole listing was 1.1 M
/// instructions a `ps.sensitivity` for a few names; docs/findings.md §30). An unknown name is
/// resolved again against the whole listing, for its error's nearest paths.
///
/// # Errors
/// See [`resolve`].
pub fn resolve_all(spec: &Simulation, names: &[String]) -> Result<(Vec<Parameter>, Vec<PathInfo>)> {
    resolve_all_in(
        spec,
        &serde_json::to_value(spec).expect("a spec serialises"),
        names,
    )
}

/// [`resolve_all`] with the spec also given serialised (`value`: a caller that has it
/// saves serialising it again).
pub fn resolve_all_in(
    spec: &Simulation,
    value: &Value,
    names: &[String],
) -> Result<(Vec<Parameter>, Vec<PathInfo>)> {
    let wanted: Vec<String> = names
        .iter()
        .filter_map(|name| spellings(spec, name).ok())
        .flat_map(|(paths, _)| paths)
        .map(|p| match p.strip_suffix(".omega_ratio") {
            Some(head) => format!("{head}.aero.omega1"),
            None => p,
        })
        .collect();
    let resolve = |paths: Vec<PathInfo>| -> Result<(Vec<Parameter>, Vec<PathInfo>)> {
        let parameters = names
            .iter()
            .map(|name| resolve_in(spec, &paths, name))
            .collect::<Result<Vec<_>>>()?;
        Ok((parameters, paths))
    };
    let wanted: Vec<&str> = wanted.iter().map(String::as_str).collect();
    let only = Walk {
        texts: false,
        only: Some(&wanted),
    };
    resolve(listing_of(value, only)).or_else(|_| resolve(field_paths(spec)))
}

/// The canonical paths `name` spells (every wing of a `wings[*]` name, `wings[0]` for
/// `wings.left`, today's spelling of a deprecated one, the waveform's field of an `actuator.`
/// shorthand), and the deprecation notes; an `omega_ratio` is left for [`resolve_in`].
fn spellings(spec: &Simulation, name: &str) -> Result<(Vec<String>, Vec<String>)> {
    let mut notes = Vec::new();
    let n_wings = spec.wings.len();
    let mut expanded: Vec<String> = if let Some(rest) = name.strip_prefix("wings[*].") {
        (0..n_wings).map(|i| format!("wings[{i}].{rest}")).collect()
    } else if let Some(rest) = name.strip_prefix("wings.left.") {
        side(n_wings, 0, rest, name)?
    } else if let Some(rest) = name.strip_prefix("wings.right.") {
        side(n_wings, 1, rest, name)?
    } else {
        vec![name.to_string()]
    };
    for p in &mut expanded {
        if let Some(new) = migrate_path(p) {
            notes.push(format!("parameter `{p}` is deprecated: use `{new}`"));
            *p = new;
        }
        if let Some(field) = p.strip_prefix("actuator.") {
            if matches!(field, "frequency_hz" | "amplitude_v" | "voltage_v") {
                let field = if field == "voltage_v" {
                    "amplitude_v"
                } else {
                    field
                };
                *p = format!("actuator.waveform.{field}");
            }
        }
    }
    Ok((expanded, notes))
}

/// [`resolve`] with the paths already listed.
///
/// # Errors
/// See [`resolve`].
pub fn resolve_in(spec: &Simulation, paths: &[PathInfo], name: &str) -> Result<Parameter> {
    let (expanded, notes) = spellings(spec, name)?;
    let mut targets = Vec::new();
    for p in expanded {
        if let Some(head) = p.strip_suffix(".omega_ratio") {
            let omega = format!("{head}.aero.omega1");
            let base = paths
                .iter()
                .find(|i| i.path == omega)
                .and_then(|i| i.value.as_f64())
                .ok_or_else(|| unknown(name, paths))?;
            targets.push((omega, Some(base)));
        } else if paths.iter().any(|i| i.path == p) {
            targets.push((p, None));
        } else {
            return Err(unknown(name, paths));
        }
    }
    Ok(Parameter {
        name: name.to_string(),
        targets,
        notes,
    })
}

fn side(n_wings: usize, index: usize, rest: &str, name: &str) -> Result<Vec<String>> {
    if n_wings != 2 {
        return Err(Error::invalid(
            name.to_string(),
            "<left/right alias>",
            format!("a two-wing spec (this one has {n_wings}); use wings[0].<field>"),
        ));
    }
    Ok(vec![format!("wings[{index}].{rest}")])
}

/// The shorthand spellings [`resolve_in`] accepts besides the canonical paths.
fn aliases(paths: &[PathInfo]) -> Vec<String> {
    let shorthand = [
        "actuator.voltage_v",
        "actuator.amplitude_v",
        "actuator.frequency_hz",
    ];
    let mut out: Vec<String> = shorthand.into_iter().map(String::from).collect();
    for p in paths {
        for (index, side) in [(0, "left"), (1, "right")] {
            if let Some(rest) = p.path.strip_prefix(&format!("wings[{index}].")) {
                out.push(format!("wings.{side}.{rest}"));
                if rest == "aero.omega1" {
                    out.push(format!("wings.{side}.omega_ratio"));
                    out.push(format!("wings[{index}].omega_ratio"));
                }
            }
        }
    }
    out
}

/// An unknown path: the nearest valid spellings (canonical paths and their aliases; siblings
/// of its last segment first on a tie), a handful at most (`schema::suggestion_for`).
fn unknown(name: &str, paths: &[PathInfo]) -> Error {
    let aliases = aliases(paths);
    let spellings = paths
        .iter()
        .map(|p| p.path.as_str())
        .chain(aliases.iter().map(String::as_str));
    // A handful of close names, never the whole list: `ps.spec_paths(spec)` prints that.
    let listed = format!("ps.spec_paths(spec) lists all {}", paths.len());
    let allowed = suggestion_for(
        name,
        spellings,
        "a parameter path of this spec",
        Some(&listed),
    );
    Error::invalid(name.to_string(), "<unknown parameter path>", allowed)
}

/// The field at `path` (canonical) in a spec value, if there is one.
pub fn get<'a>(value: &'a Value, path: &str) -> Option<&'a Value> {
    tokens(path)?.iter().try_fold(value, |node, t| match t {
        Token::Key(k) => node.get(k),
        Token::Index(i) => node.get(*i),
    })
}

/// [`get`], mutable: the existing field at `path`.
fn get_mut<'a>(value: &'a mut Value, path: &str) -> Option<&'a mut Value> {
    tokens(path)?.iter().try_fold(value, |node, t| match t {
        Token::Key(k) => node.get_mut(k),
        Token::Index(i) => node.get_mut(*i),
    })
}

/// Sets `path` (canonical) in a spec value.
///
/// # Errors
/// [`Error::InvalidParameter`] when the path does not exist in `value`.
pub fn set(value: &mut Value, path: &str, new: Value) -> Result<()> {
    let bad = || Error::invalid(path.to_string(), "<path>", "an existing field path");
    let mut node = value;
    let tokens = tokens(path).ok_or_else(bad)?;
    let (last, head) = tokens.split_last().ok_or_else(bad)?;
    for t in head {
        node = match t {
            Token::Key(k) => node
                .as_object_mut()
                .ok_or_else(bad)?
                .entry(k.to_string())
                .or_insert_with(|| Value::Object(Default::default())),
            Token::Index(i) => node
                .as_array_mut()
                .and_then(|a| a.get_mut(*i))
                .ok_or_else(bad)?,
        };
    }
    match last {
        Token::Key(k) => {
            node.as_object_mut()
                .ok_or_else(bad)?
                .insert(k.to_string(), new);
        }
        Token::Index(i) => {
            *node
                .as_array_mut()
                .and_then(|a| a.get_mut(*i))
                .ok_or_else(bad)? = new;
        }
    }
    Ok(())
}

enum Token<'a> {
    Key(&'a str),
    Index(usize),
}

fn tokens(path: &str) -> Option<Vec<Token<'_>>> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (key, mut rest) = match part.find('[') {
            Some(at) => (&part[..at], &part[at..]),
            None => (part, ""),
        };
        if !key.is_empty() {
            out.push(Token::Key(key));
        }
        while let Some(r) = rest.strip_prefix('[') {
            let close = r.find(']')?;
            out.push(Token::Index(r[..close].parse().ok()?));
            rest = &r[close + 1..];
        }
        if !rest.is_empty() {
            return None;
        }
    }
    Some(out)
}

/// `spec` with every `(parameter, value)` applied (a `null` value keeps the base value).
///
/// # Errors
/// The typed errors of [`crate::from_value`] for the resulting spec.
pub fn apply(spec: &Simulation, overrides: &[(&Parameter, &Value)]) -> Result<Simulation> {
    apply_to(
        serde_json::to_value(spec).expect("a spec serialises"),
        overrides,
    )
}

/// [`apply`] to a spec already serialised (`serde_json::to_value`): the serialisation was
/// nine tenths of an [`apply`], paid once where one spec is varied many times.
///
/// # Errors
/// As [`apply`].
pub fn apply_to(mut value: Value, overrides: &[(&Parameter, &Value)]) -> Result<Simulation> {
    set_overrides(&mut value, overrides)?;
    crate::from_value(value).map(|(s, _)| s)
}

/// [`apply_to`] without a copy of `value`, the serialisation of the valid spec `base`: the
/// overrides are set in it, the spec is read with the schema checked along the overridden
/// fields only (the rest was valid; overrides under one top-level field read that field alone
/// into a copy of `base`), and the old values are put back. A copy of the §3.3 spec's value
/// cost half of reading it back (12.5 of 25.6 µs).
///
/// # Errors
/// As [`apply`]; `value` is restored in every case.
pub fn apply_in_place(
    base: &Simulation,
    value: &mut Value,
    overrides: &[(&Parameter, &Value)],
) -> Result<Simulation> {
    // Each target's old value, taken out as the new one goes in.
    let mut old: Vec<(&str, Value)> = Vec::new();
    let mut absent = false;
    'set: for (param, v) in overrides {
        if v.is_null() {
            continue;
        }
        for (path, scale) in &param.targets {
            let Some(field) = get_mut(value, path) else {
                absent = true;
                break 'set;
            };
            old.push((path, std::mem::replace(field, scaled(v, *scale))));
        }
    }
    let spec = if absent {
        None
    } else {
        let changed: Vec<&str> = old.iter().map(|(path, _)| *path).collect();
        Some(crate::from_changed(base, value, &changed))
    };
    for (path, before) in old.into_iter().rev() {
        *get_mut(value, path).expect("a field just set") = before;
    }
    // A field the value leaves out: set on a copy.
    spec.unwrap_or_else(|| apply_to(value.clone(), overrides))
}

/// The value written at a target: `v × scale` (an `omega_ratio`), or `v`.
fn scaled(v: &Value, scale: Option<f64>) -> Value {
    match (scale, v.as_f64()) {
        (Some(s), Some(x)) => Value::from(x * s),
        _ => v.clone(),
    }
}

/// Sets every `(parameter, value)` in `value` (scaled per target).
fn set_overrides(value: &mut Value, overrides: &[(&Parameter, &Value)]) -> Result<()> {
    for (param, v) in overrides {
        if v.is_null() {
            continue;
        }
        for (path, scale) in &param.targets {
            set(value, path, scaled(v, *scale))?;
        }
    }
    Ok(())
}

/// `spec` with `{path: value}` applied, the values a JSON object keyed by any spelling
/// [`resolve_in`] accepts; also returns the deprecation notes of the paths.
///
/// # Errors
/// [`Error::InvalidParameter`] on `values` when it is not a JSON object, for an unknown path
/// (with the nearest valid one); the typed errors of the resulting spec.
pub fn apply_json(spec: &Simulation, values: &str) -> Result<(Simulation, Vec<String>)> {
    let values: serde_json::Map<String, Value> = serde_json::from_str(values)
        .map_err(|e| Error::invalid("values", e.to_string(), "a JSON object of path: value"))?;
    let listed = field_paths(spec);
    let params = values
        .keys()
        .map(|k| resolve_in(spec, &listed, k))
        .collect::<Result<Vec<_>>>()?;
    let pairs: Vec<_> = params.iter().zip(values.values()).collect();
    let out = apply(spec, &pairs)?;
    Ok((out, params.into_iter().flat_map(|p| p.notes).collect()))
}
