//! The JSON Schema of the spec (generated from the types by `schemars`) and the validator
//! that walks a spec value against it, collecting every problem with its dotted path.
//!
//! The schema is the one source of each field's unit (`x-unit`), range
//! (`minimum`/`maximum`/`exclusiveMinimum`/`exclusiveMaximum`), default and documentation:
//! validation, [`crate::paths`] and the Python dataclasses all read it.

use std::borrow::Cow;
use std::sync::OnceLock;

use paritysim_error::Problem;
use serde_json::{Map, Value};

use crate::spec::Simulation;

/// The JSON Schema (draft 2020-12) of [`Simulation`].
pub fn schema() -> &'static Value {
    static SCHEMA: OnceLock<Value> = OnceLock::new();
    SCHEMA.get_or_init(|| {
        let schema = schemars::schema_for!(Simulation);
        serde_json::to_value(schema).expect("a generated schema serialises")
    })
}

/// The schema as pretty JSON (what `python/paritysim/spec.schema.json` holds).
pub fn schema_json() -> String {
    serde_json::to_string_pretty(schema()).expect("a generated schema serialises") + "\n"
}

/// A schema node with its `$ref` resolved and merged with its sibling keywords.
pub(crate) fn node(s: &Value) -> Cow<'_, Map<String, Value>> {
    let empty = || Cow::Owned(Map::new());
    let Some(map) = s.as_object() else {
        return empty();
    };
    let Some(reference) = map.get("$ref").and_then(Value::as_str) else {
        return Cow::Borrowed(map);
    };
    let name = reference.trim_start_matches("#/$defs/");
    let Some(target) = schema().get("$defs").and_then(|d| d.get(name)) else {
        return empty();
    };
    // Annotations beside a `$ref` (description, default) change nothing the walker reads: no
    // merge, no copy.
    if map
        .keys()
        .all(|k| matches!(k.as_str(), "$ref" | "description" | "default"))
    {
        return node(target);
    }
    let mut merged = node(target).into_owned();
    for (k, v) in map {
        match (k.as_str(), merged.get_mut(k)) {
            ("$ref", _) => {}
            ("properties", Some(Value::Object(props))) => {
                for (pk, pv) in v.as_object().into_iter().flatten() {
                    props.insert(pk.clone(), pv.clone());
                }
            }
            ("required", Some(Value::Array(req))) => {
                req.extend(v.as_array().into_iter().flatten().cloned());
            }
            _ => {
                merged.insert(k.clone(), v.clone());
            }
        }
    }
    Cow::Owned(merged)
}

fn branches(s: &Map<String, Value>) -> Option<&Vec<Value>> {
    s.get("oneOf")
        .or_else(|| s.get("anyOf"))
        .and_then(Value::as_array)
}

fn is_null_schema(s: &Value) -> bool {
    node(s).get("type").and_then(Value::as_str) == Some("null")
}

/// The `kind` of a tagged-enum branch.
pub(crate) fn tag_of(s: &Map<String, Value>) -> Option<String> {
    let kind = s.get("properties")?.get("kind")?;
    let kind = node(kind);
    kind.get("const")
        .or_else(|| kind.get("enum").and_then(|e| e.get(0)))
        .and_then(Value::as_str)
        .map(str::to_string)
}

/// The branch of a tagged enum (`kind = ...`), an `Option` (`T | null`) or `None`.
pub(crate) enum Branch<'s> {
    /// A plain node.
    Plain,
    /// `Option<T>`: the `T` branch.
    Optional(&'s Value),
    /// Tagged enum: `(tag, branch)` pairs.
    Tagged(Vec<(String, Cow<'s, Map<String, Value>>)>),
    /// Untagged alternatives.
    Untagged(&'s Vec<Value>),
}

pub(crate) fn classify(s: &Map<String, Value>) -> Branch<'_> {
    let Some(list) = branches(s) else {
        return Branch::Plain;
    };
    let non_null: Vec<&Value> = list.iter().filter(|b| !is_null_schema(b)).collect();
    let tagged: Vec<_> = non_null
        .iter()
        .filter_map(|b| {
            let n = node(b);
            tag_of(&n).map(|t| (t, n))
        })
        .collect();
    if !tagged.is_empty() && tagged.len() == non_null.len() {
        return Branch::Tagged(tagged);
    }
    if non_null.len() == 1 {
        return Branch::Optional(non_null[0]);
    }
    Branch::Untagged(list)
}

fn types(s: &Map<String, Value>) -> Vec<&str> {
    match s.get("type") {
        Some(Value::String(t)) => vec![t.as_str()],
        Some(Value::Array(ts)) => ts.iter().filter_map(Value::as_str).collect(),
        _ => Vec::new(),
    }
}

fn num(s: &Map<String, Value>, key: &str) -> Option<f64> {
    s.get(key).and_then(Value::as_f64)
}

/// The unit of a field (`x-unit`), if any.
pub(crate) fn unit(s: &Map<String, Value>) -> Option<String> {
    s.get("x-unit").and_then(Value::as_str).map(str::to_string)
}

/// Human-readable range of a numeric node, e.g. `in (0, 10] mm`.
pub(crate) fn range_text(s: &Map<String, Value>) -> String {
    let lo = num(s, "exclusiveMinimum")
        .map(|v| format!("({v}"))
        .or_else(|| num(s, "minimum").map(|v| format!("[{v}")));
    let hi = num(s, "exclusiveMaximum")
        .map(|v| format!("{v})"))
        .or_else(|| num(s, "maximum").map(|v| format!("{v}]")));
    let range = match (lo, hi) {
        (Some(lo), Some(hi)) => format!("in {lo}, {hi}"),
        (Some(lo), None) => format!("in {lo}, inf)"),
        (None, Some(hi)) => format!("in (-inf, {hi}"),
        (None, None) => String::new(),
    };
    match unit(s) {
        Some(u) if u != "1" => format!("{range} {u}"),
        _ => range,
    }
}

/// What a node accepts, for messages and [`crate::paths`].
pub(crate) fn describe(s: &Value) -> String {
    let s = node(s);
    if let Some(values) = s.get("enum").and_then(Value::as_array) {
        return format!("one of {}", join_values(values));
    }
    if let Some(c) = s.get("const") {
        return format!("{c}");
    }
    match classify(&s) {
        Branch::Tagged(t) => {
            let tags: Vec<_> = t.iter().map(|(k, _)| k.as_str()).collect();
            return format!("a table with kind = one of {}", tags.join(", "));
        }
        Branch::Optional(inner) => return describe(inner),
        Branch::Untagged(list) => {
            let parts: Vec<_> = list.iter().map(describe).collect();
            return parts.join(" or ");
        }
        Branch::Plain => {}
    }
    let t = types(&s);
    if t.contains(&"integer") {
        format!("an integer {}", range_text(&s))
            .trim_end()
            .to_string()
    } else if t.contains(&"number") {
        format!("a number {}", range_text(&s))
            .trim_end()
            .to_string()
    } else if t.contains(&"string") {
        "a string".into()
    } else if t.contains(&"boolean") {
        "true or false".into()
    } else if t.contains(&"array") {
        "a list".into()
    } else if t.contains(&"object") {
        "a table".into()
    } else {
        "a value".into()
    }
}

fn join_values(values: &[Value]) -> String {
    values
        .iter()
        .map(|v| v.as_str().map_or_else(|| v.to_string(), str::to_string))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Joins a parent path and a key.
pub(crate) fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

/// The nearest candidate by edit distance, when it is close enough to be a typo.
pub fn nearest<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    candidates
        .into_iter()
        .map(|c| (strsim::levenshtein(word, c), c))
        .filter(|(d, c)| *d <= 2.max(word.len().max(c.len()) / 3))
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}

/// "a known name: did you mean `x`? (valid: ...)": the allowed text of an unknown name.
pub fn suggestion<'a>(word: &str, valid: impl IntoIterator<Item = &'a str> + Clone) -> String {
    let list: Vec<&str> = valid.clone().into_iter().collect();
    match nearest(word, valid) {
        Some(best) => format!(
            "a known name: did you mean `{best}`? (valid: {})",
            list.join(", ")
        ),
        None => format!("a known name (valid: {})", list.join(", ")),
    }
}

fn short(v: &Value) -> String {
    let s = v.to_string();
    if s.len() > 60 {
        format!("{}...", &s[..57])
    } else {
        s
    }
}

/// Walks `value` against `schema`, pushing every problem.
pub(crate) fn check(value: &Value, schema: &Value, path: &str, problems: &mut Vec<Problem>) {
    let s = node(schema);
    match classify(&s) {
        Branch::Plain => {}
        Branch::Optional(inner) => {
            if !value.is_null() {
                check(value, inner, path, problems);
            }
            return;
        }
        Branch::Tagged(variants) => {
            let Some(obj) = value.as_object() else {
                problems.push(Problem::new(path, short(value), describe(schema)));
                return;
            };
            let tags: Vec<&str> = variants.iter().map(|(t, _)| t.as_str()).collect();
            match obj.get("kind") {
                None => problems.push(Problem::new(
                    join(path, "kind"),
                    "missing",
                    format!("one of {}", tags.join(", ")),
                )),
                Some(Value::String(kind)) => match variants.iter().find(|(t, _)| t == kind) {
                    Some((_, branch)) => check_plain(value, branch, path, problems),
                    None => problems.push(Problem::new(
                        join(path, "kind"),
                        format!("{kind:?}"),
                        suggestion(kind, tags.iter().copied()),
                    )),
                },
                Some(other) => problems.push(Problem::new(
                    join(path, "kind"),
                    short(other),
                    format!("one of {}", tags.join(", ")),
                )),
            }
            return;
        }
        Branch::Untagged(list) => {
            if value.is_null() && list.iter().any(is_null_schema) {
                return;
            }
            let fits = list.iter().any(|b| {
                let mut sub = Vec::new();
                check(value, b, path, &mut sub);
                sub.is_empty()
            });
            if !fits {
                problems.push(Problem::new(path, short(value), describe(schema)));
            }
            return;
        }
    }
    check_plain(value, &s, path, problems);
}

fn check_plain(value: &Value, s: &Map<String, Value>, path: &str, problems: &mut Vec<Problem>) {
    // Only built when a problem is reported (cloning every node would dominate the walk).
    let described = || describe(&Value::Object(s.clone()));
    if let Some(allowed) = s.get("enum").and_then(Value::as_array) {
        if !allowed.contains(value) {
            let names: Vec<&str> = allowed.iter().filter_map(Value::as_str).collect();
            let text = match value.as_str() {
                Some(word) => suggestion(word, names.iter().copied()),
                None => format!("one of {}", join_values(allowed)),
            };
            problems.push(Problem::new(path, short(value), text));
        }
        return;
    }
    if let Some(c) = s.get("const") {
        if c != value {
            problems.push(Problem::new(path, short(value), format!("{c}")));
        }
        return;
    }
    let t = types(s);
    if t.is_empty() {
        return;
    }
    let fits = match value {
        Value::Null => t.contains(&"null"),
        Value::Bool(_) => t.contains(&"boolean"),
        Value::Number(n) => {
            t.contains(&"number") || (t.contains(&"integer") && (n.is_u64() || n.is_i64()))
        }
        Value::String(_) => t.contains(&"string"),
        Value::Array(_) => t.contains(&"array"),
        Value::Object(_) => t.contains(&"object"),
    };
    if !fits {
        let allowed = described();
        let allowed = if value.is_string() && (t.contains(&"number") || t.contains(&"integer")) {
            format!("{allowed} (finite)")
        } else {
            allowed
        };
        problems.push(Problem::new(path, short(value), allowed));
        return;
    }
    match value {
        Value::Number(n) => {
            let x = n.as_f64().unwrap_or(f64::NAN);
            let below = num(s, "minimum").is_some_and(|m| x < m)
                || num(s, "exclusiveMinimum").is_some_and(|m| x <= m);
            let above = num(s, "maximum").is_some_and(|m| x > m)
                || num(s, "exclusiveMaximum").is_some_and(|m| x >= m);
            if below || above || !x.is_finite() {
                problems.push(Problem::new(path, n.to_string(), described()));
            }
        }
        Value::Array(items) => {
            let len = items.len() as f64;
            if num(s, "minItems").is_some_and(|m| len < m)
                || num(s, "maxItems").is_some_and(|m| len > m)
            {
                let (lo, hi) = (num(s, "minItems"), num(s, "maxItems"));
                let want = match (lo, hi) {
                    (Some(a), Some(b)) if a == b => format!("exactly {a} items"),
                    (Some(a), Some(b)) => format!("{a} to {b} items"),
                    (Some(a), None) => format!("at least {a} items"),
                    (None, Some(b)) => format!("at most {b} items"),
                    (None, None) => String::new(),
                };
                problems.push(Problem::new(path, format!("{} items", items.len()), want));
            }
            if let Some(item) = s.get("items") {
                for (i, v) in items.iter().enumerate() {
                    check(v, item, &format!("{path}[{i}]"), problems);
                }
            }
        }
        Value::Object(obj) => {
            let props = s.get("properties").and_then(Value::as_object);
            let closed = s.get("additionalProperties") == Some(&Value::Bool(false))
                || s.get("unevaluatedProperties") == Some(&Value::Bool(false));
            let known: Vec<&str> = props
                .map(|p| p.keys().map(String::as_str).collect())
                .unwrap_or_default();
            for (k, v) in obj {
                match props.and_then(|p| p.get(k)) {
                    // The tag of a tagged enum was checked by the caller.
                    Some(_) if k == "kind" && tag_of(s).is_some() => {}
                    Some(sub) => check(v, sub, &join(path, k), problems),
                    None if closed => problems.push(Problem::new(
                        join(path, k),
                        "<unknown field>",
                        suggestion(k, known.iter().copied()),
                    )),
                    None => {}
                }
            }
            for r in s
                .get("required")
                .and_then(Value::as_array)
                .into_iter()
                .flatten()
            {
                if let Some(r) = r.as_str() {
                    if !obj.contains_key(r) {
                        let allowed = props
                            .and_then(|p| p.get(r))
                            .map_or_else(|| "required".to_string(), describe);
                        problems.push(Problem::new(join(path, r), "missing", allowed));
                    }
                }
            }
        }
        _ => {}
    }
}

/// Defaults of the tagged-enum specs (`Drivetrain`, `Aero`, `Waveform`) as JSON text: the
/// variant a table without `kind` takes, for the generated Python dataclasses.
pub fn tagged_defaults_json() -> String {
    serde_json::json!({
        "Drivetrain": crate::Drivetrain::default(),
        "Aero": crate::Aero::default(),
        "Waveform": crate::Waveform::default(),
    })
    .to_string()
}
