//! The JSON Schema of the spec (generated from the types by `schemars`) and the validator
//! that walks a spec value against it, collecting every problem with its dotted path.
//!
//! The schema is the one source of each field's unit (`x-unit`), range
//! (`minimum`/`maximum`/`exclusiveMinimum`/`exclusiveMaximum`), default and documentation:
//! validation, [`crate::paths`] and the Python dataclasses all read it.

use std::borrow::Cow;
use std::sync::OnceLock;

use serde_json::{Map, Value};

use crate::spec::Simulation;

mod check;
pub(crate) use check::{check, check_definition};

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
    close(word, candidates, 1).into_iter().next()
}

/// At most `limit` candidates close enough to `word` to be a typo, nearest first.
pub fn close<'a>(
    word: &str,
    candidates: impl IntoIterator<Item = &'a str>,
    limit: usize,
) -> Vec<&'a str> {
    let mut ranked: Vec<(usize, &str)> = candidates
        .into_iter()
        .map(|c| (strsim::levenshtein(word, c), c))
        .filter(|(d, c)| *d <= 2.max(word.len().max(c.len()) / 3))
        .collect();
    ranked.sort_by_key(|(d, _)| *d); // stable: equal distances keep the candidates' order
    ranked.dedup_by(|a, b| a.1 == b.1);
    ranked.into_iter().take(limit).map(|(_, c)| c).collect()
}

/// Names a message shows at most: a handful of close ones, never a list of a hundred.
pub const SHOWN_NAMES: usize = 5;

/// "a known name: did you mean `x`? (also close: ...)": the allowed text of an unknown name,
/// with the whole list only when it is short (the Python facade's `_errors.suggest` words its
/// own arguments the same way).
pub fn suggestion<'a>(word: &str, valid: impl IntoIterator<Item = &'a str> + Clone) -> String {
    let list: Vec<&str> = valid.clone().into_iter().collect();
    let near = close(word, valid, SHOWN_NAMES);
    let quoted = |names: &[&str]| {
        names
            .iter()
            .map(|n| format!("`{n}`"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if list.len() <= SHOWN_NAMES {
        return match near.first() {
            Some(best) => format!("did you mean `{best}`? (one of: {})", quoted(&list)),
            None => format!("one of: {}", quoted(&list)),
        };
    }
    match near.split_first() {
        Some((best, [])) => format!(
            "a known name: did you mean `{best}`? ({} names)",
            list.len()
        ),
        Some((best, others)) => format!(
            "a known name: did you mean `{best}`? (also close: {}; {} names)",
            quoted(others),
            list.len()
        ),
        None => format!(
            "a known name (none close to `{word}`; {} names, e.g. {})",
            list.len(),
            quoted(&list[..3])
        ),
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
